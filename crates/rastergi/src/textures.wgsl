// The texture atlas (textures.rs, TextureAtlas): every texture's mip chain at its own size,
// one run of texels held as the rows of the 2D texture `textures` (texel i at column i % ROW,
// row i / ROW), filtered here exactly as TextureAtlas::sample filters on the CPU. The includer
// declares `textures: texture_2d<f32>` and `atlas_entry_word(i)`, word i of the entries
// (AtlasEntry: width, height, levels, first texel; four words each). ATLAS_ROW is
// textures::ROW (shader.rs's constants).

fn atlas_entry(t: u32) -> AtlasEntry {
    let i = 4u * t;
    return AtlasEntry(atlas_entry_word(i), atlas_entry_word(i + 1u), atlas_entry_word(i + 2u), atlas_entry_word(i + 3u));
}

fn atlas_texel(i: u32) -> vec4f {
    return textureLoad(textures, vec2u(i % ATLAS_ROW, i / ATLAS_ROW), 0);
}

// Bilinear filtering of the w × h level starting at texel `first`, at st, repeat addressing:
// st wrapped to [0, 1), the four texels around st·(w, h) − ½ (TextureAtlas::bilinear).
fn atlas_bilinear(first: u32, w: u32, h: u32, st: vec2f) -> vec4f {
    let f = st - floor(st);
    let p = f * vec2f(f32(w), f32(h)) - 0.5;
    let p0 = floor(p);
    let a = p - p0;
    // p0 ∈ [−1, side − 1]: −1 wraps to the last texel, side to the first.
    let x0 = select(min(u32(max(p0.x, 0.0)), w - 1u), w - 1u, p0.x < 0.0);
    let y0 = select(min(u32(max(p0.y, 0.0)), h - 1u), h - 1u, p0.y < 0.0);
    let x1 = select(x0 + 1u, 0u, x0 + 1u >= w);
    let y1 = select(y0 + 1u, 0u, y0 + 1u >= h);
    let top = atlas_texel(first + y0 * w + x0) * (1.0 - a.x) + atlas_texel(first + y0 * w + x1) * a.x;
    let bottom = atlas_texel(first + y1 * w + x0) * (1.0 - a.x) + atlas_texel(first + y1 * w + x1) * a.x;
    return top * (1.0 - a.y) + bottom * a.y;
}

// Texture t at st and level of detail lod: trilinear, lod clamped to [0, levels − 1], a NaN
// lod read as 0 (TextureAtlas::sample_rgba).
fn atlas_sample(t: u32, st: vec2f, lod: f32) -> vec4f {
    let e = atlas_entry(t);
    let last = e.levels - 1u;
    var l = clamp(lod, 0.0, f32(last));
    if !(lod >= 0.0 || lod < 0.0) {
        l = 0.0;
    }
    // Bounded whatever the float conversion gives: the loop below runs at most `last` times.
    let k = min(u32(floor(l)), last);
    let f = l - f32(k);
    var first = e.first;
    var w = e.width;
    var h = e.height;
    for (var j = 0u; j < k; j++) {
        first += w * h;
        w = max(w / 2u, 1u);
        h = max(h / 2u, 1u);
    }
    let lo = atlas_bilinear(first, w, h, st);
    if f > 0.0 && k < last {
        return lo * (1.0 - f) + atlas_bilinear(first + w * h, max(w / 2u, 1u), max(h / 2u, 1u), st) * f;
    }
    return lo;
}

// Level of detail of a footprint on texture t whose coordinates change by dx and dy across one
// pixel: log2 of the longer change in texels of the texture's level 0, 0 under magnification
// (TextureAtlas::lod).
fn texture_lod(t: u32, dx: vec2f, dy: vec2f) -> f32 {
    let e = atlas_entry(t);
    let size = vec2f(f32(e.width), f32(e.height));
    let rho = max(length(dx * size), length(dy * size));
    return min(log2(max(rho, 1.0)), 32.0);
}
