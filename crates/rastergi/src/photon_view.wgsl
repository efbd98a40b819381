// Photon-map view (photon_view.rs): ρ/π · E(x) at the visible point → film, photon-view
// component.

// Bind group 2: gbuffer_film.wgsl.

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.resolution) {
        return;
    }
    start_alpha_stream();
    let p = visible_point_at(gid.xy);
    var radiance = vec3f(0.0);
    if p.ok {
        radiance = p.x.albedo / PI * photon_irradiance(p.x.pos, p.x.tri, !p.front);
    }
    film_add(FILM_PHOTON_VIEW, gid.xy, p.weight * (radiance));
}
