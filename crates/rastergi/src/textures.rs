//! The scene's albedo textures as the passes sample them, and the CPU twin of that sampling.
//!
//! **One texture array.** Every texture is resampled to one common size W × H and becomes a
//! layer of a single `texture_2d_array`, so one binding and one sampler serve every material
//! and every pass, and the sampler's repeat addressing and trilinear filtering work unchanged
//! (an atlas would need hand-made wrapping and padded mip levels). The texels are linear RGB in
//! half floats (`rgba16float`, filterable everywhere): the sRGB decoding happens here, exactly,
//! so the GPU filters the very values the CPU twin reads (hardware sRGB decoding is only
//! approximately specified: lavapipe's is off by up to 0.7 %), and 11 significant bits keep
//! more precision than 8-bit sRGB at every level. The alpha channel (opacity) is linear, c/255,
//! and so are the RGB of textures holding data rather than colour (normal maps,
//! [`Texture::linear`]).
//! W and H are the largest texture's sides rounded up to powers of two, at most
//! [`MAX_SIDE`], halved (the longer one first) until the whole chain fits [`BUDGET_BYTES`].
//! Resampling happens in linear RGB with a tent filter as wide as the larger of one source
//! texel and one destination texel: bilinear interpolation when enlarging (what the GPU's
//! magnification filter would have shown of the original), an area-weighted average when
//! shrinking.
//!
//! **Mip maps.** The full chain down to 1 × 1 is computed here: each level is the 2 × 2 box
//! average of the previous one in linear RGB (W and H are powers of two, so the boxes tile
//! exactly; a side that reached 1 averages 2 × 1), computed in f32 and stored rounded to f16.
//!
//! **Sampling.** Trilinear: repeat addressing, bilinear within a level, linear between the
//! two levels around the level of detail λ, clamped to [0, levels − 1]. The
//! passes give λ explicitly (`textureSampleLevel`): at the eye's visible points
//! λ = log2 max(|∂uv/∂x|, |∂uv/∂y|) in texels of level 0, from the G-buffer's screen-space
//! derivatives (or the path tracer's ray differentials); at every secondary point (photon
//! hits, gather hits, path bounces) λ = 0, the unfiltered texture: those points are averaged
//! over many samples, and a footprint filter there would only add a bias. [`TextureArray`]
//! holds the very texels the GPU samples, and [`TextureArray::sample`] is its twin.

use glam::{Vec2, Vec3, Vec4};

use crate::error::{Error, Result};
use crate::gpu::{Gpu, sampler_entry, storage_entry, texture_array_entry};
use crate::scene::Texture;
use crate::shader;

/// Largest side of the common layer size (WebGPU guarantees 8192).
pub const MAX_SIDE: u32 = 4096;
/// Largest size of the texture array with all its mip levels.
pub const BUDGET_BYTES: u64 = 256 << 20;
pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Bytes per texel of [`FORMAT`].
const TEXEL_BYTES: u64 = 8;

/// The layers of the texture array with their mip chains, exactly as uploaded.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureArray {
    /// Size of level 0.
    pub width: u32,
    pub height: u32,
    pub layers: u32,
    /// `levels[k]`: level k of every layer, layer after layer, rows from the top; linear RGBA
    /// as f16 bits.
    pub levels: Vec<Vec<[u16; 4]>>,
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

/// Size in bytes of a chain of levels starting at `w × h`, with `layers` layers.
fn chain_bytes(w: u32, h: u32, layers: u32) -> u64 {
    let (mut w, mut h, mut total) = (w as u64, h as u64, 0u64);
    loop {
        total += w * h * TEXEL_BYTES * layers as u64;
        if w == 1 && h == 1 {
            return total;
        }
        w = (w / 2).max(1);
        h = (h / 2).max(1);
    }
}

/// The common layer size for textures of these sizes (see the module documentation).
pub fn common_size(sizes: &[(u32, u32)]) -> (u32, u32) {
    let fit = |s: u32| s.max(1).next_power_of_two().min(MAX_SIDE);
    let mut w = fit(sizes.iter().map(|s| s.0).max().unwrap_or(1));
    let mut h = fit(sizes.iter().map(|s| s.1).max().unwrap_or(1));
    let layers = sizes.len().max(1) as u32;
    while chain_bytes(w, h, layers) > BUDGET_BYTES && (w > 1 || h > 1) {
        if w >= h {
            w = (w / 2).max(1);
        } else {
            h = (h / 2).max(1);
        }
    }
    (w, h)
}

/// Resamples one axis of a `n`-long periodic signal to `m` samples: a tent filter of radius
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

/// A texture's texels as linear RGBA (sRGB colour decoded, linear data and alpha as c/255),
/// resampled to `dw × dh` with repeat addressing. The texels are decoded as they are read: no
/// linear copy of a large source is made.
fn resample(t: &Texture, dw: u32, dh: u32) -> Vec<Vec4> {
    let (sw, sh, dw, dh) = (t.width as usize, t.height as usize, dw as usize, dh as usize);
    let rgb = |c: u8| if t.linear { c as f32 / 255.0 } else { srgb_to_linear(c) };
    let src = |i: usize| {
        let p = t.texels[i];
        Vec4::new(rgb(p[0]), rgb(p[1]), rgb(p[2]), p[3] as f32 / 255.0)
    };
    if (sw, sh) == (dw, dh) {
        return (0..sw * sh).map(src).collect();
    }
    let xs = resample_axis(sw, dw);
    let ys = resample_axis(sh, dh);
    let mut rows = vec![Vec4::ZERO; dw * sh];
    for y in 0..sh {
        for (x, taps) in xs.iter().enumerate() {
            rows[y * dw + x] = taps.iter().map(|&(i, w)| src(y * sw + i) * w).sum();
        }
    }
    let mut out = vec![Vec4::ZERO; dw * dh];
    for (y, taps) in ys.iter().enumerate() {
        for x in 0..dw {
            out[y * dw + x] = taps.iter().map(|&(i, w)| rows[i * dw + x] * w).sum();
        }
    }
    out
}

/// The 2 × 2 box average of a `w × h` level (a side of 1 stays 1).
fn downsample(src: &[Vec4], w: u32, h: u32) -> (Vec<Vec4>, u32, u32) {
    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
    let (fx, fy) = ((w / nw) as usize, (h / nh) as usize);
    let mut out = Vec::with_capacity((nw * nh) as usize);
    for y in 0..nh as usize {
        for x in 0..nw as usize {
            let mut sum = Vec4::ZERO;
            for dy in 0..fy {
                for dx in 0..fx {
                    sum += src[(y * fy + dy) * w as usize + x * fx + dx];
                }
            }
            out.push(sum / (fx * fy) as f32);
        }
    }
    (out, nw, nh)
}

fn encode(level: &[Vec4]) -> impl Iterator<Item = [u16; 4]> + '_ {
    let h = |v: f32| half::f16::from_f32(v).to_bits();
    level.iter().map(move |c| c.to_array().map(h))
}

impl TextureArray {
    /// The array of `textures` (a single white texel when there are none, so that the
    /// binding always exists).
    pub fn new(textures: &[Texture]) -> TextureArray {
        if textures.is_empty() {
            let one = half::f16::ONE.to_bits();
            return TextureArray { width: 1, height: 1, layers: 1, levels: vec![vec![[one; 4]]] };
        }
        let sizes: Vec<(u32, u32)> = textures.iter().map(|t| (t.width, t.height)).collect();
        let (width, height) = common_size(&sizes);
        let level_count = width.max(height).ilog2() as usize + 1;
        let mut levels: Vec<Vec<[u16; 4]>> = vec![Vec::new(); level_count];
        for t in textures {
            let (mut level, mut w, mut h) = (resample(t, width, height), width, height);
            for (k, out) in levels.iter_mut().enumerate() {
                if k > 0 {
                    (level, w, h) = downsample(&level, w, h);
                }
                out.extend(encode(&level));
            }
        }
        TextureArray { width, height, layers: textures.len() as u32, levels }
    }

    pub fn level_count(&self) -> u32 {
        self.levels.len() as u32
    }

    /// Size of mip level `k`.
    pub fn level_size(&self, k: usize) -> (u32, u32) {
        ((self.width >> k).max(1), (self.height >> k).max(1))
    }

    /// The linear RGB of texel (x, y) of `layer` at level `k`.
    pub fn texel(&self, k: usize, layer: u32, x: u32, y: u32) -> Vec3 {
        self.texel_rgba(k, layer, x, y).truncate()
    }

    /// The linear RGB and alpha of texel (x, y) of `layer` at level `k`.
    pub fn texel_rgba(&self, k: usize, layer: u32, x: u32, y: u32) -> Vec4 {
        let (w, h) = self.level_size(k);
        let p = self.levels[k][((layer * h + y) * w + x) as usize].map(|b| half::f16::from_bits(b).to_f32());
        Vec4::from_array(p)
    }

    /// Bilinear filtering of level `k` at `uv`, repeat addressing (`textureSampleLevel` within
    /// one level).
    fn bilinear(&self, k: usize, layer: u32, uv: Vec2) -> Vec4 {
        let (w, h) = self.level_size(k);
        let x = uv.x * w as f32 - 0.5;
        let y = uv.y * h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (a, b) = (x - x0, y - y0);
        let wrap = |i: f32, n: u32| (i as i64).rem_euclid(n as i64) as u32;
        let (x0, x1) = (wrap(x0, w), wrap(x0 + 1.0, w));
        let (y0, y1) = (wrap(y0, h), wrap(y0 + 1.0, h));
        let t = |x, y| self.texel_rgba(k, layer, x, y);
        (t(x0, y0) * (1.0 - a) + t(x1, y0) * a) * (1.0 - b) + (t(x0, y1) * (1.0 - a) + t(x1, y1) * a) * b
    }

    /// Trilinear sample of `layer` at `uv` and level of detail `lod`: the CPU twin of
    /// `textureSampleLevel` with the array's sampler (linear filters, repeat addressing).
    pub fn sample(&self, layer: u32, uv: Vec2, lod: f32) -> Vec3 {
        self.sample_rgba(layer, uv, lod).truncate()
    }

    /// [`TextureArray::sample`] with the alpha channel.
    pub fn sample_rgba(&self, layer: u32, uv: Vec2, lod: f32) -> Vec4 {
        let last = self.levels.len() - 1;
        let lod = if lod.is_nan() { 0.0 } else { lod.clamp(0.0, last as f32) };
        let k = (lod.floor() as usize).min(last);
        let f = lod - k as f32;
        let lo = self.bilinear(k, layer, uv);
        if f > 0.0 && k < last { lo * (1.0 - f) + self.bilinear(k + 1, layer, uv) * f } else { lo }
    }

    /// Level of detail of a footprint whose texture coordinates change by `dx` and `dy` across
    /// one pixel: log2 of the longer change in texels of level 0 (the isotropic formula of the
    /// Vulkan and WebGPU specifications), 0 under magnification. `texture_lod` in WGSL.
    pub fn lod(&self, dx: Vec2, dy: Vec2) -> f32 {
        let size = Vec2::new(self.width as f32, self.height as f32);
        let rho = (dx * size).length().max((dy * size).length());
        if rho.is_nan() { 0.0 } else { rho.max(1.0).log2().min(32.0) }
    }

    /// Checks the array against the device's limits.
    pub fn check_limits(&self, gpu: &Gpu) -> Result<()> {
        let l = gpu.device.limits();
        if self.width.max(self.height) > l.max_texture_dimension_2d || self.layers > l.max_texture_array_layers {
            return Err(Error::Limits(format!(
                "the scene's {} textures need a {}x{} texture array with {} layers, but this GPU allows {} texels per side and {} layers",
                self.layers,
                self.width,
                self.height,
                self.layers,
                l.max_texture_dimension_2d,
                l.max_texture_array_layers
            )));
        }
        Ok(())
    }

    /// Uploads the array with all its levels and creates the sampler every pass uses.
    pub fn upload(&self, gpu: &Gpu) -> (wgpu::TextureView, wgpu::Sampler) {
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("scene textures"),
            size: wgpu::Extent3d { width: self.width, height: self.height, depth_or_array_layers: self.layers },
            mip_level_count: self.level_count(),
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: FORMAT,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        for (k, level) in self.levels.iter().enumerate() {
            let (w, h) = self.level_size(k);
            gpu.queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level: k as u32,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                bytemuck::cast_slice(level),
                wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(TEXEL_BYTES as u32 * w),
                    rows_per_image: Some(h),
                },
                wgpu::Extent3d { width: w, height: h, depth_or_array_layers: self.layers },
            );
        }
        let view = texture.create_view(&wgpu::TextureViewDescriptor {
            label: Some("scene textures"),
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let sampler = gpu.device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("scene textures"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            address_mode_w: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        (view, sampler)
    }
}

/// Samples `array` on the GPU with the passes' sampler: `textureSampleLevel` at each
/// (layer, uv, lod) of `queries`, linear RGB. The GPU side of the CPU twin's tests.
pub fn sample_on_gpu(gpu: &Gpu, array: &TextureArray, queries: &[(u32, Vec2, f32)]) -> Result<Vec<Vec3>> {
    let device = &gpu.device;
    let (view, sampler) = array.upload(gpu);
    let input: Vec<[f32; 4]> = queries.iter().map(|&(layer, uv, lod)| [uv.x, uv.y, lod, layer as f32]).collect();
    let input = gpu.storage_buffer("texture queries", bytemuck::cast_slice(&input), wgpu::BufferUsages::empty());
    let size = (queries.len() as u64 * 16).max(16);
    let output = gpu.zeroed_buffer("texture samples", size, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
    let c = wgpu::ShaderStages::COMPUTE;
    let source = "
        @group(0) @binding(0) var textures: texture_2d_array<f32>;
        @group(0) @binding(1) var texture_sampler: sampler;
        @group(0) @binding(2) var<storage, read> queries: array<vec4f>;
        @group(0) @binding(3) var<storage, read_write> samples: array<vec4f>;
        @compute @workgroup_size(64)
        fn main(@builtin(global_invocation_id) gid: vec3u) {
            if gid.x >= arrayLength(&queries) {
                return;
            }
            let q = queries[gid.x];
            samples[gid.x] = textureSampleLevel(textures, texture_sampler, q.xy, u32(q.w), q.z);
        }";
    let module = shader::module(device, "texture samples", source);
    gpu.run_once(
        "texture samples",
        &module,
        &[
            texture_array_entry(0, c),
            sampler_entry(1, c),
            storage_entry::<[f32; 4]>(2, c, true),
            storage_entry::<[f32; 4]>(3, c, false),
        ],
        &[
            wgpu::BindingResource::TextureView(&view),
            wgpu::BindingResource::Sampler(&sampler),
            input.as_entire_binding(),
            output.as_entire_binding(),
        ],
        queries.len() as u32,
    );
    let bytes = gpu.read_buffer(&output, size)?;
    let samples: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
    Ok(samples[..queries.len()].iter().map(|s| Vec3::new(s[0], s[1], s[2])).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texture(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Texture {
        let texels = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| f(x, y)).collect();
        Texture { name: "t".into(), width: w, height: h, texels, linear: false }
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
    fn common_size_is_the_largest_side_in_powers_of_two_within_the_budget() {
        assert_eq!(common_size(&[(100, 30), (64, 64)]), (128, 64));
        assert_eq!(common_size(&[(1, 1)]), (1, 1));
        assert_eq!(common_size(&[(100_000, 3)]), (MAX_SIDE, 4));
        // 256 layers of 4096²: halved until the chain (4/3 of level 0) fits 256 MiB.
        let (w, h) = common_size(&vec![(4096, 4096); 256]);
        assert!(chain_bytes(w, h, 256) <= BUDGET_BYTES && chain_bytes(2 * w, h, 256) > BUDGET_BYTES);
        assert_eq!((w, h), (256, 256));
    }

    #[test]
    fn mip_levels_are_box_averages_in_linear_space() {
        // A 4×2 texture of black and white columns: level 1 (2×1) is the linear mean 0.5 (sRGB
        // code 188), not the sRGB code 128 (linear 0.216) an average of the codes would give.
        let t = texture(4, 2, |x, _| if x % 2 == 0 { [0, 0, 0, 255] } else { [255; 4] });
        let a = TextureArray::new(&[t]);
        assert_eq!((a.width, a.height, a.level_count()), (4, 2, 3));
        assert_eq!(a.texel(0, 0, 1, 1), Vec3::ONE);
        for (k, x) in [(1, 0), (1, 1), (2, 0)] {
            assert_eq!(a.texel(k, 0, x, 0), Vec3::splat(0.5), "level {k} texel {x}");
        }
    }

    #[test]
    fn smaller_textures_are_enlarged_bilinearly_with_wrapping() {
        // A 2×1 texture (black, white) enlarged to 4×1 next to a 4×1 one: destination texel
        // centres fall at source coordinates −0.25, 0.25, 0.75, 1.25 (texel units, wrapped).
        let small = texture(2, 1, |x, _| if x == 0 { [0, 0, 0, 255] } else { [255; 4] });
        let a = TextureArray::new(&[small, texture(4, 1, |_, _| [0; 4])]);
        assert_eq!((a.width, a.height), (4, 1));
        let row: Vec<f32> = (0..4).map(|x| a.texel(0, 0, x, 0).x).collect();
        let expected = [0.25, 0.25, 0.75, 0.75];
        for (got, want) in row.iter().zip(expected) {
            assert!((got - want).abs() < 5e-4, "{row:?} vs {expected:?}");
        }
    }

    #[test]
    fn sampling_interpolates_within_and_between_levels_and_repeats() {
        let t = texture(4, 4, |x, y| [(x * 60) as u8, (y * 60) as u8, 100, 255]);
        let a = TextureArray::new(&[t]);
        // At a texel centre of level 0 the sample is that texel; one period away too.
        let centre = Vec2::new(1.5 / 4.0, 2.5 / 4.0);
        assert_eq!(a.sample(0, centre, 0.0), a.texel(0, 0, 1, 2));
        assert!((a.sample(0, centre + Vec2::new(3.0, -2.0), 0.0) - a.texel(0, 0, 1, 2)).abs().max_element() < 1e-5);
        // Halfway between two texels of a row: their mean.
        let mid = a.sample(0, Vec2::new(2.0 / 4.0, 0.5 / 4.0), 0.0);
        assert!((mid - 0.5 * (a.texel(0, 0, 1, 0) + a.texel(0, 0, 2, 0))).abs().max_element() < 1e-6);
        // Between levels: the linear blend of the two levels' samples; beyond the last: clamped.
        let uv = Vec2::new(0.3, 0.7);
        let blend = a.sample(0, uv, 1.25);
        let expected = a.sample(0, uv, 1.0) * 0.75 + a.sample(0, uv, 2.0) * 0.25;
        assert!((blend - expected).abs().max_element() < 1e-6);
        assert!((a.sample(0, uv, 7.0) - a.texel(2, 0, 0, 0)).abs().max_element() < 1e-6);
    }

    #[test]
    fn level_of_detail_is_log2_of_the_footprint_in_texels() {
        let a = TextureArray::new(&[texture(64, 16, |_, _| [0; 4])]);
        assert_eq!(a.lod(Vec2::new(4.0 / 64.0, 0.0), Vec2::new(0.0, 1.0 / 16.0)), 2.0);
        assert_eq!(a.lod(Vec2::new(0.1 / 64.0, 0.0), Vec2::ZERO), 0.0, "magnification reads level 0");
    }
}
