//! The scene's textures as the passes sample them, and the CPU twin of that sampling.
//!
//! **One atlas, each texture at its own size.** Every texture keeps its own resolution and its
//! own mip chain; the chains lie one after another in one run of texels ([`TextureAtlas`]),
//! which the GPU holds as the rows of a single `rgba16float` 2D texture read with
//! `textureLoad` (texel i at column i mod [`ROW`], row i / [`ROW`]): one binding serves every
//! texture of every size, nothing is resized to a common size, and the capacity is that of a
//! texture (WebGPU guarantees 8192 rows, [`CAPACITY`] texels, 256 MiB), not the far smaller
//! storage-binding limit (128 MiB on lavapipe). Filtering is therefore done by the shader
//! (`textures.wgsl`), the same arithmetic as [`TextureAtlas::sample`] here. Only when the
//! chains together exceed the capacity is the largest texture halved, and again, until they
//! fit ([`fitted_sizes`]): a scene with one 8 k texture keeps its other textures as they are.
//!
//! **Texels.** Linear RGB in half floats: the sRGB decoding happens here, exactly, so the GPU
//! filters the very values the CPU twin reads, and 11 significant bits keep more precision
//! than 8-bit sRGB at every level. The alpha channel (opacity) is linear, c/255, and so are
//! the RGB of textures holding data rather than colour (normal maps, [`Texture::linear`]). A
//! texture halved to fit is resampled in linear RGB with a tent filter as wide as one
//! destination texel (an area-weighted average).
//!
//! **Mip maps.** Level k + 1 of a w × h level is max(⌊w/2⌋, 1) × max(⌊h/2⌋, 1), down to 1 × 1.
//! Along an axis that halves exactly each texel is the mean of its two parents (the 2 × 2 box
//! where both do); along an odd one, the tent filter above (repeat addressing). Computed in
//! f32, stored rounded to f16.
//!
//! **Sampling** (`atlas_sample` in WGSL, [`TextureAtlas::sample`]). Trilinear with repeat
//! addressing: the coordinates wrapped to [0, 1), bilinear within a level between the four
//! texels around u·w − ½, v·h − ½ (texel centres at (i + ½)/w, as Vulkan, WebGPU and Mitsuba's
//! bitmap place them), linear between the two levels around the level of detail λ, clamped to
//! [0, levels − 1]. The passes give λ explicitly: at the eye's visible points
//! λ = log2 max(|∂st/∂x|·(w, h), |∂st/∂y|·(w, h)) in texels of the texture's own level 0, from
//! the G-buffer's screen-space derivatives (or the path tracer's ray differentials); at every
//! secondary point (photon hits, gather hits, path bounces) λ = 0, the unfiltered texture:
//! those points are averaged over many samples, and a footprint filter there would only add a
//! bias. `--texture-filter bilinear` reads level 0 at the visible points too, as a reference
//! renderer's bilinear lookups averaged over the pixel do.

use glam::{Vec2, Vec3, Vec4};

use crate::error::{Error, Result};
use crate::gpu::binding::{Group, Slot};
use crate::gpu::structs::{GpuStruct, gpu_struct};
use crate::gpu::{Gpu, shader};
use crate::par::prelude::*;
use crate::scene::Texture;

/// Texels per row of the atlas texture.
pub use crate::gpu::consts::ATLAS_ROW as ROW;
/// Rows of the atlas texture at most (WebGPU guarantees 8192 texels per side).
pub const MAX_ROWS: u32 = 8192;
/// Texels the atlas holds at most: 256 MiB of `rgba16float`.
pub const CAPACITY: u64 = ROW as u64 * MAX_ROWS as u64;
pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Bytes per texel of [`FORMAT`].
const TEXEL_BYTES: u64 = 8;

gpu_struct! {
    /// Where texture k lies in the atlas: its level 0's size, its level count and its first
    /// texel. `AtlasEntry` in WGSL (`textures.wgsl`), four words each in the scene's data buffer.
    #[derive(PartialEq, Eq)]
    pub struct AtlasEntry as "AtlasEntry" {
        pub width: u32,
        pub height: u32,
        pub levels: u32,
        pub first: u32,
    }
}

/// Every texture's mip chain, exactly as uploaded.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureAtlas {
    pub entries: Vec<AtlasEntry>,
    /// Texture after texture, level after level, rows from the top: linear RGBA as f16 bits.
    pub texels: Vec<[u16; 4]>,
}

/// The sRGB transfer function's inverse, for each 8-bit code.
fn srgb_decode_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|i| {
            let c = i as f64 / 255.0;
            (if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }) as f32
        })
    })
}

/// Linear value of an 8-bit sRGB code.
pub fn srgb_to_linear(code: u8) -> f32 {
    srgb_decode_table()[code as usize]
}

/// Size of the level after a `w × h` one.
fn next_level(w: u32, h: u32) -> (u32, u32) {
    ((w / 2).max(1), (h / 2).max(1))
}

/// Number of levels of a chain starting at `w × h` (down to 1 × 1).
pub fn level_count(w: u32, h: u32) -> u32 {
    w.max(h).max(1).ilog2() + 1
}

/// Texels of a chain of levels starting at `w × h`.
pub fn chain_texels(w: u32, h: u32) -> u64 {
    let (mut w, mut h, mut total) = (w.max(1), h.max(1), 0u64);
    loop {
        total += w as u64 * h as u64;
        if w == 1 && h == 1 {
            return total;
        }
        (w, h) = next_level(w, h);
    }
}

/// The size each texture keeps in the atlas: its own, unless the chains together exceed
/// [`CAPACITY`]; then the texture with the largest chain is halved (both sides, rounded up),
/// and again, until they fit. Textures that were not the largest keep their size.
pub fn fitted_sizes(sizes: &[(u32, u32)]) -> Vec<(u32, u32)> {
    let mut out: Vec<(u32, u32)> = sizes.iter().map(|&(w, h)| (w.max(1), h.max(1))).collect();
    let mut total: u64 = out.iter().map(|&(w, h)| chain_texels(w, h)).sum();
    while total > CAPACITY {
        let (k, &(w, h)) = out.iter().enumerate().max_by_key(|(_, s)| chain_texels(s.0, s.1)).expect("not empty");
        if (w, h) == (1, 1) {
            break; // More textures than texels: reported by TextureAtlas::check.
        }
        let halved = (w.div_ceil(2), h.div_ceil(2));
        total = total - chain_texels(w, h) + chain_texels(halved.0, halved.1);
        out[k] = halved;
    }
    out
}

/// Resamples one axis of an `n`-long periodic signal to `m` samples: a tent filter of radius
/// max(1, n/m) source texels around each destination texel's centre, weights normalised.
fn resample_axis(n: usize, m: usize) -> Vec<Vec<(usize, f32)>> {
    let scale = n as f64 / m as f64;
    let radius = scale.max(1.0);
    (0..m)
        .map(|j| {
            let centre = (j as f64 + 0.5) * scale - 0.5;
            let lo = (centre - radius).floor() as i64;
            let hi = (centre + radius).ceil() as i64;
            let mut taps: Vec<(usize, f32)> = Vec::new();
            let mut total = 0.0f64;
            for i in lo..=hi {
                let w = 1.0 - (i as f64 - centre).abs() / radius;
                if w > 0.0 {
                    total += w;
                    taps.push((i.rem_euclid(n as i64) as usize, w as f32));
                }
            }
            taps.iter_mut().for_each(|t| t.1 = (t.1 as f64 / total) as f32);
            taps
        })
        .collect()
}

/// The taps of one axis of the next mip level: the mean of two parents where the side halves
/// exactly, the identity where it stays (1), the tent filter where it is odd.
fn mip_axis(n: usize, m: usize) -> Vec<Vec<(usize, f32)>> {
    if n == m {
        (0..m).map(|j| vec![(j, 1.0)]).collect()
    } else if n == 2 * m {
        (0..m).map(|j| vec![(2 * j, 0.5), (2 * j + 1, 0.5)]).collect()
    } else {
        resample_axis(n, m)
    }
}

/// Applies separable taps to a `sw × sh` image: `xs` along rows (to `xs.len()` columns), then
/// `ys` along columns. Row by row: each destination row resamples the source rows its taps
/// name along x (kept while the next row's taps name them too), so the image resampled along x
/// alone is never held whole (for an 8 k texture halved, 512 MiB of it).
fn separable(
    src: impl Fn(usize) -> Vec4,
    sw: usize,
    sh: usize,
    xs: &[Vec<(usize, f32)>],
    ys: &[Vec<(usize, f32)>],
) -> Vec<Vec4> {
    let dw = xs.len();
    let along_x = |y: usize| -> Vec<Vec4> {
        xs.iter().map(|taps| taps.iter().map(|&(i, w)| src(y * sw + i) * w).sum()).collect()
    };
    debug_assert!(ys.iter().flatten().all(|&(i, _)| i < sh));
    let mut out = vec![Vec4::ZERO; dw * ys.len()];
    let mut rows: Vec<(usize, Vec<Vec4>)> = Vec::new();
    for (y, taps) in ys.iter().enumerate() {
        let mut kept: Vec<(usize, Vec<Vec4>)> = Vec::with_capacity(taps.len());
        for &(i, _) in taps {
            if kept.iter().any(|(k, _)| *k == i) {
                continue;
            }
            let row = match rows.iter().position(|(k, _)| *k == i) {
                Some(at) => rows.swap_remove(at).1,
                None => along_x(i),
            };
            kept.push((i, row));
        }
        rows = kept;
        let picked: Vec<(&[Vec4], f32)> = taps
            .iter()
            .filter_map(|&(i, w)| rows.iter().find(|(k, _)| *k == i).map(|(_, row)| (row.as_slice(), w)))
            .collect();
        for x in 0..dw {
            out[y * dw + x] = picked.iter().map(|&(row, w)| row[x] * w).sum();
        }
    }
    out
}

/// A texture's texels as linear RGBA (sRGB colour decoded, linear data and alpha as c/255),
/// at `dw × dh`: as they are where that is the texture's size, else resampled with repeat
/// addressing. The texels are decoded as they are read: no linear copy of a large source is
/// made.
fn decode(t: &Texture, dw: u32, dh: u32) -> Vec<Vec4> {
    let (sw, sh, dw, dh) = (t.width as usize, t.height as usize, dw as usize, dh as usize);
    let rgb = |c: u8| if t.linear { c as f32 / 255.0 } else { srgb_to_linear(c) };
    let src = |i: usize| {
        let p = t.texels[i];
        Vec4::new(rgb(p[0]), rgb(p[1]), rgb(p[2]), p[3] as f32 / 255.0)
    };
    if (sw, sh) == (dw, dh) {
        return (0..sw * sh).map(src).collect();
    }
    separable(src, sw, sh, &resample_axis(sw, dw), &resample_axis(sh, dh))
}

/// The next mip level of a `w × h` level.
fn downsample(src: &[Vec4], w: u32, h: u32) -> (Vec<Vec4>, u32, u32) {
    let (nw, nh) = next_level(w, h);
    let xs = mip_axis(w as usize, nw as usize);
    let ys = mip_axis(h as usize, nh as usize);
    (separable(|i| src[i], w as usize, h as usize, &xs, &ys), nw, nh)
}

fn encode(level: &[Vec4]) -> impl Iterator<Item = [u16; 4]> + '_ {
    let h = |v: f32| half::f16::from_f32(v).to_bits();
    level.iter().map(move |c| c.to_array().map(h))
}

impl TextureAtlas {
    /// The atlas of `textures`, each at its [`fitted_sizes`] size (a single white texel and no
    /// entries when there are none, so that the binding always exists).
    pub fn new(textures: &[Texture]) -> TextureAtlas {
        let sizes: Vec<(u32, u32)> = textures.iter().map(|t| (t.width, t.height)).collect();
        let fitted = fitted_sizes(&sizes);
        // The chains one after another, each written in place on a core of its own (the
        // decoding and the mip levels of a staircase's ten photographs dominate its start-up).
        let mut entries = Vec::with_capacity(textures.len());
        let mut first = 0usize;
        for &(width, height) in &fitted {
            let levels = level_count(width, height);
            entries.push(AtlasEntry { width, height, levels, first: first as u32 });
            first += chain_texels(width, height) as usize;
        }
        let mut texels = vec![[0u16; 4]; first];
        let mut chains: Vec<(usize, &mut [[u16; 4]])> = Vec::with_capacity(textures.len());
        let mut rest = texels.as_mut_slice();
        for (i, &(width, height)) in fitted.iter().enumerate() {
            let (chain, after) = rest.split_at_mut(chain_texels(width, height) as usize);
            chains.push((i, chain));
            rest = after;
        }
        let _: Vec<()> = chains
            .into_par_iter()
            .map(|(i, chain)| {
                let (t, (width, height)) = (&textures[i], fitted[i]);
                let (mut level, mut w, mut h) = (decode(t, width, height), width, height);
                let mut at = 0;
                for k in 0..level_count(width, height) {
                    if k > 0 {
                        (level, w, h) = downsample(&level, w, h);
                    }
                    for texel in encode(&level) {
                        chain[at] = texel;
                        at += 1;
                    }
                }
            })
            .collect();
        if texels.is_empty() {
            texels.push([half::f16::ONE.to_bits(); 4]);
        }
        TextureAtlas { entries, texels }
    }

    /// Size of level `k` of texture `t`.
    pub fn level_size(&self, t: u32, k: u32) -> (u32, u32) {
        let e = self.entries[t as usize];
        ((e.width >> k).max(1), (e.height >> k).max(1))
    }

    /// The atlas index of texel (0, 0) of level `k` of texture `t`.
    fn level_first(&self, t: u32, k: u32) -> u32 {
        let e = self.entries[t as usize];
        let (mut first, mut w, mut h) = (e.first, e.width, e.height);
        for _ in 0..k {
            first += w * h;
            (w, h) = next_level(w, h);
        }
        first
    }

    /// The linear RGB of texel (x, y) of level `k` of texture `t`.
    pub fn texel(&self, t: u32, k: u32, x: u32, y: u32) -> Vec3 {
        self.texel_rgba(t, k, x, y).truncate()
    }

    /// The linear RGB and alpha of texel (x, y) of level `k` of texture `t`.
    pub fn texel_rgba(&self, t: u32, k: u32, x: u32, y: u32) -> Vec4 {
        let (w, _) = self.level_size(t, k);
        let p = self.texels[(self.level_first(t, k) + y * w + x) as usize].map(|b| half::f16::from_bits(b).to_f32());
        Vec4::from_array(p)
    }

    /// Bilinear filtering of the `w × h` level starting at texel `first`, at `st`, repeat
    /// addressing (`atlas_bilinear` in WGSL, step for step).
    fn bilinear(&self, first: u32, w: u32, h: u32, st: Vec2) -> Vec4 {
        let f = st - st.floor();
        let p = f * Vec2::new(w as f32, h as f32) - 0.5;
        let p0 = p.floor();
        let a = p - p0;
        // p0 ∈ [−1, side − 1]: −1 wraps to the last texel, side to the first.
        let wrap = |i: f32, n: u32| if i < 0.0 { n - 1 } else { (i as u32).min(n - 1) };
        let (x0, y0) = (wrap(p0.x, w), wrap(p0.y, h));
        let (x1, y1) = (if x0 + 1 >= w { 0 } else { x0 + 1 }, if y0 + 1 >= h { 0 } else { y0 + 1 });
        let texel = |x: u32, y: u32| {
            Vec4::from_array(self.texels[(first + y * w + x) as usize].map(|b| half::f16::from_bits(b).to_f32()))
        };
        let top = texel(x0, y0) * (1.0 - a.x) + texel(x1, y0) * a.x;
        let bottom = texel(x0, y1) * (1.0 - a.x) + texel(x1, y1) * a.x;
        top * (1.0 - a.y) + bottom * a.y
    }

    /// Trilinear sample of texture `t` at `st` and level of detail `lod` (linear RGB): the
    /// CPU twin of `atlas_sample` in WGSL.
    pub fn sample(&self, t: u32, st: Vec2, lod: f32) -> Vec3 {
        self.sample_rgba(t, st, lod).truncate()
    }

    /// [`TextureAtlas::sample`] with the alpha channel.
    pub fn sample_rgba(&self, t: u32, st: Vec2, lod: f32) -> Vec4 {
        let e = self.entries[t as usize];
        let last = e.levels - 1;
        let lod = if lod.is_nan() { 0.0 } else { lod.clamp(0.0, last as f32) };
        let k = (lod.floor() as u32).min(last);
        let f = lod - k as f32;
        let (w, h) = self.level_size(t, k);
        let first = self.level_first(t, k);
        let lo = self.bilinear(first, w, h, st);
        if f > 0.0 && k < last {
            let (nw, nh) = next_level(w, h);
            lo * (1.0 - f) + self.bilinear(first + w * h, nw, nh, st) * f
        } else {
            lo
        }
    }

    /// Level of detail of a footprint on texture `t` whose coordinates change by `dx` and
    /// `dy` across one pixel: log2 of the longer change in texels of the texture's level 0
    /// (the isotropic formula of the Vulkan and WebGPU specifications), 0 under magnification.
    /// `texture_lod` in WGSL.
    pub fn lod(&self, t: u32, dx: Vec2, dy: Vec2) -> f32 {
        let e = self.entries[t as usize];
        let size = Vec2::new(e.width as f32, e.height as f32);
        let rho = (dx * size).length().max((dy * size).length());
        if rho.is_nan() { 0.0 } else { rho.max(1.0).log2().min(32.0) }
    }

    /// Rows of the atlas texture.
    pub fn rows(&self) -> u32 {
        (self.texels.len() as u64).div_ceil(ROW as u64) as u32
    }

    /// Bytes the atlas takes on the GPU.
    pub fn bytes(&self) -> u64 {
        self.rows() as u64 * ROW as u64 * TEXEL_BYTES
    }

    /// The entries as the scene's data buffer holds them (one zero entry where there are none:
    /// no texture slot then points into them).
    pub fn gpu_entries(&self) -> Vec<AtlasEntry> {
        if self.entries.is_empty() { vec![bytemuck::Zeroable::zeroed()] } else { self.entries.clone() }
    }

    /// Checks the atlas against the device's limits (the 2D texture it becomes).
    pub fn check_limits(&self, gpu: &Gpu) -> Result<()> {
        let max = gpu.device.limits().max_texture_dimension_2d;
        if self.rows() > max || ROW > max {
            return Err(Error::Limits(format!(
                "the scene's {} textures need {} MiB ({} rows of {ROW} texels), but this GPU allows {max} texels per side; use smaller textures",
                self.entries.len(),
                self.bytes() >> 20,
                self.rows()
            )));
        }
        Ok(())
    }

    /// Uploads the atlas as the rows of one `rgba16float` texture (the last row padded).
    pub fn upload(&self, gpu: &Gpu) -> wgpu::TextureView {
        let rows = self.rows();
        let width = if rows == 1 { self.texels.len() as u32 } else { ROW };
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("scene textures"),
            size: wgpu::Extent3d { width, height: rows, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: FORMAT,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        // The full rows straight from the texels, the last row padded: no copy of the whole.
        let full = if rows == 1 { 1 } else { (self.texels.len() / ROW as usize) as u32 };
        let tail: Vec<[u16; 4]> = if full < rows {
            let mut t = self.texels[(full * ROW) as usize..].to_vec();
            t.resize(ROW as usize, [0; 4]);
            t
        } else {
            Vec::new()
        };
        let full_texels = &self.texels[..(full * width) as usize];
        for (y, texels, height) in [(0, full_texels, full), (full, &tail[..], rows - full)] {
            if height == 0 {
                continue;
            }
            gpu.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d { x: 0, y, z: 0 },
                    aspect: wgpu::TextureAspect::All,
                },
                bytemuck::cast_slice(texels),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(TEXEL_BYTES as u32 * width),
                    rows_per_image: Some(height),
                },
                wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            );
        }
        texture.create_view(&wgpu::TextureViewDescriptor { label: Some("scene textures"), ..Default::default() })
    }
}

/// Samples `atlas` on the GPU with `textures.wgsl`'s `atlas_sample` at each (texture, st, lod)
/// of `queries`, linear RGBA. The GPU side of the CPU twin's tests.
pub fn sample_on_gpu(gpu: &Gpu, atlas: &TextureAtlas, queries: &[(u32, Vec2, f32)]) -> Result<Vec<Vec4>> {
    let device = &gpu.device;
    atlas.check_limits(gpu)?;
    let view = atlas.upload(gpu);
    let entries =
        gpu.storage_buffer("texture entries", bytemuck::cast_slice(&atlas.gpu_entries()), wgpu::BufferUsages::empty());
    let input: Vec<[f32; 4]> = queries.iter().map(|&(t, st, lod)| [st.x, st.y, lod, f32::from_bits(t)]).collect();
    let input = gpu.storage_buffer("texture queries", bytemuck::cast_slice(&input), wgpu::BufferUsages::empty());
    let source = format!(
        "{}{}
        @group(0) @binding(0) var textures: texture_2d<f32>;
        @group(0) @binding(1) var<storage, read> entries: array<u32>;
        @group(0) @binding(2) var<storage, read> queries: array<vec4f>;
        @group(0) @binding(3) var<storage, read_write> samples: array<vec4f>;
        fn atlas_entry_word(i: u32) -> u32 {{
            return entries[i];
        }}
        @compute @workgroup_size(64)
        fn main(@builtin(global_invocation_id) gid: vec3u) {{
            if gid.x >= arrayLength(&queries) {{
                return;
            }}
            let q = queries[gid.x];
            samples[gid.x] = atlas_sample(bitcast<u32>(q.w), q.xy, q.z);
        }}",
        shader::constants(),
        [AtlasEntry::wgsl().as_str(), shader::TEXTURES].join("\n")
    );
    let module = shader::module(device, "texture samples", &source);
    let samples: Vec<[f32; 4]> = gpu.run_once_read(
        "texture samples",
        &module,
        &Group::compute(
            "texture samples",
            &[
                Slot::float_texture(0, "textures"),
                Slot::read::<u32>(1, "entries"),
                Slot::read::<[f32; 4]>(2, "queries"),
                Slot::write::<[f32; 4]>(3, "samples"),
            ],
        ),
        &[
            ("textures", wgpu::BindingResource::TextureView(&view)),
            ("entries", entries.as_entire_binding()),
            ("queries", input.as_entire_binding()),
        ],
        "samples",
        queries.len(),
    )?;
    Ok(samples.into_iter().map(Vec4::from_array).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texture(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Texture {
        let texels = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| f(x, y)).collect();
        Texture { name: "t".into(), width: w, height: h, texels, linear: false }
    }

    fn f16(v: f32) -> f32 {
        half::f16::from_f32(v).to_f32()
    }

    #[test]
    fn srgb_decoding_follows_the_standard_curve() {
        assert_eq!(srgb_to_linear(0), 0.0);
        assert_eq!(srgb_to_linear(255), 1.0);
        // The linear segment below code 10.3, the power segment above.
        assert!((srgb_to_linear(10) - 10.0 / 255.0 / 12.92).abs() < 1e-7);
        assert!((srgb_to_linear(188) - 0.502886).abs() < 1e-6);
        assert!((0..255).all(|c| srgb_to_linear(c) < srgb_to_linear(c + 1)));
    }

    #[test]
    fn every_texture_keeps_its_own_size_unless_the_atlas_overflows() {
        assert_eq!(fitted_sizes(&[(100, 30), (64, 64), (1, 1)]), vec![(100, 30), (64, 64), (1, 1)]);
        assert_eq!(level_count(100, 30), 7);
        assert_eq!(chain_texels(4, 2), 8 + 2 + 1);
        assert_eq!(chain_texels(5, 3), 15 + 2 + 1);
        // One 16 k texture beside ten of 512²: only the large one shrinks, by halving, to the
        // largest size whose chain fits beside the others.
        let mut sizes = vec![(16384, 16384)];
        sizes.extend([(512, 512); 10]);
        let fitted = fitted_sizes(&sizes);
        assert_eq!(&fitted[1..], &sizes[1..]);
        assert_eq!(fitted[0], (4096, 4096));
        let total = |s: &[(u32, u32)]| s.iter().map(|&(w, h)| chain_texels(w, h)).sum::<u64>();
        assert!(total(&fitted) <= CAPACITY);
        let mut larger = fitted.clone();
        larger[0] = (8192, 8192);
        assert!(total(&larger) > CAPACITY);
        // Many equal textures: halved in turn, never below what fits.
        let fitted = fitted_sizes(&[(4096, 4096); 4]);
        assert!(total(&fitted) <= CAPACITY);
        assert!(fitted.iter().all(|&s| s == (4096, 4096) || s == (2048, 2048)), "{fitted:?}");
    }

    #[test]
    fn level_zero_holds_each_texture_as_it_was_decoded() {
        // Three sizes, none a power of two, in one atlas: texel (x, y) of level 0 is the
        // source's sRGB code decoded (to f16), and a sample at its centre returns it.
        let code = |t: u32, x: u32, y: u32| ((t * 71 + x * 13 + y * 29) % 256) as u8;
        let sizes = [(37, 23), (5, 300), (129, 1)];
        let textures: Vec<Texture> = sizes
            .iter()
            .enumerate()
            .map(|(t, &(w, h))| texture(w, h, |x, y| [code(t as u32, x, y), 0, 255, 128]))
            .collect();
        let a = TextureAtlas::new(&textures);
        for (t, &(w, h)) in sizes.iter().enumerate() {
            let t = t as u32;
            assert_eq!(a.level_size(t, 0), (w, h));
            for (x, y) in [(0, 0), (w - 1, h - 1), (w / 2, h / 3)] {
                let want = Vec4::new(f16(srgb_to_linear(code(t, x, y))), 0.0, 1.0, f16(128.0 / 255.0));
                assert_eq!(a.texel_rgba(t, 0, x, y), want);
                let centre = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                assert!((a.sample_rgba(t, centre, 0.0) - want).abs().max_element() < 1e-6, "texture {t} ({x}, {y})");
            }
        }
    }

    #[test]
    fn mip_levels_are_box_averages_in_linear_space() {
        // A 4×2 texture of black and white columns: level 1 (2×1) is the linear mean 0.5 (sRGB
        // code 188), not the sRGB code 128 (linear 0.216) an average of the codes would give.
        let t = texture(4, 2, |x, _| if x % 2 == 0 { [0, 0, 0, 255] } else { [255; 4] });
        let a = TextureAtlas::new(&[t]);
        assert_eq!((a.level_size(0, 0), a.entries[0].levels), ((4, 2), 3));
        assert_eq!(a.texel(0, 0, 1, 1), Vec3::ONE);
        for (k, x) in [(1, 0), (1, 1), (2, 0)] {
            assert_eq!(a.texel(0, k, x, 0), Vec3::splat(0.5), "level {k} texel {x}");
        }
        // An odd side (3 → 1): the level keeps the mean of a constant row and of any row.
        let t = texture(3, 1, |x, _| [[0, 255, 255][x as usize], 0, 0, 255]);
        let a = TextureAtlas::new(&[t]);
        assert_eq!(a.level_size(0, 1), (1, 1));
        assert!((a.texel(0, 1, 0, 0).x - 2.0 / 3.0).abs() < 1e-3, "{}", a.texel(0, 1, 0, 0));
    }

    #[test]
    fn a_texture_halved_to_fit_is_its_area_average() {
        // 2×1 (black, white) to 1×1 by the tent filter of one destination texel: the mean.
        let t = texture(2, 1, |x, _| if x == 0 { [0, 0, 0, 255] } else { [255; 4] });
        let level = decode(&t, 1, 1);
        assert!((level[0].x - 0.5).abs() < 1e-6);
    }

    #[test]
    fn sampling_interpolates_within_and_between_levels_and_repeats() {
        let t = texture(4, 4, |x, y| [(x * 60) as u8, (y * 60) as u8, 100, 255]);
        let a = TextureAtlas::new(&[texture(3, 5, |_, _| [7; 4]), t]);
        // At a texel centre of level 0 the sample is that texel; one period away too.
        let centre = Vec2::new(1.5 / 4.0, 2.5 / 4.0);
        assert_eq!(a.sample(1, centre, 0.0), a.texel(1, 0, 1, 2));
        assert!((a.sample(1, centre + Vec2::new(3.0, -2.0), 0.0) - a.texel(1, 0, 1, 2)).abs().max_element() < 1e-5);
        // Halfway between two texels of a row: their mean; at the left edge: the mean of the
        // first and the last texel (repeat).
        let mid = a.sample(1, Vec2::new(2.0 / 4.0, 0.5 / 4.0), 0.0);
        assert!((mid - 0.5 * (a.texel(1, 0, 1, 0) + a.texel(1, 0, 2, 0))).abs().max_element() < 1e-6);
        let edge = a.sample(1, Vec2::new(0.0, 0.5 / 4.0), 0.0);
        assert!((edge - 0.5 * (a.texel(1, 0, 0, 0) + a.texel(1, 0, 3, 0))).abs().max_element() < 1e-6);
        // Between levels: the linear blend of the two levels' samples; beyond the last: clamped.
        let uv = Vec2::new(0.3, 0.7);
        let blend = a.sample(1, uv, 1.25);
        let expected = a.sample(1, uv, 1.0) * 0.75 + a.sample(1, uv, 2.0) * 0.25;
        assert!((blend - expected).abs().max_element() < 1e-6);
        assert!((a.sample(1, uv, 7.0) - a.texel(1, 2, 0, 0)).abs().max_element() < 1e-6);
    }

    #[test]
    fn level_of_detail_is_log2_of_the_footprint_in_the_textures_own_texels() {
        let a = TextureAtlas::new(&[texture(64, 16, |_, _| [0; 4]), texture(16, 16, |_, _| [0; 4])]);
        assert_eq!(a.lod(0, Vec2::new(4.0 / 64.0, 0.0), Vec2::new(0.0, 1.0 / 16.0)), 2.0);
        assert_eq!(a.lod(1, Vec2::new(4.0 / 64.0, 0.0), Vec2::new(0.0, 1.0 / 16.0)), 0.0);
        assert_eq!(a.lod(0, Vec2::new(0.1 / 64.0, 0.0), Vec2::ZERO), 0.0, "magnification reads level 0");
    }
}
