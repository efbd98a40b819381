// The guides' tables (gather/guide.rs): per cell of a grid over the part of the scene the
// camera reads, and per side (the dominant axis of a visible point's shading normal), a table
// of direction bins per guide: the gather's (the radiance its rays found, in
// GATHER_GUIDE_BINS directions of equal solid angle; the traced gather draws its directions
// from a mixture of the visible point's scattering and this table, and the direct pass weighs
// its environment samples against that mixture) and the guided sky's (passes/sky_guide.rs:
// how open each block of the environment is from there). They live in the guide buffer
// `photon_guide` (bound by the including shader): a header at word GUIDE_HEADER, then the
// cells, `guide_entry_words()` words each: the cell's key (0: free), then each guide's table
// at its offset in the entry (GUIDE_NO_TABLE where that guide is off): the bins' sums (fixed
// point), their sample counts, their cumulative weights (f32), GATHER_GUIDE_BINS words each.

const NO_GUIDE: u32 = 0xffffffffu;
const GUIDE_NO_TABLE: u32 = 0xffffffffu;

fn guide_header_u32(k: u32) -> u32 {
    return atomicLoad(&photon_guide[GUIDE_HEADER + k]);
}

fn guide_header_f32(k: u32) -> f32 {
    return bitcast<f32>(guide_header_u32(k));
}

// The key of the cell holding x for a surface whose shading normal is n (0: no guide).
fn gather_guide_key(x: vec3f, n: vec3f) -> u32 {
    let capacity = guide_header_u32(7u);
    if capacity == 0u {
        return 0u;
    }
    let origin = vec3f(guide_header_f32(0u), guide_header_f32(1u), guide_header_f32(2u));
    let dims = vec3u(guide_header_u32(4u), guide_header_u32(5u), guide_header_u32(6u));
    let c = vec3u(clamp(vec3i(floor((x - origin) / guide_header_f32(3u))), vec3i(0), vec3i(dims) - 1));
    let a = abs(n);
    var side = select(0u, 1u, n.x < 0.0);
    if a.y >= a.x && a.y >= a.z {
        side = select(2u, 3u, n.y < 0.0);
    } else if a.z >= a.x && a.z >= a.y {
        side = select(4u, 5u, n.z < 0.0);
    }
    return 1u + ((c.z * dims.y + c.y) * dims.x + c.x) * 6u + side;
}

// Words per cell entry: its key and its guides' tables.
fn guide_entry_words() -> u32 {
    return guide_header_u32(10u);
}

// The offset in an entry of the gather guide's table, and of the guided sky's
// (GUIDE_NO_TABLE: that guide is off).
fn gather_guide_table() -> u32 {
    return guide_header_u32(11u);
}

fn sky_guide_table() -> u32 {
    return guide_header_u32(12u);
}

// The word k of guide entry e.
fn guide_entry_word(e: u32, k: u32) -> u32 {
    return guide_header_u32(8u) + e * guide_entry_words() + k;
}

// The entry of cell `key`, NO_GUIDE where it has none; with `insert`, a free entry is taken
// for it (linear probing, GATHER_GUIDE_PROBES entries at most: a full table guides no more
// cells).
fn gather_guide_entry(key: u32, insert: bool) -> u32 {
    let capacity = guide_header_u32(7u);
    if key == 0u || capacity == 0u {
        return NO_GUIDE;
    }
    var i = pcg_hash(key) & (capacity - 1u);
    for (var probe = 0u; probe < GATHER_GUIDE_PROBES; probe++) {
        let at = guide_entry_word(i, 0u);
        let k = atomicLoad(&photon_guide[at]);
        if k == key {
            return i;
        }
        if k == 0u {
            if !insert {
                return NO_GUIDE;
            }
            let r = atomicCompareExchangeWeak(&photon_guide[at], 0u, key);
            if r.exchanged || r.old_value == key {
                return i;
            }
            if r.old_value == 0u {
                // A spurious failure: try this entry again.
                probe -= 1u;
                continue;
            }
        }
        i = (i + 1u) & (capacity - 1u);
    }
    return NO_GUIDE;
}

// The direction bin of unit direction w: GATHER_GUIDE_BANDS bands of equal solid angle in
// w.y, as many sectors of φ = atan2(w.x, −w.z) (gather/guide.rs: direction_bin).
fn gather_guide_bin(w: vec3f) -> u32 {
    let n = GATHER_GUIDE_BANDS;
    let band = min(u32((w.y + 1.0) * 0.5 * f32(n)), n - 1u);
    let u = atan2(w.x, -w.z) / (2.0 * PI);
    let sector = min(u32((u - floor(u)) * f32(n)), n - 1u);
    return band * n + sector;
}

// A direction uniform in bin b from two uniforms (gather/guide.rs: bin_direction).
fn gather_guide_direction(b: u32, u: vec2f) -> vec3f {
    let n = GATHER_GUIDE_BANDS;
    let y = -1.0 + (f32(b / n) + u.x) * 2.0 / f32(n);
    let phi = (f32(b % n) + u.y) * 2.0 * PI / f32(n);
    let s = sqrt(max(1.0 - y * y, 0.0));
    return vec3f(sin(phi) * s, y, -cos(phi) * s);
}

// The cumulative weight up to bin b, inclusive, of the table at offset t of entry e.
fn guide_cdf(e: u32, t: u32, b: u32) -> f32 {
    return bitcast<f32>(atomicLoad(&photon_guide[guide_entry_word(e, t + 2u * GATHER_GUIDE_BINS + b)]));
}

// Bin b's own weight in the table at offset t of entry e.
fn guide_weight(e: u32, t: u32, b: u32) -> f32 {
    var below = 0.0;
    if b > 0u {
        below = guide_cdf(e, t, b - 1u);
    }
    return guide_cdf(e, t, b) - below;
}

// The total weight of the table at offset t of entry e (0: nothing learned, or no entry, or
// no table).
fn guide_total(e: u32, t: u32) -> f32 {
    if e == NO_GUIDE || t == GUIDE_NO_TABLE {
        return 0.0;
    }
    return guide_cdf(e, t, GATHER_GUIDE_BINS - 1u);
}

// A bin picked from a table by its weight, and the uniform's position in its cdf interval.
struct GuidePick {
    bin: u32,
    u: f32,
}

// The bin of the table at offset t of entry e (total weight `total` > 0) whose cdf interval
// holds u·total, and u's position in that interval, in [0, 1).
fn guide_pick(e: u32, t: u32, total: f32, u: f32) -> GuidePick {
    let goal = u * total;
    var lo = 0u;
    var hi = GATHER_GUIDE_BINS - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if guide_cdf(e, t, mid) <= goal {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    var below = 0.0;
    if lo > 0u {
        below = guide_cdf(e, t, lo - 1u);
    }
    let s = clamp((goal - below) / max(guide_cdf(e, t, lo) - below, 1e-30), 0.0, 0.9999999);
    return GuidePick(lo, s);
}

// Adds one sample of value q (fixed point) to bin b of the table at offset t of entry e.
fn guide_add(e: u32, t: u32, b: u32, q: u32) {
    if e == NO_GUIDE || t == GUIDE_NO_TABLE {
        return;
    }
    if q > 0u {
        atomicAdd(&photon_guide[guide_entry_word(e, t + b)], q);
    }
    atomicAdd(&photon_guide[guide_entry_word(e, t + GATHER_GUIDE_BINS + b)], 1u);
}

// The guided sky's blocks (passes/sky_guide.rs), from the header's word 15: the environment's
// probability of blocks 0 to b together, and of block b (its cells' pmfs summed).
fn sky_blocks_cdf(b: u32) -> f32 {
    return bitcast<f32>(atomicLoad(&photon_guide[guide_header_u32(15u) + b]));
}

fn sky_block_mass(b: u32) -> f32 {
    var below = 0.0;
    if b > 0u {
        below = sky_blocks_cdf(b - 1u);
    }
    return sky_blocks_cdf(b) - below;
}

// Entry e's total weight in the gather guide's table.
fn gather_guide_total(e: u32) -> f32 {
    return guide_total(e, gather_guide_table());
}

// The table's density (per steradian) of direction w in entry e of total weight `total` > 0.
fn gather_guide_pdf(e: u32, total: f32, w: vec3f) -> f32 {
    let b = gather_guide_bin(w);
    return guide_weight(e, gather_guide_table(), b) / total * f32(GATHER_GUIDE_BINS) / (4.0 * PI);
}

// A direction from entry e (total weight `total` > 0): a bin by its weight (u.x, remapped
// within the bin's interval), then uniform in it.
fn gather_guide_sample(e: u32, total: f32, u: vec2f) -> vec3f {
    let pick = guide_pick(e, gather_guide_table(), total, u.x);
    return gather_guide_direction(pick.bin, vec2f(pick.u, u.y));
}

// Adds a gather ray's finding to entry e: radiance of luminance y along w (clamped, for the
// table only: the estimates stay unbiased whatever it holds).
fn gather_guide_learn(e: u32, w: vec3f, y: f32) {
    let q = u32(clamp(y * guide_header_f32(9u), 0.0, 65535.0));
    guide_add(e, gather_guide_table(), gather_guide_bin(w), q);
}
