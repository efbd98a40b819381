// Photon-map view (photon_view.rs): ρ/π · E(x) at the visible point → film component 2.

@group(2) @binding(0) var gbuffer: texture_2d<u32>;
@group(2) @binding(1) var<storage, read_write> film: array<vec4f>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.resolution) {
        return;
    }
    let pixel = gid.y * frame.resolution.x + gid.x;
    let g = textureLoad(gbuffer, gid.xy, 0);
    var radiance = vec3f(0.0);
    if g.x != 0u {
        let s = surface_at(g.x - 1u, bitcast<f32>(g.y), bitcast<f32>(g.z), bitcast<f32>(g.w));
        let front = dot(s.normal, frame.eye - s.pos) > 0.0;
        if front || (s.flags & MATERIAL_TWO_SIDED) != 0u {
            let n = select(-s.normal, s.normal, front);
            radiance = s.albedo / PI * photon_irradiance(s.pos, n);
        }
    }
    let n_pixels = frame.resolution.x * frame.resolution.y;
    film[2u * n_pixels + pixel] += vec4f(radiance, 0.0);
}
