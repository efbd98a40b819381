// Display (display.rs): draws the film's resolved display image — packed RGBA8, already
// sRGB-encoded by resolve.wgsl — onto a window's surface, with a text overlay on top.
// One full-screen triangle; each fragment looks up its image pixel and overlay glyph.

@group(0) @binding(0) var<uniform> params: Display;
// One packed RGBA8 (pack4x8unorm) sRGB pixel per element, row 0 at the top.
@group(0) @binding(1) var<storage, read> image: array<u32>;
// 8×8 glyphs of characters 0..127: glyph c's rows 0..3 in font[2c], rows 4..7 in
// font[2c + 1], one byte per row, bit 0 the leftmost pixel.
@group(0) @binding(2) var<storage, read> font: array<u32>;
// Overlay characters, four per element (byte k of element i is character 4i + k), row-major
// in a text_cols × text_rows grid.
@group(0) @binding(3) var<storage, read> text: array<u32>;

const BACKGROUND: vec3f = vec3f(0.08, 0.08, 0.09);
const TEXT_COLOR: vec3f = vec3f(1.0, 1.0, 0.85);
const TEXT_MARGIN: u32 = 4u;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4f {
    // A triangle covering the viewport: (-1,-1), (3,-1), (-1,3).
    let p = vec2f(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4f(p * 2.0 - 1.0, 0.0, 1.0);
}

// The sRGB transfer function's inverse (IEC 61966-2-1).
fn srgb_decode(c: vec3f) -> vec3f {
    let lo = c / 12.92;
    let hi = pow((c + 0.055) / 1.055, vec3f(2.4));
    return select(hi, lo, c <= vec3f(0.04045));
}

// The film pixel shown at target pixel `p`: the image scaled to fit, centred, nearest
// neighbour; the identity when the sizes agree. The background colour off the image. Where the
// display buffer holds a smaller image of the same view (params.source_size, a moving frame's
// preview), the film pixel's value is that image's, bilinear between its pixel centres as the
// resolve stretches a preview over the film (resolve.wgsl's preview_mean), of the encoded
// values.
fn image_at(p: vec2f) -> vec3f {
    let image_size = vec2f(params.image_size);
    if params.image_size.x == 0u || params.image_size.y == 0u {
        return BACKGROUND;
    }
    let target_size = vec2f(params.target_size);
    let s = min(target_size.x / image_size.x, target_size.y / image_size.y);
    let offset = floor(0.5 * (target_size - image_size * s));
    let q = floor((floor(p) - offset) / s);
    if any(q < vec2f(0.0)) || any(q >= image_size) {
        return BACKGROUND;
    }
    if all(params.source_size == params.image_size) {
        let i = u32(q.y) * params.image_size.x + u32(q.x);
        return unpack4x8unorm(image[i]).rgb;
    }
    let size = vec2f(params.source_size);
    let c = (q + 0.5) * size / image_size - 0.5;
    let base = floor(c);
    let f = c - base;
    let lo = vec2u(clamp(base, vec2f(0.0), size - 1.0));
    let hi = vec2u(clamp(base + 1.0, vec2f(0.0), size - 1.0));
    let w = params.source_size.x;
    let top = mix(unpack4x8unorm(image[lo.y * w + lo.x]).rgb, unpack4x8unorm(image[lo.y * w + hi.x]).rgb, f.x);
    let bottom = mix(unpack4x8unorm(image[hi.y * w + lo.x]).rgb, unpack4x8unorm(image[hi.y * w + hi.x]).rgb, f.x);
    return mix(top, bottom, f.y);
}

// Overlay coverage at target pixel `p`: x = 1 on a glyph's lit texel, y = 1 inside the
// text box (the image darkens there for legibility).
fn overlay_at(p: vec2u) -> vec2f {
    let scale = max(params.text_scale, 1u);
    let cell = 8u * scale;
    let text_size = vec2u(params.text_cols, params.text_rows) * cell;
    // The box: the text plus a margin on every side, in the top-left corner.
    if params.text_rows == 0u || any(p >= text_size + vec2u(2u * TEXT_MARGIN)) {
        return vec2f(0.0);
    }
    if any(p < vec2u(TEXT_MARGIN)) || any(p - vec2u(TEXT_MARGIN) >= text_size) {
        return vec2f(0.0, 1.0);
    }
    let local = p - vec2u(TEXT_MARGIN);
    let index = (local.y / cell) * params.text_cols + local.x / cell;
    let c = (text[index / 4u] >> (8u * (index % 4u))) & 0x7fu;
    let texel = (local % vec2u(cell)) / scale;
    let bits = font[2u * c + texel.y / 4u] >> (8u * (texel.y % 4u));
    return vec2f(f32((bits >> texel.x) & 1u), 1.0);
}

@fragment
fn fs_main(@builtin(position) frag: vec4f) -> @location(0) vec4f {
    // Compose in the film's sRGB encoding, then decode for a linear target.
    var color = image_at(frag.xy);
    let overlay = overlay_at(vec2u(frag.xy));
    color = mix(color, color * 0.35, overlay.y);
    color = mix(color, TEXT_COLOR, overlay.x);
    if params.decode_srgb == 1u {
        color = srgb_decode(color);
    }
    return vec4f(color, 1.0);
}
