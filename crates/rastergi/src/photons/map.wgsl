// Photon map lookups (photons/map.rs), bind group 3 of the passes that read the map: per slot
// table entry (Φ_rgb/h², A/h²), the table's keys, and every triangle's plane keys.

struct PhotonGrid {
    origin: vec3f,
    cell: f32,
    dims: vec3u,
    // Table capacity − 1 (a power of two minus one) and the longest probe of any slot.
    mask: u32,
    max_probe: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(3) @binding(0) var<storage, read> photon_slots: array<vec4f>;
@group(3) @binding(1) var<uniform> photon_grid: PhotonGrid;
@group(3) @binding(2) var<storage, read> slot_keys: array<vec2u>;
@group(3) @binding(3) var<storage, read> planes: array<TrianglePlane>;

// E(p) on side `back` of triangle tri: Σ w_i Φ_i / Σ w_i A_i over the slots of its plane in
// the 8 cells around p, w_i trilinear on cell centres (PhotonMap::irradiance_on).
fn photon_irradiance(p: vec3f, tri: u32, back: bool) -> vec3f {
    let plane = planes[tri];
    let g = (p - photon_grid.origin) / photon_grid.cell - 0.5;
    let base = floor(g);
    let f = g - base;
    let hi = vec3i(photon_grid.dims) - 1;
    var sum = vec4f(0.0);
    for (var k = 0u; k < 8u; k++) {
        let o = vec3u(k & 1u, (k >> 1u) & 1u, (k >> 2u) & 1u);
        let w3 = select(1.0 - f, f, o == vec3u(1u));
        let c = vec3u(clamp(vec3i(base) + vec3i(o), vec3i(0), hi));
        let cell = (c.z * photon_grid.dims.y + c.y) * photon_grid.dims.x + c.x;
        let key = plane_key(plane, cell_centre(photon_grid.origin, photon_grid.cell, c), photon_grid.cell, back);
        let s = find_slot(cell, key, photon_grid.mask, photon_grid.max_probe);
        if s != NO_SLOT {
            sum += (w3.x * w3.y * w3.z) * photon_slots[s];
        }
    }
    return select(vec3f(0.0), sum.rgb / sum.a, sum.a > 0.0);
}
