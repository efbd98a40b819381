// Photon-map view (photon_view.rs): ρ/π · E(x) at the visible point → film, photon-view
// component.

// Bind group 2: gbuffer_film.wgsl.

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if !begin_pixel(gid.xy) { return; }
    let p = visible_point_at(gid.xy);
    var radiance = vec3f(0.0);
    if p.ok {
        radiance = surface_rho(p.x, normalize(p.eye - p.x.pos)) / PI * photon_irradiance(p.x.pos, p.x.tri, !p.front);
    }
    film_add(FILM_PHOTON_VIEW, gid.xy, p.weight * (radiance));
}

// The caustic term at the visible points (renderer: every iteration of a scene with caustic
// twins): ρ/π · E_caustic(x), the light that reached x from the lights through perfect mirrors
// and smooth glass alone, read directly from the caustic map (the gather would blur it, and
// its rays through specular surfaces leave that light out) → film, indirect component.
@compute @workgroup_size(8, 8)
fn caustics(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if !begin_pixel(gid.xy) { return; }
    let p = visible_point_at(gid.xy);
    if !p.ok {
        return;
    }
    let radiance = surface_rho(p.x, normalize(p.eye - p.x.pos)) / PI * caustic_irradiance(p.x.pos, p.x.tri, !p.front);
    film_add(FILM_INDIRECT, gid.xy, p.weight * radiance);
}
