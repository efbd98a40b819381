//! Budgets: the most a scene's files may make rastergi read, decode, expand and hold, declared
//! once here and checked by every reader before it allocates (a count a file declares is
//! measured against its budget before anything is allocated from it), so that a hostile or
//! broken file ends in one error line instead of exhausting memory or the stack.
//!
//! | budget (`--budget NAME=N`) | what it counts | default |
//! |---|---|---|
//! | `triangles` | triangles of the whole scene, instances included, before they are read | 2²⁵ (33.5 M) |
//! | `vertices` | vertices of one mesh (PLY, `.serialized`, OBJ, glTF accessor) | 2²⁶ (67 M) |
//! | `texels` | texels of the scene's decoded textures together, each image's declared size checked before it is decoded; also the pixels of one environment map or image read (`--env`, `envmap`, `compare`) | 2²⁷ (134 M: 512 MiB of 8-bit RGBA) |
//! | `decompressed` | bytes decompressed from `.serialized` meshes, in all | 2 GiB (512 MiB on 32-bit targets) |
//! | `xml-bytes` | bytes of a Mitsuba file and its includes, in all; and the nodes (elements, comments, runs of text) a file may hold, one per 32 bytes of it | 64 MiB (2 M nodes) |
//! | `xml-depth` | nesting of a Mitsuba file's elements (at most [`MAX_XML_DEPTH`]) | 256 |
//! | `expansion` | bytes of text made by `$name` substitution and DTD entity references, in all | 64 MiB |
//!
//! Where the device is the bound, [`Budgets::fit_device`] lowers a budget to what the device
//! can take: the triangles to what one storage buffer binds (48 bytes each). The texture atlas
//! already halves textures beyond what a 2D texture holds (`textures.rs`); the texel budget
//! bounds what is decoded before that.

use std::fmt;

/// The most the XML depth budget may be raised to: the reader descends one call per level
/// (about 1.5 KiB of stack each), and a thread's stack is 8 MiB at most.
pub const MAX_XML_DEPTH: u64 = 2048;

/// One of the [`Budgets`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Budget {
    Triangles,
    Vertices,
    Texels,
    Decompressed,
    XmlBytes,
    XmlDepth,
    Expansion,
}

impl Budget {
    pub const ALL: [Budget; 7] = [
        Budget::Triangles,
        Budget::Vertices,
        Budget::Texels,
        Budget::Decompressed,
        Budget::XmlBytes,
        Budget::XmlDepth,
        Budget::Expansion,
    ];

    /// The name `--budget` takes.
    pub fn name(self) -> &'static str {
        match self {
            Budget::Triangles => "triangles",
            Budget::Vertices => "vertices",
            Budget::Texels => "texels",
            Budget::Decompressed => "decompressed",
            Budget::XmlBytes => "xml-bytes",
            Budget::XmlDepth => "xml-depth",
            Budget::Expansion => "expansion",
        }
    }

    /// What it counts, for messages.
    fn unit(self) -> &'static str {
        match self {
            Budget::Triangles => "triangles",
            Budget::Vertices => "vertices",
            Budget::Texels => "texels",
            Budget::Decompressed => "bytes decompressed",
            Budget::XmlBytes => "bytes of XML",
            Budget::Expansion => "bytes of expanded text",
            Budget::XmlDepth => "levels of nested elements",
        }
    }
}

impl fmt::Display for Budget {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The budgets of one load (module docs): each the most of what it counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Budgets {
    pub triangles: u64,
    pub vertices: u64,
    pub texels: u64,
    pub decompressed: u64,
    pub xml_bytes: u64,
    pub xml_depth: u64,
    pub expansion: u64,
    /// Where [`Budgets::fit_device`] lowered the triangle budget: the triangles the device
    /// binds in one buffer (a budget no flag raises).
    pub device_triangles: Option<u64>,
}

impl Default for Budgets {
    fn default() -> Self {
        Budgets {
            triangles: 1 << 25,
            vertices: 1 << 26,
            texels: 1 << 27,
            decompressed: if usize::BITS < 64 { 1 << 29 } else { 2 << 30 },
            xml_bytes: 64 << 20,
            xml_depth: 256,
            expansion: 64 << 20,
            device_triangles: None,
        }
    }
}

impl Budgets {
    pub fn get(&self, b: Budget) -> u64 {
        match b {
            Budget::Triangles => self.triangles,
            Budget::Vertices => self.vertices,
            Budget::Texels => self.texels,
            Budget::Decompressed => self.decompressed,
            Budget::XmlBytes => self.xml_bytes,
            Budget::XmlDepth => self.xml_depth,
            Budget::Expansion => self.expansion,
        }
    }

    pub fn set(&mut self, b: Budget, value: u64) {
        *match b {
            Budget::Triangles => &mut self.triangles,
            Budget::Vertices => &mut self.vertices,
            Budget::Texels => &mut self.texels,
            Budget::Decompressed => &mut self.decompressed,
            Budget::XmlBytes => &mut self.xml_bytes,
            Budget::XmlDepth => &mut self.xml_depth,
            Budget::Expansion => &mut self.expansion,
        } = value;
    }

    /// Checks that `need` (the total once the thing is read) is within budget `b`. The error
    /// is a predicate for the caller to put after what needs it (a file, an element): "needs
    /// N triangles (`detail`), more than the triangles budget of M; raise it with --budget
    /// triangles=N …".
    pub fn check(&self, b: Budget, need: u64, detail: &str) -> Result<(), String> {
        if need <= self.get(b) { Ok(()) } else { Err(self.refusal(b, need, detail)) }
    }

    /// [`Budgets::check`] of `adding` more of budget `b` to the `used` already spent by the
    /// load (the triangles of the shapes read before a mesh).
    pub fn check_more(&self, b: Budget, used: u64, adding: u64, detail: &str) -> Result<(), String> {
        let need = used.saturating_add(adding);
        if need <= self.get(b) {
            return Ok(());
        }
        let detail = if used == 0 { detail.to_owned() } else { format!("{detail} and the {used} read before") };
        Err(self.refusal(b, need, &detail))
    }

    /// The message of [`Budgets::check`] for a need beyond budget `b`.
    pub fn refusal(&self, b: Budget, need: u64, detail: &str) -> String {
        let limit = self.get(b);
        let detail = if detail.is_empty() { String::new() } else { format!(" ({detail})") };
        if b == Budget::Triangles && self.device_triangles == Some(limit) {
            return format!(
                "needs {need} triangles{detail}, more than the {limit} triangles this GPU binds in one buffer; render it on a GPU with a larger storage-buffer limit"
            );
        }
        format!(
            "needs {need} {}{detail}, more than the {} budget of {limit}; raise it with --budget {}={need} where memory allows",
            b.unit(),
            b.name(),
            b.name()
        )
    }

    /// These budgets lowered to what the device can take (module docs): the triangles to those
    /// that one storage buffer binds.
    pub fn fit_device(mut self, limits: &wgpu::Limits) -> Budgets {
        let stride = std::mem::size_of::<crate::gpu_scene::GpuTriangle>() as u64;
        let device = crate::gpu::limits::max_storage_buffer(limits) / stride;
        if device < self.triangles {
            self.triangles = device;
            self.device_triangles = Some(device);
        }
        self
    }
}

/// Parses `NAME=N` (the CLI's `--budget`): a budget's name and a whole number, which may be
/// written with `_` separators or a binary suffix (`k`, `M`, `G`: 2¹⁰, 2²⁰, 2³⁰).
pub fn parse_budget(s: &str) -> Result<(Budget, u64), String> {
    let names = || Budget::ALL.iter().map(|b| b.name()).collect::<Vec<_>>().join(", ");
    let (name, value) = s.split_once('=').ok_or_else(|| format!("'{s}' is not NAME=N (NAME one of {})", names()))?;
    let budget = Budget::ALL
        .into_iter()
        .find(|b| b.name() == name.trim())
        .ok_or_else(|| format!("'{name}' is not a budget; the budgets are {}", names()))?;
    let value = value.trim().replace('_', "");
    let (digits, shift) = match value.char_indices().last() {
        Some((i, 'k' | 'K')) => (&value[..i], 10),
        Some((i, 'M')) => (&value[..i], 20),
        Some((i, 'G')) => (&value[..i], 30),
        _ => (value.as_str(), 0),
    };
    let n: u64 = digits.parse().map_err(|_| format!("'{value}' is not a whole number such as 1000000 or 64M"))?;
    let n = n.checked_mul(1 << shift).ok_or_else(|| format!("'{value}' is beyond 2⁶⁴"))?;
    if budget == Budget::XmlDepth && n > MAX_XML_DEPTH {
        return Err(format!("xml-depth is at most {MAX_XML_DEPTH}: the reader descends one call per level"));
    }
    Ok((budget, n))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_budget_is_parsed_by_name_and_checked_inclusively() {
        assert_eq!(parse_budget("triangles=1_000").unwrap(), (Budget::Triangles, 1000));
        assert_eq!(parse_budget("xml-bytes=64M").unwrap(), (Budget::XmlBytes, 64 << 20));
        assert_eq!(parse_budget("texels=2G").unwrap(), (Budget::Texels, 2 << 30));
        assert!(parse_budget("triangle=5").unwrap_err().contains("triangles, vertices"));
        assert!(parse_budget("texels=-1").is_err());
        assert!(parse_budget("texels=99999999999G").unwrap_err().contains("2⁶⁴"));
        assert_eq!(parse_budget("xml-depth=2048").unwrap(), (Budget::XmlDepth, 2048));
        assert!(parse_budget("xml-depth=2049").unwrap_err().contains("at most 2048"));
        let mut b = Budgets::default();
        b.set(Budget::Vertices, 10);
        assert!(b.check(Budget::Vertices, 10, "x").is_ok());
        let e = b.check(Budget::Vertices, 11, "its positions").unwrap_err();
        assert_eq!(
            e,
            "needs 11 vertices (its positions), more than the vertices budget of 10; raise it with --budget vertices=11 where memory allows"
        );
        let e = b.check_more(Budget::Vertices, 4, 7, "its positions").unwrap_err();
        assert!(e.starts_with("needs 11 vertices (its positions and the 4 read before)"), "{e}");
    }

    #[test]
    fn the_triangle_budget_follows_the_storage_binding_limit() {
        let limits = wgpu::Limits { max_storage_buffer_binding_size: 48 << 20, ..wgpu::Limits::default() };
        let fitted = Budgets::default().fit_device(&limits);
        assert_eq!(fitted.triangles, 1 << 20);
        let e = fitted.check(Budget::Triangles, (1 << 20) + 1, "").unwrap_err();
        assert!(e.contains("this GPU binds in one buffer") && !e.contains("--budget"), "{e}");
        let roomy = wgpu::Limits { max_storage_buffer_binding_size: u64::MAX, max_buffer_size: u64::MAX, ..limits };
        assert_eq!(Budgets::default().fit_device(&roomy), Budgets::default());
    }
}
