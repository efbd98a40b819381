// Final gather projection (gather/raster.rs): each peeled layer projected onto the eye's
// visible points; the estimate is gather_estimate (estimator.wgsl). Every layer serves both
// sides of the ray view: a point whose surface faces ω gathers along ω and takes the first
// layer (back to front) in front of it; one facing −ω gathers along −ω and keeps the nearest
// layer behind it, resolved once all layers are peeled (resolve_behind).

@group(2) @binding(0) var<uniform> gather: Gather;
@group(2) @binding(1) var gbuffer: texture_2d<u32>;
@group(2) @binding(2) var layer: texture_2d<u32>;
// Per eye pixel: 1 once its gather ray for this direction is resolved (hit, miss or no
// contribution), so later layers no longer count.
@group(2) @binding(3) var<storage, read_write> found: array<u32>;
@group(2) @binding(4) var<storage, read_write> film: array<vec4f>;
// Per eye pixel gathering along −ω: the nearest surface behind it so far, (triangle + 1,
// distance bits); 0 where none.
@group(2) @binding(5) var<storage, read_write> behind: array<vec2u>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if !begin_pixel(gid.xy) { return; }
    let pixel = pixel_index(gid.xy);
    if found[pixel] != 0u {
        return;
    }
    let p = visible_point_at(gid.xy);
    let w = gather_side(p.n, gather.direction);
    let cos_x = gather_cosine(p, w);
    if !p.ok || cos_x <= 0.0 {
        found[pixel] = 1u;
        return;
    }
    let l = textureLoad(layer, ray_view_texel(p.x.pos), 0);
    if l.x == 0u {
        // Nothing at this texel in this layer, hence in no later (nearer) layer: along ω the ray
        // escapes; along −ω the nearest surface behind x, if any, is in `behind`.
        found[pixel] = 1u;
        if dot(w, gather.direction) > 0.0 {
            film_add(FILM_DIRECT, gid.xy, p.weight * (escape_estimate(p, cos_x, w) / f32(gather.count)));
        }
        return;
    }
    let tri = l.x - 1u;
    if tri == p.x.tri {
        return;
    }
    // Where x's ray meets the plane of the layer's triangle: in front of x, or not a hit.
    let dist = plane_distance(tri, p.x.pos, w);
    if dot(w, gather.direction) > 0.0 {
        // Ray-view depth falls along ω and the layers come farthest first: the first one in
        // front of x is the nearest hit.
        if dist <= frame.ray_epsilon {
            return;
        }
        found[pixel] = 1u;
        film_add(FILM_INDIRECT, gid.xy, p.weight * (texel_estimate(p, cos_x, w, tri, dist, pixel) / f32(gather.count)));
        return;
    }
    // Along −ω the layers come farthest first: keep the nearest behind x. Once a layer lies in
    // front of x (its plane crosses x's −ω ray before x), so do all later ones.
    if dist > frame.ray_epsilon {
        let b = behind[pixel];
        if b.x == 0u || dist < bitcast<f32>(b.y) {
            behind[pixel] = vec2u(tri + 1u, bitcast<u32>(dist));
        }
    } else if dist < -frame.ray_epsilon && dist > PLANE_PARALLEL {
        found[pixel] = 1u;
    }
}

// After the last layer: the estimate of each point gathering along −ω from the nearest surface
// behind it; and the environment for every ray that found no surface: along −ω none behind,
// along ω no layer in front of x (an empty texel already counted its escape; where every layer
// of x's texel lies behind x or is x's own, none was empty).
@compute @workgroup_size(8, 8)
fn resolve_behind(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if !begin_pixel(gid.xy) { return; }
    let pixel = pixel_index(gid.xy);
    let b = behind[pixel];
    if b.x != 0u {
        let p = visible_point_at(gid.xy);
        let w = -gather.direction;
        film_add(FILM_INDIRECT, gid.xy, p.weight * (texel_estimate(p, gather_cosine(p, w), w, b.x - 1u, bitcast<f32>(b.y), pixel) / f32(gather.count)));
        return;
    }
    if !has_environment() {
        return;
    }
    let p = visible_point_at(gid.xy);
    let w = gather_side(p.n, gather.direction);
    let cos_x = gather_cosine(p, w);
    let along = dot(w, gather.direction) > 0.0;
    if p.ok && cos_x > 0.0 && (!along || found[pixel] == 0u) {
        film_add(FILM_DIRECT, gid.xy, p.weight * (escape_estimate(p, cos_x, w) / f32(gather.count)));
    }
}
