//! Textures and colour properties: constants, bitmaps (read once per file and encoding),
//! generated checkerboards, scaled textures, and textures made from others (a plastic's mapped
//! albedo, an opacity from a bitmap's luminance).

use std::path::PathBuf;

use glam::Vec3;

use super::materials::Value;
use super::spectra::{linear_to_srgb, srgb_to_linear};
use super::xml::{Elem, Plugin, resolve};
use super::{Loader, Res, values};
use crate::scene::{Texture, TextureRef, UvTransform};

/// Side of a generated checkerboard texture (two cells per side).
const CHECKER_SIDE: u32 = 256;

impl<'a> Loader<'a> {
    /// A colour or texture property (`rgb`, `spectrum`, `float`, a nested or referenced
    /// texture), `default` where absent.
    pub(super) fn value(&mut self, p: &Plugin<'a>, key: &str, default: Vec3) -> Res<Value> {
        self.value_with(p, key, default, false)
    }

    /// [`Self::value`]; `alpha`: a texture's values go to its alpha channel (opacity).
    pub(super) fn value_with(&mut self, p: &Plugin<'a>, key: &str, default: Vec3, alpha: bool) -> Res<Value> {
        let Some(e) = p.get(key) else { return Ok(Value::Constant(default)) };
        match e.tag.as_str() {
            "texture" | "ref" => {
                let v = self.texture_value(e, false)?;
                if alpha { self.as_opacity(v).map_err(|m| self.err(e, m)) } else { Ok(v) }
            }
            _ => {
                let c = self.v(values::colour(e))?;
                if let Some(note) = c.note {
                    self.warn(note);
                }
                Ok(Value::Constant(c.rgb))
            }
        }
    }

    /// A texture element (or a reference to one); `linear`: its data are not colour (a normal
    /// map).
    pub(super) fn texture_value(&mut self, e: &'a Elem, linear: bool) -> Res<Value> {
        let e = self.deref(e, "texture")?;
        let p = Plugin::new(e);
        let value = match p.ty() {
            "bitmap" => {
                let filename =
                    self.string(&p, "filename")?.ok_or_else(|| self.err(e, "a bitmap needs a filename"))?.to_owned();
                let raw = self.boolean(&p, "raw", false)?;
                let gamma = self.float(&p, "gamma", -1.0)?;
                let linear = linear || raw || (gamma - 1.0).abs() < 1e-3;
                if gamma != -1.0 && (gamma - 1.0).abs() >= 1e-3 && (gamma - 2.2).abs() >= 1e-3 {
                    self.warn_once(
                        "gamma",
                        format!("a bitmap's gamma other than 1 and 2.2 is read as sRGB (first: {filename}, {gamma})"),
                    );
                }
                for (key, what) in
                    [("filter_type", "rastergi filters textures trilinearly"), ("wrap_mode", "textures repeat")]
                {
                    if let Some(mode) = self.string(&p, key)?
                        && !matches!(mode, "repeat" | "bilinear" | "trilinear")
                    {
                        self.warn_once(
                            &format!("{key} {mode}"),
                            format!("bitmap {key} '{mode}' is ignored: {what} (first: {filename})"),
                        );
                    }
                }
                let path = resolve(self.dir_of(e), &filename);
                let texture = self.load_texture(e, path, linear)?;
                let transform = self.uv_transform(&p)?;
                Value::Texture { texture: TextureRef { texture, transform }, factor: Vec3::ONE }
            }
            "checkerboard" => {
                let c0 = self.texture_colour(&p, "color0", Vec3::splat(0.4))?;
                let c1 = self.texture_colour(&p, "color1", Vec3::splat(0.2))?;
                let texture = self.checkerboard(c0, c1);
                let transform = self.uv_transform(&p)?;
                Value::Texture { texture: TextureRef { texture, transform }, factor: Vec3::ONE }
            }
            "scale" => {
                let scale = self.value(&p, "scale", Vec3::ONE)?.factor();
                let inner = self.nested_of(&p, "texture");
                let inner = inner.first().ok_or_else(|| self.err(e, "a scale texture holds no texture"))?;
                match self.texture_value(inner, linear)? {
                    Value::Constant(c) => Value::Constant(c * scale),
                    Value::Texture { texture, factor } => Value::Texture { texture, factor: factor * scale },
                }
            }
            other => {
                p.read_all();
                self.warn(format!("the texture type '{other}' is not supported; it is read as grey 0.5"));
                Value::Constant(Vec3::splat(0.5))
            }
        };
        self.warn_unread(&p, &format!("texture '{}'", p.ty()));
        Ok(value)
    }

    /// A constant colour property (a texture is refused here).
    fn texture_colour(&mut self, p: &Plugin<'a>, key: &str, default: Vec3) -> Res<Vec3> {
        let name = format!("{} texture", p.ty());
        self.constant(p, key, default, &name)
    }

    /// The placement of a texture's image: 0.x's uscale, vscale, uoffset, voffset (uv' = s·uv
    /// + o), or Mitsuba 3's `to_uv` transform (its 2D affine part).
    fn uv_transform(&mut self, p: &Plugin<'a>) -> Res<UvTransform> {
        if let Some(e) = p.get("to_uv") {
            let m = self.v(values::transform(e))?;
            let c = m.to_cols_array_2d();
            return Ok(UvTransform([[c[0][0], c[1][0], c[3][0]], [c[0][1], c[1][1], c[3][1]]]));
        }
        let (us, vs) = (self.float(p, "uscale", 1.0)?, self.float(p, "vscale", 1.0)?);
        let (uo, vo) = (self.float(p, "uoffset", 0.0)?, self.float(p, "voffset", 0.0)?);
        Ok(UvTransform([[us, 0.0, uo], [0.0, vs, vo]]))
    }

    /// The texture at `path` (read once per file, however its path is spelled, and encoding),
    /// its size checked against the texel budget before it is decoded.
    fn load_texture(&mut self, e: &'a Elem, path: PathBuf, linear: bool) -> Res<usize> {
        let canonical = self.files.canonical(&path);
        if let Some(&t) = self.textures.get(&(canonical.clone(), linear)) {
            return Ok(t);
        }
        if let Some(what) = self.files.missing(&path) {
            return Err(self.err(e, format!("the texture {}: {what}", path.display())));
        }
        if self.files.is_special(&path) {
            return Err(self.err(e, format!("the texture {} is not a regular file", path.display())));
        }
        let bytes = self
            .files
            .read(&path)
            .map_err(|err| self.err(e, format!("the texture {} cannot be read ({err})", path.display())))?;
        let bad = |l: &Self, m: String| l.err(e, format!("the texture {} {m}", path.display()));
        let (w, h) = Texture::dimensions(&bytes).map_err(|m| bad(self, m))?;
        self.charge_texels(w as u64 * h as u64, &format!("{w}x{h}")).map_err(|m| bad(self, m))?;
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let texture = Texture::decode(&name, &bytes).map_err(|m| bad(self, m))?;
        let t = self.add_texture(e, Texture { linear, ..texture })?;
        self.textures.insert((canonical, linear), t);
        Ok(t)
    }

    /// Counts `n` more texels against the texel budget (an error where they exceed it).
    fn charge_texels(&mut self, n: u64, what: &str) -> Result<(), String> {
        self.budgets.check_more(crate::scene::Budget::Texels, self.texels, n, what)?;
        self.texels += n;
        Ok(())
    }

    fn add_texture(&mut self, e: &Elem, t: Texture) -> Res<usize> {
        if self.scene.textures.len() >= crate::scene::MAX_TEXTURES {
            return Err(self.err(e, format!("the scene needs more than {} textures", crate::scene::MAX_TEXTURES)));
        }
        Ok(self.scene.add_texture(t))
    }

    /// A 256² texture of Mitsuba's checkerboard: color0 where ⌊2u⌋ and ⌊2v⌋ have the same
    /// parity, color1 elsewhere (cells of 128 texels: the bilinear filter blurs one texel).
    fn checkerboard(&mut self, c0: Vec3, c1: Vec3) -> usize {
        let key = format!("{c0} {c1}");
        if let Some(&t) = self.checkers.get(&key) {
            return t;
        }
        // A generated texture's few texels are counted but never refused: the budget bounds
        // what files make the loader decode.
        self.texels += (CHECKER_SIDE * CHECKER_SIDE) as u64;
        let encode = |c: Vec3| c.to_array().map(|x| (linear_to_srgb(x) * 255.0).round() as u8);
        let (a, b) = (encode(c0), encode(c1));
        let half = CHECKER_SIDE / 2;
        let texels = (0..CHECKER_SIDE * CHECKER_SIDE)
            .map(|i| {
                let (x, y) = (i % CHECKER_SIDE / half, i / CHECKER_SIDE / half);
                let [r, g, bl] = if x == y { a } else { b };
                [r, g, bl, 255]
            })
            .collect();
        let t = self.scene.add_texture(Texture {
            name: "checkerboard".into(),
            width: CHECKER_SIDE,
            height: CHECKER_SIDE,
            texels,
            linear: false,
        });
        self.checkers.insert(key, t);
        t
    }

    /// `v` with `f` applied to its colour: to a constant, or to every texel of a copy of its
    /// texture (cached under `key`; the copy's texels count against the texel budget).
    pub(super) fn map_value(&mut self, v: Value, key: &str, f: impl Fn(Vec3) -> Vec3) -> Result<Value, String> {
        Ok(match v {
            Value::Constant(c) => Value::Constant(f(c)),
            Value::Texture { texture, factor } => {
                let linear = self.scene.textures[texture.texture].linear;
                let encode =
                    |x: f32| (if linear { x.clamp(0.0, 1.0) } else { linear_to_srgb(x) } * 255.0).round() as u8;
                let derived = self.derived_texture(texture.texture, format!("{key} {factor}"), key, |t, rgb| {
                    let c = f(factor * rgb);
                    [encode(c.x), encode(c.y), encode(c.z), t[3]]
                })?;
                match derived {
                    Some(t) => Value::Texture {
                        texture: TextureRef { texture: t, transform: texture.transform },
                        factor: Vec3::ONE,
                    },
                    None => Value::Constant(f(factor * 0.5)),
                }
            }
        })
    }

    /// A texture as an opacity: its luminance (linear) in the alpha channel of a copy.
    fn as_opacity(&mut self, v: Value) -> Result<Value, String> {
        let Value::Texture { texture, factor } = v else { return Ok(v) };
        let derived = self.derived_texture(texture.texture, "opacity".to_owned(), "opacity", |t, rgb| {
            [t[0], t[1], t[2], (crate::environment::luminance(rgb).clamp(0.0, 1.0) * 255.0).round() as u8]
        })?;
        Ok(match derived {
            Some(t) => Value::Texture { texture: TextureRef { texture: t, transform: texture.transform }, factor },
            None => Value::Constant(factor * 0.5),
        })
    }

    /// A copy of texture `source` whose every texel is `texel(bytes, linear RGB)`, named
    /// "`source` (`label`)" and cached under `cache`; `None` where the scene holds the most
    /// textures it may; an error where its texels exceed the texel budget.
    fn derived_texture(
        &mut self,
        source: usize,
        cache: String,
        label: &str,
        texel: impl Fn([u8; 4], Vec3) -> [u8; 4],
    ) -> Result<Option<usize>, String> {
        let key = (source, cache);
        if let Some(&t) = self.derived.get(&key) {
            return Ok(Some(t));
        }
        if self.scene.textures.len() >= crate::scene::MAX_TEXTURES {
            return Ok(None);
        }
        let (name, width, height) = {
            let src = &self.scene.textures[source];
            (src.name.clone(), src.width, src.height)
        };
        self.charge_texels(width as u64 * height as u64, &format!("a {label} copy of the texture {name}"))
            .map_err(|m| format!("the scene {m}"))?;
        let src = &self.scene.textures[source];
        let linear = src.linear;
        let decode = |c: u8| if linear { c as f32 / 255.0 } else { srgb_to_linear(c as f32 / 255.0) };
        let texels =
            src.texels.iter().map(|&t| texel(t, Vec3::new(decode(t[0]), decode(t[1]), decode(t[2])))).collect();
        let derived = Texture { name: format!("{name} ({label})"), width, height, texels, linear };
        let t = self.scene.add_texture(derived);
        self.derived.insert(key, t);
        Ok(Some(t))
    }
}
