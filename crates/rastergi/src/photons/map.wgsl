// Photon map lookups (photons/map.rs), bind group 3 of the passes that read the map.
// Texel (x, y, z + bin·nz) holds (Φ_rgb/h², A/h²) of cell (x, y, z) in orientation bin `bin`.

struct PhotonGrid {
    origin: vec3f,
    cell: f32,
    dims: vec3u,
    _pad: u32,
}

@group(3) @binding(0) var photon_texture: texture_3d<f32>;
@group(3) @binding(1) var<uniform> photon_grid: PhotonGrid;

// E(p) for the surface side with normal n: Σ w_i Φ_i / Σ w_i A_i over the 8 cells around p
// in n's bin, w_i trilinear on cell centres (PhotonMap::irradiance).
fn photon_irradiance(p: vec3f, n: vec3f) -> vec3f {
    let bin = orientation_bin(n);
    let g = (p - photon_grid.origin) / photon_grid.cell - 0.5;
    let base = floor(g);
    let f = g - base;
    let hi = vec3i(photon_grid.dims) - 1;
    var sum = vec4f(0.0);
    for (var k = 0u; k < 8u; k++) {
        let o = vec3u(k & 1u, (k >> 1u) & 1u, (k >> 2u) & 1u);
        let w3 = select(1.0 - f, f, o == vec3u(1u));
        let c = vec3u(clamp(vec3i(base) + vec3i(o), vec3i(0), hi));
        sum += (w3.x * w3.y * w3.z) * textureLoad(photon_texture, vec3u(c.x, c.y, c.z + bin * photon_grid.dims.z), 0);
    }
    return select(vec3f(0.0), sum.rgb / sum.a, sum.a > 0.0);
}
