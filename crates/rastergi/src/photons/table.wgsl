// The photon map's slot table (photons::map::SlotTable): open addressing with linear probing
// over `slot_keys` (bound by the including shader), keyed by (cell index, plane key); EMPTY
// where there is no slot. A search stops at the key, at an empty entry, or after `max_probe`
// entries (the longest probe of any key).

const NO_SLOT: u32 = 0xffffffffu;

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

// One level's cells (photons::map::Lattice): coordinates lo ..= hi, indices from base.
struct Lattice {
    origin: vec3f,
    cell: f32,
    lo: vec3i,
    base: u32,
    hi: vec3i,
    dims: vec3u,
}

// The level whose cells hold p (GridSpec::lattice_at).
fn lattice_at(g: GridLevels, p: vec3f) -> Lattice {
    var l: Lattice;
    l.origin = g.origin;
    let c = vec3u(clamp(vec3i(floor((p - g.origin) / g.cell)), vec3i(0), vec3i(g.dims) - 1));
    if g.factor > 1u && all(c >= g.fine_lo) && all(c < g.fine_hi) {
        l.cell = g.fine_cell;
        l.lo = vec3i(g.fine_lo * g.factor);
        l.dims = (g.fine_hi - g.fine_lo) * g.factor;
        l.base = g.fine_base;
    } else {
        l.cell = g.cell;
        l.lo = vec3i(0);
        l.dims = g.dims;
        l.base = 0u;
    }
    l.hi = l.lo + vec3i(l.dims) - 1;
    return l;
}

// The cell of `l` holding p, clamped (Lattice::cell_of).
fn lattice_cell(l: Lattice, p: vec3f) -> vec3u {
    return vec3u(clamp(vec3i(floor((p - l.origin) / l.cell)), l.lo, l.hi));
}

// The linear index of cell c of `l` (Lattice::index).
fn lattice_index(l: Lattice, c: vec3u) -> u32 {
    let r = c - vec3u(l.lo);
    return l.base + (r.z * l.dims.y + r.y) * l.dims.x + r.x;
}

fn slot_hash(cell: u32, plane: u32) -> u32 {
    return pcg_hash(cell ^ pcg_hash(plane));
}

// The entry of key (cell, plane) in the open-addressed table of `slot_keys` that starts at
// entry `base`, NO_SLOT if the table has none; `mask` = its capacity − 1, `max_probe` its
// longest probe (linear probing from the key's hash).
fn find_entry(cell: u32, plane: u32, base: u32, mask: u32, max_probe: u32) -> u32 {
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

// The entry of slot (cell, plane), NO_SLOT if the map has none; `mask` = capacity − 1.
fn find_slot(cell: u32, plane: u32, mask: u32, max_probe: u32) -> u32 {
    return find_entry(cell, plane, 0u, mask, max_probe);
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

// The separators' table follows the slots' in `slot_keys` (from entry `base`, the slots'
// capacity), then the separators' records (8 entries of f32 bits each, from entry
// `t.records`), then one bit per cell where the cell holds separators and one where it holds
// slots (64 an entry, from `t.cell_flags`): one binding for them all
// (photons::gpu::table_entries), under WebGPU's 10 storage buffers per stage.
struct TableLayout {
    base: u32,
    mask: u32,
    max_probe: u32,
    records: u32,
    cell_flags: u32,
}

// Bit `cell` of the flags from entry `first` (64 an entry).
fn cell_flag(first: u32, cell: u32) -> bool {
    let w = slot_keys[first + cell / 64u];
    let bit = cell % 64u;
    return ((select(w.x, w.y, bit >= 32u) >> (bit % 32u)) & 1u) != 0u;
}

// Whether cell `cell` holds the separators of some slot (the first run of flags).
fn cell_has_separators(t: TableLayout, cell: u32) -> bool {
    return cell_flag(t.cell_flags, cell);
}

// Whether cell `cell` (its index without CAUSTIC_CELL) holds some slot (the second run of flags,
// one entry per 64 cells of the grid after the first: `cells` the grid's cell count).
fn cell_has_slots(t: TableLayout, cells: u32, cell: u32) -> bool {
    return cell_flag(t.cell_flags + (cells + 63u) / 64u, cell);
}

// The entry of base slot (cell, plane)'s separators, NO_SLOT where it has none: find_slot over
// the separators' table, searched only in a cell flagged to hold some.
fn find_separators(t: TableLayout, cell: u32, plane: u32) -> u32 {
    if !cell_has_separators(t, cell) {
        return NO_SLOT;
    }
    return find_entry(cell, plane, t.base, t.mask, t.max_probe);
}

// The record of separators' entry `sep`.
fn separator_record(t: TableLayout, sep: u32) -> SeparatorRecord {
    var r: SeparatorRecord;
    let first = t.records + 2u * MAX_SEPARATORS * sep;
    for (var k = 0u; k < MAX_SEPARATORS; k++) {
        r.s[k] = bitcast<vec4f>(vec4u(slot_keys[first + 2u * k], slot_keys[first + 2u * k + 1u]));
    }
    return r;
}
