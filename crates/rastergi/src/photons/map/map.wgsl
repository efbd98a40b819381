// Photon map lookups (photons/map/), bind group 3 of the passes that read the map: per slot
// table entry (Φ_rgb/h², A/h²), the table's keys (with the separators'), and every triangle's
// plane keys.

@group(3) @binding(0) var<storage, read> photon_slots: array<vec4f>;
@group(3) @binding(1) var<uniform> photon_grid: PhotonGrid;
// The slots' table keys, then the separators' keys, records and cell flags (table.wgsl).
@group(3) @binding(2) var<storage, read> slot_keys: array<vec2u>;
@group(3) @binding(3) var<storage, read> planes: array<TrianglePlane>;
// The photon guide (photons/guide.rs): its first words mark the cells where the map is read.
@group(3) @binding(4) var<storage, read_write> photon_guide: array<atomic<u32>>;

// Marks the cell of p, in the guide's grid, as one where the map is read (once: a marked
// cell is only loaded).
fn mark_read(p: vec3f) {
    if photon_grid.marks.dims.x == 0u {
        return; // photons not guided: nothing marks
    }
    let l = lattice_at(photon_grid.marks, p);
    let i = lattice_index(l, lattice_cell(l, p));
    let bit = 1u << (i % 32u);
    let word = GUIDE_MARKS + i / 32u;
    if (atomicLoad(&photon_guide[word]) & bit) == 0u {
        atomicOr(&photon_guide[word], bit);
    }
}

fn map_separators() -> TableLayout {
    let g = photon_grid;
    return TableLayout(g.mask + 1u, g.sep_mask, g.sep_max_probe, g.records, g.cell_flags);
}

// p's region among the separators of base slot (cell, key): 0 where it has none.
fn photon_region(cell: u32, key: u32, p: vec3f) -> u32 {
    let t = map_separators();
    let sep = find_separators(t, cell, key);
    if sep == NO_SLOT {
        return 0u;
    }
    return region_of(separator_record(t, sep), p);
}

// E(p) on side `back` of triangle tri: Σ w_i Φ_i / Σ w_i A_i over the slots of its plane in
// the 8 cells around p, w_i trilinear on cell centres (PhotonMap::irradiance_on).
fn photon_irradiance(p: vec3f, tri: u32, back: bool) -> vec3f {
    return photon_lookup(p, tri, back, 0u);
}

// The caustic map's E(p) (PhotonMap::caustic_irradiance_on): the same lookup over the slots'
// caustic twins (zero where the map has none).
fn caustic_irradiance(p: vec3f, tri: u32, back: bool) -> vec3f {
    return photon_lookup(p, tri, back, CAUSTIC_CELL);
}

// The lookup over the slots whose cell index has the bits `twin` set.
fn photon_lookup(p: vec3f, tri: u32, back: bool, twin: u32) -> vec3f {
    mark_read(p);
    let plane = planes[tri];
    // The level holding p: its 8 cells around p (the other level's hold no slots of this one).
    let l = lattice_at(photon_grid.grid, p);
    let origin = l.origin;
    let h = l.cell;
    // The separators of p's own slot: cells beyond them (across a wall) do not count.
    let home = lattice_cell(l, p);
    let home_key = plane_key(plane, cell_centre(origin, h, home), h, back);
    let own = find_separators(map_separators(), lattice_index(l, home), home_key);
    var own_record: SeparatorRecord;
    if own != NO_SLOT {
        own_record = separator_record(map_separators(), own);
    }
    // Areas are in units of the coarse cell's side².
    let scale = h / photon_grid.grid.cell;
    let min_area = MIN_LOOKUP_AREA * scale * scale;
    let g = (p - origin) / h - 0.5;
    let base = floor(g);
    let f = g - base;
    var sum = vec4f(0.0);
    for (var k = 0u; k < 8u; k++) {
        let o = vec3u(k & 1u, (k >> 1u) & 1u, (k >> 2u) & 1u);
        let w3 = select(1.0 - f, f, o == vec3u(1u));
        let c = vec3u(clamp(vec3i(base) + vec3i(o), l.lo, l.hi));
        let centre = cell_centre(origin, h, c);
        if own != NO_SLOT && any(c != home) && region_of(own_record, p) != region_of(own_record, centre) {
            continue;
        }
        let cell = lattice_index(l, c);
        // A cell without slots (the air above a floor) holds none of this plane.
        if !cell_has_slots(map_separators(), photon_grid.cells, cell) {
            continue;
        }
        let key = plane_key(plane, centre, h, back);
        // A plane 8 steps (a cell) or more from a cell's centre misses the cell, and so does
        // every plane that shares its key (within half a step of it; a cell's surface lies
        // within √3/2 cells of its centre): no slot of this key exists there (the CPU twin's
        // search finds none), so the search is skipped.
        if abs(bitcast<i32>(key) >> OFFSET_SHIFT) >= i32(1.0 / OFFSET_STEP) {
            continue;
        }
        let s = find_slot(cell | twin, key | (photon_region(cell, key, p) << REGION_SHIFT), photon_grid.mask, photon_grid.max_probe);
        // Slots of almost no area are left out (PhotonMap::irradiance_on_plane).
        if s != NO_SLOT && photon_slots[s].a >= min_area {
            sum += (w3.x * w3.y * w3.z) * photon_slots[s];
        }
    }
    return select(vec3f(0.0), sum.rgb / sum.a, sum.a > 0.0);
}
