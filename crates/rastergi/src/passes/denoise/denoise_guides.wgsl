// Denoiser guides (denoise/mod.rs, Guides): per pixel, after every pass of the iteration has added
// to the film, the sums of the visible point's albedo, distance, shading normal and coverage,
// the sum of the emission the eye sees (what the direct pass adds before any light is
// reflected: an emitter's front face, the environment where the camera ray escapes, times the
// eye chain's throughput), and the first two moments of the iteration's demodulated luminance
// of the reflected direct light (the emission taken out) and of the indirect component (the
// iteration's value is the film's sum less the sum at the previous iteration). Slot k of
// pixel p at k·W·H + p; `previous` holds the film's direct and indirect sums at the last
// iteration (slots 0, 1) and the emission's sum (slot 2). The including pass binds `film`.

@group(3) @binding(0) var<storage, read_write> guides: array<vec4f>;
@group(3) @binding(1) var<storage, read_write> previous: array<vec4f>;

@compute @workgroup_size(8, 8)
fn accumulate_guides(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    let xy = gid.xy;
    if !begin_pixel(xy) {
        return;
    }
    let p = pixel_index(xy);
    let n = frame.resolution.x * frame.resolution.y;
    let v = visible_point_at(xy);
    var albedo = vec3f(0.0);
    var normal = vec3f(0.0);
    var depth = 0.0;
    var seen = 0.0;
    // What the direct pass adds before any light is reflected.
    let emitted = seen_emission(v, xy).radiance;
    if v.seen {
        albedo = v.weight * v.x.albedo;
        normal = v.ns;
        depth = distance(frame.eye, v.x.pos);
        seen = 1.0;
    }
    guides[p] += vec4f(albedo, depth);
    guides[n + p] += vec4f(normal, seen);
    let direct = film[film_slot(FILM_DIRECT, p, n)].rgb;
    let indirect = film[film_slot(FILM_INDIRECT, p, n)].rgb;
    let a = demodulation(albedo);
    let ld = luminance((direct - previous[p].rgb - emitted) / a);
    let li = luminance((indirect - previous[n + p].rgb) / a);
    previous[p] = vec4f(direct, 0.0);
    previous[n + p] = vec4f(indirect, 0.0);
    previous[2u * n + p] += vec4f(emitted, 0.0);
    guides[2u * n + p] += vec4f(ld, ld * ld, li, li * li);
}
