// History (history.rs): what the film held before a camera move, kept and re-projected onto
// the new view for the display. Prelude: the per-pixel passes' (scene, frame, visible points,
// film); bind group 3 below.

@group(3) @binding(0) var<uniform> history_params: HistoryParams;
// Per pixel of the view before the move: the film's mean of the shown component (rgb) and what
// it saw (w, bitcast `seen_key`).
@group(3) @binding(1) var<storage, read_write> history: array<vec4f>;
// Per pixel of the new view: the history's mean where the same triangle is seen through the
// old view (rgb; w = 1, or 2 where either pixel straddles an edge of light), else 0.
@group(3) @binding(2) var<storage, read_write> reprojected: array<vec4f>;

// The film's mean of the shown component at pixel `p` of the view before the move.
fn film_mean(p: u32, y: u32) -> vec3f {
    let n = frame.resolution.x * frame.resolution.y;
    let direct = film[film_slot(FILM_DIRECT, p, n)].rgb;
    let indirect = film[film_slot(FILM_INDIRECT, p, n)].rgb;
    var sum = direct + indirect;
    switch history_params.show {
        case 1u: { sum = direct; }
        case 2u: { sum = indirect; }
        case 3u: { sum = film[film_slot(FILM_PHOTON_VIEW, p, n)].rgb; }
        default: {}
    }
    let samples = history_params.samples + select(0u, 1u, y < history_params.rows_ahead);
    return sum / f32(max(samples, 1u));
}

// What G-buffer texel `g` sees from the frame's eye: 0 the sky, else the triangle + 1 and, in
// the top bit, whether it is its back (a wall seen from outside is not its inside).
fn seen_key(g: vec4u) -> u32 {
    if g.x == 0u {
        return 0u;
    }
    let s = surface_at(g.x - 1u, bitcast<f32>(g.y), bitcast<f32>(g.z), bitcast<f32>(g.w));
    let back = dot(s.normal, frame.eye - s.pos) < 0.0;
    return g.x | select(0u, 0x80000000u, back);
}

// Marks a kept pixel at an edge of light (seen_key's bit 30; triangle + 1 stays below it).
const MIXED: u32 = 0x40000000u;

// The share of the old film's iterations at pixel xy whose sample saw light itself (the direct
// component's fourth channel counts them).
fn light_share(xy: vec2u) -> f32 {
    let n = history_params.samples + select(0u, 1u, xy.y < history_params.rows_ahead);
    let seen = film[film_slot(FILM_DIRECT, pixel_index(xy), frame.resolution.x * frame.resolution.y)].w;
    return seen / f32(max(n, 1u));
}

// Whether the old film's samples show an edge of an emitter or of the sky at pixel xy (the
// shares of its 3 × 3 neighbourhood differ): such a pixel's mean is a mix of both sides in
// proportions that a pixel of the new view, straddling the edge elsewhere, does not share —
// better than nothing, worse than any sample of the new view's own.
fn light_edge(xy: vec2u) -> bool {
    let s = light_share(xy);
    let lo = max(vec2i(xy) - 1, vec2i(0));
    let hi = min(vec2i(xy) + 1, vec2i(frame.resolution) - 1);
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            if light_share(vec2u(vec2i(x, y))) != s {
                return true;
            }
        }
    }
    return false;
}

// What G-buffer texel g sees as light (light_seen_through's keys, textures aside): 1 the sky,
// 2 + m an emitter's front face of material m, 0 anything else.
fn texel_light_key(g: vec4u) -> u32 {
    if g.x == 0u {
        return 1u;
    }
    let t = triangles[g.x - 1u];
    let b = vec2f(bitcast<f32>(g.y), bitcast<f32>(g.z));
    let pos = t.v0 * (1.0 - b.x - b.y) + t.v1 * b.x + t.v2 * b.y;
    let front = dot(triangle_normal(t), frame.eye - pos) > 0.0;
    if front && any(materials[t.material].material.emission > vec3f(0.0)) {
        return 2u + t.material;
    }
    return 0u;
}

// Whether the G-buffer's texels show an edge of light at pixel xy: the keys of its 3 × 3
// neighbourhood differ.
fn texels_light_edge(xy: vec2u) -> bool {
    let k = texel_light_key(textureLoad(gbuffer, xy, 0));
    let lo = max(vec2i(xy) - 1, vec2i(0));
    let hi = min(vec2i(xy) + 1, vec2i(frame.resolution) - 1);
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            if texel_light_key(textureLoad(gbuffer, vec2i(x, y), 0)) != k {
                return true;
            }
        }
    }
    return false;
}

// Before the move (the frame still the old view's): keeps the film's mean and what each pixel
// sees, marked MIXED at an edge of light: where the film's samples show one, or the G-buffer's
// texels (the film's mean there may be the supersampled coverage, emitter_edges.rs, though its
// samples all saw the light).
@compute @workgroup_size(8, 8)
fn snapshot(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if !begin_pixel(gid.xy) { return; }
    let p = pixel_index(gid.xy);
    let g = textureLoad(gbuffer, gid.xy, 0);
    let key = seen_key(g) | select(0u, MIXED, light_edge(gid.xy) || texels_light_edge(gid.xy));
    history[p] = vec4f(film_mean(p, gid.y), bitcast<f32>(key));
}

// After it (the frame and the G-buffer the new view's, without jitter): the old view's pixel
// that saw this pixel's point (the sky: its direction), if it saw the same side of the same
// triangle there.
@compute @workgroup_size(8, 8)
fn reproject(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if !begin_pixel(gid.xy) { return; }
    let p = pixel_index(gid.xy);
    reprojected[p] = vec4f(0.0);
    let g = textureLoad(gbuffer, gid.xy, 0);
    var clip: vec4f;
    if g.x == 0u {
        clip = history_params.view_proj * vec4f(camera_ray(vec2f(gid.xy) + 0.5), 0.0);
    } else {
        let s = surface_at(g.x - 1u, bitcast<f32>(g.y), bitcast<f32>(g.z), bitcast<f32>(g.w));
        clip = history_params.view_proj * vec4f(s.pos, 1.0);
    }
    if clip.w <= 0.0 {
        return;
    }
    let ndc = clip.xy / clip.w;
    let res = vec2f(frame.resolution);
    let q = floor(vec2f(0.5 * (ndc.x + 1.0), 0.5 * (1.0 - ndc.y)) * res);
    if any(q < vec2f(0.0)) || any(q >= res) {
        return;
    }
    let h = history[u32(q.y) * frame.resolution.x + u32(q.x)];
    let key = bitcast<u32>(h.w);
    if (key & ~MIXED) == seen_key(g) {
        // Only until the film has an iteration where either view's pixel straddles an edge.
        let mixed = (key & MIXED) != 0u || texels_light_edge(gid.xy);
        reprojected[p] = vec4f(h.rgb, select(1.0, 2.0, mixed));
    }
}
