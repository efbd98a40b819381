// The guided sky (passes/sky_guide.rs): per guide cell and side, how open each block of the
// environment map is from there (guide.wgsl's tables, at sky_guide_table() in an entry; the
// blocks' masses from the word the header's word 15 names); the direct pass draws its
// environment samples from the mixture (1 − g)·p_env + g·q, q = p_env·V̄_b/ΣW, and the gathers
// weigh their escaping rays against that density. For a shader that binds the guide buffer
// and knows the environment and the visible point.

// Whether the environment's samples are guided.
fn sky_guided() -> bool {
    return sky_guide_table() != GUIDE_NO_TABLE && has_environment();
}

// The block of unit direction d: block (k, l) holds cells (i, j) with ⌊i·columns/W⌋ = k and
// ⌊j·rows/(H − 1)⌋ = l (SkyBlocks::block_of).
fn sky_block_of(d: vec3f) -> u32 {
    let p = env_position(d);
    let i = min(u32(p.x), environment.width - 1u);
    let j = min(u32(p.y), environment.height - 2u);
    let columns = guide_header_u32(13u);
    let rows = guide_header_u32(14u);
    return (j * rows / (environment.height - 1u)) * columns + i * columns / environment.width;
}

// Visible point p's cell entry (NO_GUIDE where the sky is not guided, the point lies outside
// the guides' grid — where its cell would be shared with points far from it, in other light
// — or no entry is free), taken for it with `insert`.
fn sky_guide_entry(p: VisiblePoint, insert: bool) -> u32 {
    if !sky_guided() {
        return NO_GUIDE;
    }
    let origin = vec3f(guide_header_f32(0u), guide_header_f32(1u), guide_header_f32(2u));
    let dims = vec3f(f32(guide_header_u32(4u)), f32(guide_header_u32(5u)), f32(guide_header_u32(6u)));
    let c = (p.x.pos - origin) / guide_header_f32(3u);
    if any(c < vec3f(0.0)) || any(c >= dims) {
        return NO_GUIDE;
    }
    return gather_guide_entry(gather_guide_key(p.x.pos, p.ns), insert);
}

// Entry e's total weight in the sky's table (0: nothing learned).
fn sky_guide_total(e: u32) -> f32 {
    return guide_total(e, sky_guide_table());
}

// The guided environment density of direction w (per steradian) for entry e of total weight
// `total`: p_env·F_b (sky_factor), or p_env where nothing is learned.
fn sky_density(e: u32, total: f32, w: vec3f) -> f32 {
    let p = env_pdf(w);
    if total <= 0.0 {
        return p;
    }
    return p * sky_factor(e, total, sky_block_of(w));
}

// The density of the direct pass's environment samples along w at visible point p (what the
// gathers weigh their escaping rays against).
fn env_light_density(p: VisiblePoint, w: vec3f) -> f32 {
    let e = sky_guide_entry(p, false);
    return sky_density(e, sky_guide_total(e), w);
}

// Row j's column cdf before column i (0 for the first).
fn sky_column_cdf(j: u32, i: u32) -> f32 {
    if i == 0u {
        return 0.0;
    }
    return env_data(environment.column_cdf + j * environment.width + i - 1u);
}

// The environment's probability of the cells of block column k in cell rows r0 (the first
// of j's block row) to j: the table after the blocks' masses, a row of `columns` per cell row.
fn sky_rows_cdf(j: u32, k: u32) -> f32 {
    let columns = guide_header_u32(13u);
    let at = guide_header_u32(15u) + columns * guide_header_u32(14u) + j * columns + k;
    return bitcast<f32>(atomicLoad(&photon_guide[at]));
}

// The mixture's factor F_b = p/p_env of block b: (1 − g) + g·W_b/(P_b·ΣW).
fn sky_factor(e: u32, total: f32, b: u32) -> f32 {
    let m = sky_block_mass(b);
    if m <= 0.0 {
        return 0.0;
    }
    return (1.0 - SKY_GUIDE_FRACTION) + SKY_GUIDE_FRACTION * guide_weight(e, sky_guide_table(), b) / (m * total);
}

// The mixture's probability of the cell rows r0 (the first of block row l) to j of block row l,
// whose blocks' factors are `f`: Σ_k F_(l,k)·(row cdf of j in column k).
fn sky_rows_mixture(f: array<f32, 16>, columns: u32, j: u32) -> f32 {
    var acc = 0.0;
    for (var k = 0u; k < columns; k++) {
        acc += f[k] * sky_rows_cdf(j, k);
    }
    return acc;
}

// The mixture's probability of blocks 0 to b together: (1 − g)·ΣP + g·ΣW/total.
fn sky_mixture_cdf(e: u32, total: f32, b: u32) -> f32 {
    return (1.0 - SKY_GUIDE_FRACTION) * sky_blocks_cdf(b)
        + SKY_GUIDE_FRACTION * guide_cdf(e, sky_guide_table(), b) / total;
}

// Light sample l of the environment drawn again from the guided mixture at entry e (total
// weight `total`) with the same uniforms u, warped as the environment's own sampling warps
// them (SkyBlocks::sample): u.x picks the cell row by the mixture's row masses (its block row
// first, then the row in it), u.y the cell in the row by the mixture's masses along it (its
// block column first, then the column by the row's cdf), each remainder the point in the cell.
// Both warps stay monotone in θ and φ, so a pixel's Sobol' points keep their stratification;
// where every factor is 1 it is the environment's own warp. The density is the mixture's,
// p_env·F_b (sky_density). Unchanged where nothing is learned.
fn sky_guided_light(l: LightRay, u: vec2f, e: u32, total: f32) -> LightRay {
    if total <= 0.0 {
        return l;
    }
    let columns = guide_header_u32(13u);
    let rows = guide_header_u32(14u);
    // The block row: the mixture's cdf at each block row's last block.
    var lo = 0u;
    var hi = rows - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if sky_mixture_cdf(e, total, mid * columns + columns - 1u) <= u.x {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let band = lo;
    var below = 0.0;
    if band > 0u {
        below = sky_mixture_cdf(e, total, band * columns - 1u);
    }
    var f: array<f32, 16>;
    for (var k = 0u; k < columns; k++) {
        f[k] = sky_factor(e, total, band * columns + k);
    }
    let r = environment.height - 1u;
    let r0 = (band * r + rows - 1u) / rows;
    let r1 = ((band + 1u) * r + rows - 1u) / rows;
    let band_mass = sky_rows_mixture(f, columns, r1 - 1u);
    let goal = clamp((u.x - below) / max(sky_mixture_cdf(e, total, band * columns + columns - 1u) - below, 1e-30), 0.0, 0.99999994) * band_mass;
    // The cell row in the block row.
    lo = r0;
    hi = r1 - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if sky_rows_mixture(f, columns, mid) <= goal {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    let j = lo;
    var before = 0.0;
    if j > r0 {
        before = sky_rows_mixture(f, columns, j - 1u);
    }
    let row_mass = sky_rows_mixture(f, columns, j) - before;
    let v = clamp((goal - before) / max(row_mass, 1e-30), 0.0, 0.99999994);
    // The block column along the row, then the column by the row's own cdf.
    let goal2 = u.y * row_mass;
    var acc = 0.0;
    var k = 0u;
    var m = 0.0;
    loop {
        var prev = 0.0;
        if j > r0 {
            prev = sky_rows_cdf(j - 1u, k);
        }
        m = f[k] * (sky_rows_cdf(j, k) - prev);
        if (acc + m > goal2 && m > 0.0) || k + 1u >= columns {
            break;
        }
        acc += m;
        k++;
    }
    let w = environment.width;
    let c0 = (k * w + columns - 1u) / columns;
    let c1 = ((k + 1u) * w + columns - 1u) / columns;
    let rest = clamp((goal2 - acc) / max(m, 1e-30), 0.0, 0.99999994);
    let lo_c = sky_column_cdf(j, c0);
    let at = lo_c + rest * (sky_column_cdf(j, c1) - lo_c);
    let row = environment.column_cdf + j * w;
    let i = c0 + env_search(row + c0, c1 - c0, at);
    let s = env_remap(at, sky_column_cdf(j, i), env_data(row + i));
    let phi = 2.0 * PI * (f32(i) + 0.5 + s) / f32(w);
    let c = env_row_cosines(j);
    let cos_t = c.x - v * (c.x - c.y);
    let sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
    var out = l;
    out.dir = vec3f(sin(phi) * sin_t, cos_t, -cos(phi) * sin_t);
    out.pdf = environment.pmf * sky_density(e, total, out.dir);
    out.e = select(vec3f(0.0), env_radiance(out.dir) / out.pdf, out.pdf > 0.0);
    return out;
}

// Adds what a ray along w from entry e's cell found: its openness V·cos θ in [0, 1].
fn sky_guide_learn(e: u32, w: vec3f, openness: f32) {
    if e == NO_GUIDE {
        return;
    }
    guide_add(e, sky_guide_table(), sky_block_of(w), u32(clamp(openness, 0.0, 1.0) * SKY_GUIDE_SCALE + 0.5));
}
