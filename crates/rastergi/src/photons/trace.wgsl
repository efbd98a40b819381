// Photon pass (photons/gpu.rs): trace photons from the lights, deposit into 64-bit
// fixed-point counters per (slot, channel); then resolve the counters into the slots' lookup
// values. Draw for draw the twin of photons/cpu.rs.

@group(1) @binding(0) var<uniform> params: PhotonParams;
// Per channel (one binding each, so a large grid fits the per-binding limit) and slot two
// words: (low, high) of the 64-bit fixed-point sum.
@group(1) @binding(1) var<storage, read_write> tally_r: array<atomic<u32>>;
@group(1) @binding(2) var<storage, read_write> tally_g: array<atomic<u32>>;
@group(1) @binding(3) var<storage, read_write> tally_b: array<atomic<u32>>;
// Surface area per table entry, in units of the coarse cell's side².
@group(1) @binding(4) var<storage, read> slot_area: array<f32>;
// Per table entry: (Φ_rgb/h², A/h²), what the lookups read (map.wgsl).
@group(1) @binding(5) var<storage, read_write> slots_out: array<vec4f>;
// The slots' table keys, then the separators' keys, records and cell flags (table.wgsl).
@group(1) @binding(6) var<storage, read> slot_keys: array<vec2u>;
@group(1) @binding(7) var<storage, read> planes: array<TrianglePlane>;
// The photon guide (photons/guide.rs): the cells where the map is read (one bit each), the
// useful deposits and the photons per start bin, the learned tables (emit.wgsl).
@group(1) @binding(8) var<storage, read_write> photon_guide: array<atomic<u32>>;

// Whether the map is read in the cell of p (its mark in the guide's grid).
fn is_read(p: vec3f) -> bool {
    if params.marks.dims.x == 0u {
        return false;
    }
    let l = lattice_at(params.marks, p);
    let i = lattice_index(l, lattice_cell(l, p));
    return (atomicLoad(&photon_guide[GUIDE_MARKS + i / 32u]) & (1u << (i % 32u))) != 0u;
}

// The table entry of a deposit at p on side `back` of triangle tri (MapLayout::deposit_slot).
// With `twin` = CAUSTIC_CELL, the slot's caustic twin (NO_SLOT where the map has none).
// A point on a face of its cell whose cell holds no area of its plane deposits in the
// neighbour across that face (MapLayout::deposit_slot: the area of a surface on a cell
// boundary is in the cell above it, where f32 rounding may not put its points).
fn slot_of(p: vec3f, tri: u32, back: bool, twin: u32) -> u32 {
    let l = lattice_at(params.grid, p);
    let c = lattice_cell(l, p);
    let s = slot_in(l, c, p, tri, back, twin);
    if s != NO_SLOT {
        return s;
    }
    let f = (p - l.origin) / l.cell - vec3f(c);
    for (var axis = 0u; axis < 3u; axis++) {
        var step = 0;
        if f[axis] < NEAR_FACE {
            step = -1;
        } else if f[axis] > 1.0 - NEAR_FACE {
            step = 1;
        }
        var n = vec3i(c);
        n[axis] += step;
        if step != 0 && all(n >= l.lo) && all(n <= l.hi) {
            let t = slot_in(l, vec3u(n), p, tri, back, twin);
            if t != NO_SLOT {
                return t;
            }
        }
    }
    return NO_SLOT;
}

// The slot of p's plane and region in cell c of lattice l.
fn slot_in(l: Lattice, c: vec3u, p: vec3f, tri: u32, back: bool, twin: u32) -> u32 {
    let cell = lattice_index(l, c);
    let key = plane_key(planes[tri], cell_centre(l.origin, l.cell, c), l.cell, back);
    var region = 0u;
    let t = TableLayout(params.mask + 1u, params.sep_mask, params.sep_max_probe, params.records, params.cell_flags);
    let sep = find_separators(t, cell, key);
    if sep != NO_SLOT {
        region = region_of(separator_record(t, sep), p);
    }
    return find_slot(cell | twin, key | (region << REGION_SHIFT), params.mask, params.max_probe);
}

// 64-bit add on the (low, high) words of slot s in channel c: whoever wraps the low word
// carries into the high word.
fn add64(c: u32, s: u32, v: u32) {
    if v == 0u {
        return;
    }
    let i = 2u * s;
    if c == 0u {
        if atomicAdd(&tally_r[i], v) > 0xffffffffu - v {
            atomicAdd(&tally_r[i + 1u], 1u);
        }
    } else if c == 1u {
        if atomicAdd(&tally_g[i], v) > 0xffffffffu - v {
            atomicAdd(&tally_g[i + 1u], 1u);
        }
    } else {
        if atomicAdd(&tally_b[i], v) > 0xffffffffu - v {
            atomicAdd(&tally_b[i + 1u], 1u);
        }
    }
}

// The 64-bit sum of slot s in channel c, in quanta.
fn tally64(c: u32, s: u32) -> f32 {
    var w: vec2u;
    if c == 0u {
        w = vec2u(atomicLoad(&tally_r[2u * s]), atomicLoad(&tally_r[2u * s + 1u]));
    } else if c == 1u {
        w = vec2u(atomicLoad(&tally_g[2u * s]), atomicLoad(&tally_g[2u * s + 1u]));
    } else {
        w = vec2u(atomicLoad(&tally_b[2u * s]), atomicLoad(&tally_b[2u * s + 1u]));
    }
    return f32(w.y) * 4294967296.0 + f32(w.x);
}

// Adds flux to the slot of p on side `back` of tri; a hit that rounding moved into a cell
// without area of its plane deposits nothing (counted by the CPU twin).
fn deposit(p: vec3f, tri: u32, back: bool, flux: vec3f, twin: u32) {
    let s = slot_of(p, tri, back, twin);
    if s == NO_SLOT {
        return;
    }
    // Below u32's range whatever the shading-normal corrections did (2⁷ times the largest
    // initial flux, 2²⁴ quanta: never reached in practice).
    let q = vec3u(round(min(flux * params.quantum, vec3f(2147483648.0))));
    add64(0u, s, q.x);
    add64(1u, s, q.y);
    add64(2u, s, q.z);
}

// A Lambertian bounce at x about the shading normal ns from two uniforms: the direction and
// the factor (cos θ/π)/p by which its weight differs from the cosine's (photons/mod.rs:
// lambertian_bounce). Cosine-distributed (factor 1) unless `aimed` and x lies outside the
// aim's sphere (aim = centre, radius > 0): then from the mixture (1 − β)·cos θ/π + β·U_cone, U_cone
// uniform in the cone the sphere subtends, v1 choosing the strategy and then reused.
struct Bounce {
    dir: vec3f,
    factor: f32,
}

fn lambertian_bounce(x: vec3f, ns: vec3f, aimed: bool, aim: vec4f, v1: f32, v2: f32) -> Bounce {
    let to = aim.xyz - x;
    let d2 = dot(to, to);
    if !aimed || aim.w <= 0.0 || d2 <= aim.w * aim.w {
        return Bounce(cosine_hemisphere(ns, v1, v2), 1.0);
    }
    let beta = BOUNCE_AIM_FRACTION;
    let axis = to / sqrt(d2);
    let s2 = aim.w * aim.w / d2;
    let one_minus_cos = s2 / (1.0 + sqrt(max(1.0 - s2, 0.0)));
    var w: vec3f;
    if v1 < beta {
        w = uniform_cone(axis, one_minus_cos, v1 / beta, v2);
    } else {
        w = cosine_hemisphere(ns, (v1 - beta) / (1.0 - beta), v2);
    }
    let c = cross(to, w);
    let in_cone = dot(to, w) > 0.0 && dot(c, c) <= aim.w * aim.w;
    let cosine = max(dot(w, ns), 0.0) / PI;
    let cone = select(0.0, 1.0 / (2.0 * PI * one_minus_cos), in_cone);
    let p = (1.0 - beta) * cosine + beta * cone;
    return Bounce(w, select(0.0, cosine / p, p > 0.0));
}

@compute @workgroup_size(64)
fn trace_photons(@builtin(global_invocation_id) gid: vec3u) {
    let local = gid.x + gid.y * params.groups_x * 64u;
    if local >= params.batch_size {
        return;
    }
    // Stochastic opacity, per pass (passes_through hashes the hit point with it).
    alpha_seed = pcg_hash(params.seed ^ STREAM_PHOTON ^ pcg_hash(params.pass_index));
    var rng = rng_new(params.seed ^ STREAM_PHOTON, params.first_photon + local, params.pass_index);
    let u0 = rng_f32(&rng);
    let u1 = rng_f32(&rng);
    let u2 = rng_f32(&rng);
    let u3 = rng_f32(&rng);
    let u4 = rng_f32(&rng);
    let start = emit_photon(u0, u1, u2, u3, u4, params.ray_epsilon, params.aim);
    // Φ/N.
    var flux = start.flux * params.inv_photon_count;
    var dir = start.dir;
    var origin = start.origin;
    var skip = start.skip;
    // Every scattering so far was a specular (delta) one, and there was one.
    var caustic = false;
    // Deposits where the map is read (counted for a guided photon's start).
    var useful = 0u;
    // Whether the photon's one aimed bounce (lambertian_bounce) is still to come.
    var aim_bounce = true;
    // The first surface deposits unless the map's readers take this light's direct part from
    // a light sample (SampledDirect: 1 every light's, 2 the punctual lights').
    let first_deposit = select(0u, 1u, params.first_deposit == 1u || (params.first_deposit == 2u && start.punctual));
    for (var bounce = 0u; bounce < params.max_bounces; bounce++) {
        let hit = trace(origin, dir, params.ray_epsilon, 3.0e38, skip, NO_TRIANGLE, false);
        if hit.tri == NO_TRIANGLE {
            break;
        }
        flux *= segment_transmittance(hit.tri, dir, hit.t);
        // The texel's albedo, unfiltered (level 0): photons sample the texture point-wise.
        let s = surface_at(hit.tri, hit.b1, hit.b2, 0.0);
        let front = dot(s.normal, dir) < 0.0;
        let lambertian = surface_is_lambertian(s);
        // Glass is entered and left by either face.
        if !front && (s.flags & MATERIAL_TWO_SIDED) == 0u && s.transmission <= 0.0 {
            break;
        }
        let n = select(-s.normal, s.normal, front);
        // Shading normals (photons/mod.rs): the deposit estimates the shading irradiance,
        // flux × |ω_o·n_s|/|ω_o·n_g| with ω_o = −dir, and scattering has the adjoint weight
        // f·|ω_i·n_s|/pdf · (|ω_o·n_s|/|ω_o·n_g|)·(|ω_i·n_g|/|ω_i·n_s|).
        let ns = bend_towards(select(-s.shading, s.shading, front), -dir);
        let arrive = dot(-dir, ns) / dot(-dir, n);
        if bounce >= first_deposit {
            deposit(s.pos, hit.tri, !front, flux * arrive, 0u);
            if start.bin != NO_BIN && is_read(s.pos) {
                useful += 1u;
            }
        }
        // A photon that came through specular surfaces alone adds to the caustic map too.
        if SCENE_PASSES_RAYS && caustic {
            deposit(s.pos, hit.tri, !front, flux * arrive, CAUSTIC_CELL);
        }
        var below = false;
        if lambertian {
            // Russian roulette by the albedo, then a cosine-distributed direction: f·cos/pdf = ρ.
            let survive = max(s.albedo.x, max(s.albedo.y, s.albedo.z));
            if rng_f32(&rng) >= survive {
                break;
            }
            flux *= s.albedo / survive;
            let v1 = rng_f32(&rng);
            let v2 = rng_f32(&rng);
            // Cosine-distributed, or once outside the aim's sphere towards it (photons/mod.rs).
            let to_aim = params.aim.xyz - s.pos;
            let outside = params.aim.w > 0.0 && dot(to_aim, to_aim) > params.aim.w * params.aim.w;
            let bounce = lambertian_bounce(s.pos, ns, aim_bounce && outside, params.aim, v1, v2);
            aim_bounce = aim_bounce && !outside;
            dir = bounce.dir;
            let cos_s = dot(dir, ns);
            let cos_g = dot(dir, n);
            // No way into the surface.
            if cos_g <= 0.0 || cos_s <= 0.0 || bounce.factor <= 0.0 {
                break;
            }
            flux *= arrive * (cos_g / cos_s) * bounce.factor;
            caustic = false;
        } else {
            // A direction from the BSDF (importance: no 1/η² on refraction), then Russian
            // roulette by its weight. A solid glass hit from behind is left: η inverts.
            let sf = shading_frame(ns);
            var b = surface_bsdf(s);
            if !front && !b.thin {
                b.ior = 1.0 / b.ior;
            }
            let v = vec3f(rng_f32(&rng), rng_f32(&rng), rng_f32(&rng));
            let bs = bsdf_sample(b, to_local(sf, -dir), v, TRANSPORT_IMPORTANCE);
            let u_rr = rng_f32(&rng);
            if !bs.ok {
                break;
            }
            let wi = normalize(sf * bs.wi);
            let cos_g = dot(wi, n);
            below = cos_g < 0.0;
            // The geometric and the shading side agree, or the path ends.
            if (bs.wi.z < 0.0) != below || cos_g == 0.0 || bs.wi.z == 0.0 {
                break;
            }
            let w = bs.weight * (arrive * abs(cos_g / bs.wi.z));
            let survive = min(max(w.x, max(w.y, w.z)), 1.0);
            if u_rr >= survive {
                break;
            }
            flux *= w / survive;
            dir = wi;
            // Caustic light: through the surfaces the gather's rays pass (mirrors, glass) alone;
            // a smooth layer over a diffuse base reflects into the gather's stand-in of it.
            caustic = bs.delta && surface_passes_rays(s) && (caustic || bounce == 0u);
        }
        origin = s.pos + select(n, -n, below) * params.ray_epsilon;
        skip = hit.tri;
    }
    // What the guide learns (guide.rs: PhotonGuide::learn): this start's photons and their
    // deposits where the map is read.
    if start.bin != NO_BIN {
        if useful > 0u {
            atomicAdd(&photon_guide[params.guide_counters + start.bin], useful);
        }
        atomicAdd(&photon_guide[params.guide_counters + params.guide_bins + start.bin], 1u);
    }
}

@compute @workgroup_size(64)
fn resolve_map(@builtin(global_invocation_id) gid: vec3u) {
    let s = gid.x + gid.y * params.groups_x * 64u;
    if s > params.mask {
        return;
    }
    var flux = vec3f(0.0);
    for (var c = 0u; c < 3u; c++) {
        flux[c] = tally64(c, s) / params.quantum;
    }
    let h2 = params.grid.cell * params.grid.cell;
    slots_out[s] = vec4f(flux / h2, slot_area[s]);
}
