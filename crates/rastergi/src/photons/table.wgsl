// The photon map's slot table (photons::map::SlotTable): open addressing with linear probing
// over `slot_keys` (bound by the including shader), keyed by (cell index, plane key); EMPTY
// where there is no slot. A search stops at the key, at an empty entry, or after `max_probe`
// entries (the longest probe of any key).

const NO_SLOT: u32 = 0xffffffffu;

// A triangle's plane (photons::map::TrianglePlane): front normal, n·v0, the bins of both sides.
struct TrianglePlane {
    normal: vec3f,
    offset: f32,
    bins: vec2u,
    _pad0: u32,
    _pad1: u32,
}

// The plane key of side `back` of `plane` in the cell centred at `centre` with side `cell`
// (TrianglePlane::key): the bin, and the distance from the centre to the plane in steps of
// OFFSET_STEP cells, rounded as floor(d + 1/2).
fn plane_key(plane: TrianglePlane, centre: vec3f, cell: f32, back: bool) -> u32 {
    let d = (plane.offset - dot(plane.normal, centre)) / (OFFSET_STEP * cell);
    var steps = i32(floor(d + 0.5));
    if back {
        steps = -steps;
    }
    return select(plane.bins.x, plane.bins.y, back) | (bitcast<u32>(steps) << OFFSET_SHIFT);
}

// The centre of cell c of a grid at `origin` with cells of side `cell`.
fn cell_centre(origin: vec3f, cell: f32, c: vec3u) -> vec3f {
    return origin + (vec3f(c) + 0.5) * cell;
}

fn slot_hash(cell: u32, plane: u32) -> u32 {
    return pcg_hash(cell ^ pcg_hash(plane));
}

// The entry of slot (cell, plane), NO_SLOT if the map has none; `mask` = capacity − 1.
fn find_slot(cell: u32, plane: u32, mask: u32, max_probe: u32) -> u32 {
    var i = slot_hash(cell, plane) & mask;
    for (var probe = 0u; probe < max_probe; probe++) {
        let k = slot_keys[i];
        if k.x == cell && k.y == plane {
            return i;
        }
        if k.x == NO_SLOT {
            return NO_SLOT;
        }
        i = (i + 1u) & mask;
    }
    return NO_SLOT;
}

// The separators of a base slot (photons::map::Separators): a point's region has bit k set
// where it lies on the negative side of plane k, n·x − d < 0 (unused planes are zero).
struct SeparatorRecord {
    s: array<vec4f, MAX_SEPARATORS>,
}

fn region_of(r: SeparatorRecord, p: vec3f) -> u32 {
    var region = 0u;
    for (var k = 0u; k < MAX_SEPARATORS; k++) {
        if dot(r.s[k].xyz, p) - r.s[k].w < 0.0 {
            region |= 1u << k;
        }
    }
    return region;
}

// The entry of base slot (cell, plane)'s separators, NO_SLOT where it has none: find_slot over
// the separators' table, which follows the slots' in `slot_keys` (from entry `base`, the
// slots' capacity: one binding for both, under WebGPU's 10 storage buffers per stage).
fn find_separators(cell: u32, plane: u32, base: u32, mask: u32, max_probe: u32) -> u32 {
    var i = slot_hash(cell, plane) & mask;
    for (var probe = 0u; probe < max_probe; probe++) {
        let k = slot_keys[base + i];
        if k.x == cell && k.y == plane {
            return i;
        }
        if k.x == NO_SLOT {
            return NO_SLOT;
        }
        i = (i + 1u) & mask;
    }
    return NO_SLOT;
}
