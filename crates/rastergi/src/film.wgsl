// Film writes (film.rs): component c (FILM_DIRECT, FILM_INDIRECT, FILM_PHOTON_VIEW) of pixel p
// at c·W·H + p. The including pass binds `film`.

fn film_slot(component: u32, pixel: u32, n_pixels: u32) -> u32 {
    return component * n_pixels + pixel;
}

// Adds v to component `component` of the pixel at `texel` of this frame's image.
fn film_add(component: u32, texel: vec2u, v: vec3f) {
    let pixel = texel.y * frame.resolution.x + texel.x;
    film[film_slot(component, pixel, frame.resolution.x * frame.resolution.y)] += vec4f(v, 0.0);
}
