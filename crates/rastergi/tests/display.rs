//! The display pass shows exactly the bytes of the display image (the PNG screenshot): on a
//! plain `*Unorm` target as they are, on an `*Srgb` target through decode + hardware encode;
//! a moving frame's preview, upscaled, as bilinear between its pixel centres; and its overlay
//! darkens a box and lights glyph texels on top.

mod common;

use rastergi::gpu::Gpu;
use rastergi::passes::display::{DisplayPass, needs_decode, text_scale};
use rastergi::renderer::Renderer;
use rastergi::scene::cornell_box;
use rastergi::settings::RenderSettings;

/// Draws the renderer's film (resolved for the full image at `exposure`) with `overlay` onto
/// a `format` texture of the film's size and reads it back as RGBA8 rows.
fn draw(gpu: &Gpu, renderer: &Renderer, format: wgpu::TextureFormat, overlay: &[String]) -> Vec<u8> {
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    renderer.encode_resolve(&mut enc, rastergi::passes::film::Show::Full, 0.5);
    draw_resolved(gpu, renderer, enc, format, overlay)
}

/// Draws the renderer's film as last resolved (after `enc`'s work) onto a `format` texture of
/// the film's size and reads it back as RGBA8 rows.
fn draw_resolved(
    gpu: &Gpu,
    renderer: &Renderer,
    mut enc: wgpu::CommandEncoder,
    format: wgpu::TextureFormat,
    overlay: &[String],
) -> Vec<u8> {
    let (w, h) = (renderer.settings().width, renderer.settings().height);
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("display target"),
        size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());
    let mut pass = DisplayPass::new(gpu, format);
    pass.encode(gpu, &mut enc, &view, (w, h), Some(renderer.film()), overlay);
    let row = (w * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let buffer = gpu.zeroed_buffer(
        "display readback",
        (row * h) as u64,
        wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
    );
    enc.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(h) },
        },
        wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
    );
    gpu.queue.submit([enc.finish()]);
    let bytes = gpu.read_buffer(&buffer, buffer.size()).unwrap();
    (0..h as usize).flat_map(|y| bytes[y * row as usize..y * row as usize + w as usize * 4].to_vec()).collect()
}

fn renderer(gpu: &Gpu, w: u32, h: u32) -> Renderer {
    let settings = RenderSettings { width: w, height: h, photons: 1 << 14, grid_resolution: 16, ..Default::default() };
    let mut r = Renderer::new(gpu, &cornell_box(), settings).unwrap();
    for _ in 0..2 {
        r.iterate().unwrap();
    }
    r
}

#[test]
fn window_shows_the_screenshot_bytes_on_plain_and_srgb_targets() {
    let gpu = common::gpu();
    // Not square: a swapped width and height would show.
    let r = renderer(&gpu, 24, 16);
    let expected = r.read_display(rastergi::passes::film::Show::Full, 0.5).unwrap().rgba;
    assert!(expected.chunks(4).any(|p| p[0] > 40 && p[0] < 250), "a lit, unsaturated pixel to compare");
    for format in [wgpu::TextureFormat::Rgba8Unorm, wgpu::TextureFormat::Rgba8UnormSrgb] {
        let shown = draw(&gpu, &r, format, &[]);
        assert_eq!(needs_decode(format), format.is_srgb());
        // Decode in f32 then the hardware's encode may round a value to its neighbour.
        let worst = shown.iter().zip(&expected).map(|(a, b)| a.abs_diff(*b)).max().unwrap();
        let tolerance = if format.is_srgb() { 1 } else { 0 };
        assert!(worst <= tolerance, "{format:?}: bytes differ by up to {worst}");
    }
}

#[test]
fn overlay_lights_glyphs_over_a_darkened_box_and_leaves_the_rest() {
    let gpu = common::gpu();
    let (w, h) = (64u32, 48u32);
    let r = renderer(&gpu, w, h);
    let plain = draw(&gpu, &r, wgpu::TextureFormat::Rgba8Unorm, &[]);
    let text = draw(&gpu, &r, wgpu::TextureFormat::Rgba8Unorm, &["#".into()]);
    assert_eq!(text_scale(h), 1);
    // The box: one 8×8 cell at (4, 4) plus a 4-pixel margin: pixels [0, 16)².
    let at = |img: &[u8], x: u32, y: u32| -> [u8; 4] {
        let i = 4 * (y * w + x) as usize;
        img[i..i + 4].try_into().unwrap()
    };
    let (mut lit, mut dark) = (0, 0);
    for y in 0..h {
        for x in 0..w {
            let (p, q) = (at(&plain, x, y), at(&text, x, y));
            if x >= 16 || y >= 16 {
                assert_eq!(p, q, "outside the box at ({x}, {y})");
            } else if q[..2] == [255, 255] && q[2] > 200 {
                lit += 1;
                assert!((4..12).contains(&x) && (4..12).contains(&y), "glyph texel outside its cell at ({x}, {y})");
            } else {
                dark += 1;
                assert!(q[..3].iter().zip(&p[..3]).all(|(a, b)| a <= b), "box darkens at ({x}, {y})");
            }
        }
    }
    // '#' lights a good part of its cell, and not all of it.
    assert!((10..50).contains(&lit), "{lit} glyph texels");
    assert!(dark > 16 * 16 - 64, "{dark}");
}

/// A moving frame whose film holds nothing yet shows the preview's own resolve, upscaled by the
/// display pass: each window pixel bilinear between the preview pixels' centres around its own
/// centre (as the resolve stretches a preview), of the preview's display bytes, computed here
/// on the CPU from those bytes — within one step of rounding. Once the film has an iteration
/// nothing is upscaled and the display shows the film's own resolve again.
#[test]
fn a_moving_frames_preview_is_upscaled_between_its_pixel_centres() {
    let gpu = common::gpu();
    let (w, h) = (64u32, 40u32);
    let settings = RenderSettings { width: w, height: h, photons: 1 << 14, grid_resolution: 16, ..Default::default() };
    let mut r = Renderer::new(&gpu, &cornell_box(), settings).unwrap();
    for _ in 0..2 {
        while !r.iterate_preview_rows(4, 64).unwrap() {}
    }
    let show = (rastergi::passes::film::Show::Full, 0.5);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    assert!(r.encode_resolve_upscaled(&mut enc, show, Some((4, 2.0))), "the film is empty: the preview is upscaled");
    let shown = draw_resolved(&gpu, &r, enc, wgpu::TextureFormat::Rgba8Unorm, &[]);
    let pre = r.preview_film(4).unwrap().read_display_buffer(&gpu).unwrap();
    assert_eq!((pre.width, pre.height), (16, 10));
    let texel = |x: f32, y: f32, c: usize| {
        let (x, y) = (x.clamp(0.0, 15.0) as usize, y.clamp(0.0, 9.0) as usize);
        f32::from(pre.rgba[4 * (y * 16 + x) + c])
    };
    let mut worst = 0.0f32;
    for y in 0..h {
        for x in 0..w {
            let (px, py) = ((x as f32 + 0.5) / 4.0 - 0.5, (y as f32 + 0.5) / 4.0 - 0.5);
            let (bx, by) = (px.floor(), py.floor());
            let (fx, fy) = (px - bx, py - by);
            for c in 0..3 {
                let top = texel(bx, by, c) * (1.0 - fx) + texel(bx + 1.0, by, c) * fx;
                let bottom = texel(bx, by + 1.0, c) * (1.0 - fx) + texel(bx + 1.0, by + 1.0, c) * fx;
                let want = top * (1.0 - fy) + bottom * fy;
                worst = worst.max((f32::from(shown[4 * (y * w + x) as usize + c]) - want).abs());
            }
        }
    }
    assert!(worst <= 1.0, "the upscaled preview differs from its bilinear by up to {worst} steps");
    assert!(pre.rgba.chunks(4).any(|p| p[0] > 40 && p[0] < 250), "a lit, unsaturated pixel to compare");
    // An iteration of the window's own: its resolve, not the preview's.
    r.iterate().unwrap();
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    assert!(!r.encode_resolve_upscaled(&mut enc, show, Some((4, 2.0))));
    r.encode_resolve(&mut enc, show.0, show.1);
    let own = draw_resolved(&gpu, &r, enc, wgpu::TextureFormat::Rgba8Unorm, &[]);
    assert_eq!(own, r.film().read_display_buffer(&gpu).unwrap().rgba, "the film's own resolve is not what is shown");
}
