// Film writes (film.rs): component c (FILM_DIRECT, FILM_INDIRECT, FILM_PHOTON_VIEW) of pixel p
// at c·W·H + p. The including pass binds `film`.

fn film_slot(component: u32, pixel: u32, n_pixels: u32) -> u32 {
    return component * n_pixels + pixel;
}

// Adds v to component `component` of the pixel at `texel` of this frame's image.
fn film_add(component: u32, texel: vec2u, v: vec3f) {
    film_add_seen(component, texel, v, 0.0);
}

// film_add, and `seen` to the component's fourth channel: the direct pass and the path tracer
// add to FILM_DIRECT's the share of the pixel that this iteration sees as an emitter or the
// sky, directly or through smooth glass and mirrors — 1 or 0 by its sample, or on an emitter's
// edge the share of the direct pass's sub-pixel rays that meet light (seen_emission)
// (FilmState::error_estimate leaves pixels with any out); FILM_INDIRECT's is
// film_add_light_variance's; nothing else writes them.
fn film_add_seen(component: u32, texel: vec2u, v: vec3f, seen: f32) {
    let pixel = texel.y * frame.resolution.x + texel.x;
    film[film_slot(component, pixel, frame.resolution.x * frame.resolution.y)] += vec4f(v, seen);
}

// Adds v to FILM_INDIRECT's fourth channel: the direct pass's estimate of one light sample's
// variance at the pixel's visible point, summed over the iterations that drew two or more
// (FilmState::light_sample_variance, the light budget's).
fn film_add_light_variance(texel: vec2u, v: f32) {
    let pixel = texel.y * frame.resolution.x + texel.x;
    film[film_slot(FILM_INDIRECT, pixel, frame.resolution.x * frame.resolution.y)].w += v;
}
