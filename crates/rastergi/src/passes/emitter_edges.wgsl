// Emitter-edges passes (emitter_edges.rs). `keys`: the key of what each pixel's centre sees as
// light (light_seen_through, visible_point.wgsl), over the band's rows and the row below it;
// `flags`: then, over the band's rows, whether the pixel's 3 × 3 neighbourhood holds different
// keys (EDGE_FLAG added). Both kept in the w of the pixel's second eye-path slot, as a float
// (exact: keys below EDGE_FLAG), for the direct pass and the denoiser's guides
// (on_emitter_edge). A row's flag needs the keys of the rows beside it: the band before this
// one wrote the row above, this one writes the row below before the next band flags it.

fn edge_slot(xy: vec2u) -> u32 {
    return 3u * pixel_index(xy) + 1u;
}

@compute @workgroup_size(8, 8)
fn keys(@builtin(global_invocation_id) id: vec3u) {
    let xy = band_pixel(id).xy;
    if any(xy >= frame.resolution) || xy.y > frame.band_y0 + frame.band_rows {
        return;
    }
    start_alpha_stream();
    eye_paths[edge_slot(xy)].w = f32(light_seen_through(vec2f(xy) + 0.5).key);
}

@compute @workgroup_size(8, 8)
fn flags(@builtin(global_invocation_id) id: vec3u) {
    let xy = band_pixel(id).xy;
    if !begin_pixel(xy) {
        return;
    }
    // The keys without the flags (a neighbour's may already be flagged).
    let k = edge_key(xy);
    let lo = max(vec2i(xy) - 1, vec2i(0));
    let hi = min(vec2i(xy) + 1, vec2i(frame.resolution) - 1);
    var edge = false;
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            edge = edge || edge_key(vec2u(vec2i(x, y))) != k;
        }
    }
    if edge {
        eye_paths[edge_slot(xy)].w = f32(k + EDGE_FLAG);
    }
}
