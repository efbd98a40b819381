// The guides' tables (gather/guide.rs): per cell of a grid over the part of the scene the
// camera reads, and per side (the dominant axis of a visible point's shading normal), a table
// of direction bins per guide: the gather's (the radiance its rays found, in
// GATHER_GUIDE_BINS bins of the cosine warp's square in the side's frame; the traced gather
// draws its directions on a Lambertian surface by one warp of the mixture of the cosine and
// this table, and the direct pass weighs its environment samples against that mixture) and
// the guided sky's (passes/sky_guide.rs: how open each block of the environment is from
// there). They live in the guide buffer `photon_guide` (bound by the including shader): a
// header at word GUIDE_HEADER, then the cells, `guide_entry_words()` words each: the cell's
// key (0: free), then each guide's table at its offset in the entry (GUIDE_NO_TABLE where that
// guide is off): the bins' sums (fixed point), their sample counts, their cumulative weights
// (f32), GATHER_GUIDE_BINS words each.

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

// The guide's frame at a surface of shading normal n: the tangent t from a world axis across
// the side's dominant axis (z where x dominates, else x), b = n × t — the same for every
// point of a cell's side whose normals agree, and continuous in n within the side
// (gather/guide.rs: frame).
fn gather_guide_frame(n: vec3f) -> mat3x3f {
    let a = abs(n);
    let r = select(vec3f(1.0, 0.0, 0.0), vec3f(0.0, 0.0, 1.0), a.x > max(a.y, a.z));
    let t = normalize(r - n * dot(n, r));
    return mat3x3f(t, cross(n, t), n);
}

// The cosine warp in the guide's frame about n: v = (sin²θ, φ/2π) ↦ w, pdf cos θ/π for v
// uniform (gather/guide.rs: warp).
fn gather_guide_warp(n: vec3f, v: vec2f) -> vec3f {
    let f = gather_guide_frame(n);
    let r = sqrt(v.x);
    let phi = 2.0 * PI * v.y;
    return normalize(f[0] * (r * cos(phi)) + f[1] * (r * sin(phi)) + n * sqrt(max(1.0 - v.x, 0.0)));
}

// The direction bin of w about n: the cell of the cosine warp's square [0, 1)² holding the
// point that warps to w, GATHER_GUIDE_BANDS rows of sin²θ by as many columns of φ — bins of
// equal projected solid angle (gather/guide.rs: direction_bin).
fn gather_guide_bin(n: vec3f, w: vec3f) -> u32 {
    let f = gather_guide_frame(n);
    let x = dot(w, f[0]);
    let y = dot(w, f[1]);
    let k = f32(GATHER_GUIDE_BANDS);
    let row = min(u32(clamp(x * x + y * y, 0.0, 1.0) * k), GATHER_GUIDE_BANDS - 1u);
    let a = atan2(y, x) / (2.0 * PI);
    let column = min(u32((a - floor(a)) * k), GATHER_GUIDE_BANDS - 1u);
    return row * GATHER_GUIDE_BANDS + column;
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

// The guided mixture's factor F_b = p/p_cos of bin b of entry e (total weight `total` > 0):
// (1 − g) + g·BINS·weight_b/total — the cosine warp's square drawn with probability F_b/BINS
// per bin (gather/guide.rs: factor).
fn gather_guide_factor(e: u32, total: f32, b: u32) -> f32 {
    let q = guide_weight(e, gather_guide_table(), b) / total;
    return (1.0 - GATHER_GUIDE_FRACTION) + GATHER_GUIDE_FRACTION * f32(GATHER_GUIDE_BINS) * q;
}

// The mixture's probability of bins 0 to b together: (1 − g)(b + 1)/BINS + g·cdf_b/total.
fn gather_guide_mixture_cdf(e: u32, total: f32, b: u32) -> f32 {
    return (1.0 - GATHER_GUIDE_FRACTION) * f32(b + 1u) / f32(GATHER_GUIDE_BINS)
        + GATHER_GUIDE_FRACTION * guide_cdf(e, gather_guide_table(), b) / total;
}

// A direction about n from entry e (total weight `total` > 0), by one warp of the two
// uniforms u: u.x picks the row of the cosine warp's square by the mixture's row masses, u.y
// the bin along that row by the mixture's masses, each remainder the point in the bin; that
// point is warped by the cosine (gather_guide_warp). Monotone in each uniform, so a pixel's
// Sobol' points stay stratified; with a uniform table it is the cosine warp itself. Density
// F_b·cos θ/π (gather/guide.rs: sample).
fn gather_guide_sample(e: u32, total: f32, n: vec3f, u: vec2f) -> vec3f {
    let k = GATHER_GUIDE_BANDS;
    var lo = 0u;
    var hi = k - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if gather_guide_mixture_cdf(e, total, mid * k + k - 1u) <= u.x {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let row = lo;
    var below = 0.0;
    if row > 0u {
        below = gather_guide_mixture_cdf(e, total, row * k - 1u);
    }
    let row_mass = max(gather_guide_mixture_cdf(e, total, row * k + k - 1u) - below, 1e-30);
    let v1 = clamp((u.x - below) / row_mass, 0.0, 0.99999994);
    let goal = below + u.y * row_mass;
    lo = row * k;
    hi = row * k + k - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if gather_guide_mixture_cdf(e, total, mid) <= goal {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    var before = below;
    if lo > row * k {
        before = gather_guide_mixture_cdf(e, total, lo - 1u);
    }
    let v2 = clamp((goal - before) / max(gather_guide_mixture_cdf(e, total, lo) - before, 1e-30), 0.0, 0.99999994);
    return gather_guide_warp(n, vec2f((f32(row) + v1) / f32(k), (f32(lo - row * k) + v2) / f32(k)));
}

// Adds a gather ray's finding to entry e: radiance of luminance y along w about the shading
// normal n (clamped, for the table only: the estimates stay unbiased whatever it holds).
fn gather_guide_learn(e: u32, n: vec3f, w: vec3f, y: f32) {
    let q = u32(clamp(y * guide_header_f32(9u), 0.0, 65535.0));
    guide_add(e, gather_guide_table(), gather_guide_bin(n, w), q);
}
