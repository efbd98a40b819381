//! The display pass shows exactly the bytes of the display image (the PNG screenshot): on a
//! plain `*Unorm` target as they are, on an `*Srgb` target through decode + hardware encode;
//! and its overlay darkens a box and lights glyph texels on top.

mod common;

use rastergi::gpu::Gpu;
use rastergi::passes::display::{DisplayPass, needs_decode, text_scale};
use rastergi::renderer::Renderer;
use rastergi::scene::cornell_box;
use rastergi::settings::RenderSettings;

/// Draws the renderer's film (resolved for the full image at `exposure`) with `overlay` onto
/// a `format` texture of the film's size and reads it back as RGBA8 rows.
fn draw(gpu: &Gpu, renderer: &Renderer, format: wgpu::TextureFormat, overlay: &[String]) -> Vec<u8> {
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
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    renderer.encode_resolve(&mut enc, rastergi::passes::film::Show::Full, 0.5);
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
