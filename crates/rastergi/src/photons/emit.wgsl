// Photon emission (the photon tracer's; lights.rs: LightTable::emit_photon_guided, its CPU
// twin): where a photon starts, its direction and its flux. The sun's and the sky's photons
// start on a disc across the scene, aimed at the photon region (disc_start) and, where the
// guide has learned it, drawn towards where the map is read (guided_start; photons/guide.rs).
// The including shader binds `photon_guide` and `params` (trace.wgsl).

// A photon leaving the lights: origin, direction, flux × the photon count, the emitter
// triangle to skip (NO_TRIANGLE for the other lights), its guide counter bin (NO_BIN for a
// light that is not guided), and whether its light is punctual (a point, spot or distant
// light: SampledDirect::skips_first).
struct PhotonStart {
    origin: vec3f,
    skip: u32,
    dir: vec3f,
    bin: u32,
    flux: vec3f,
    punctual: bool,
}

const NO_BIN: u32 = 0xffffffffu;

// A point uniform (u1, u2) on the disc of radius r, normal to `axis`, that a photon crossing
// the sphere (centre, r) along `axis` starts from.
fn disc_point(axis: vec3f, centre: vec3f, r: f32, u1: f32, u2: f32) -> vec3f {
    let tb = orthonormal_basis(axis);
    let rho = r * sqrt(u1);
    let phi = 2.0 * PI * u2;
    return centre - axis * r + (tb[0] * cos(phi) + tb[1] * sin(phi)) * rho;
}

// The start of a photon crossing the sphere (centre, r) along `axis`, aimed at the sphere
// aim = (centre, radius; radius 0: not aimed): (origin, 1/p(x)) (lights.rs: disc_start).
struct DiscStart {
    origin: vec3f,
    inv_pdf: f32,
}

fn disc_start(axis: vec3f, centre: vec3f, r: f32, aim: vec4f, u1: f32, u2: f32) -> DiscStart {
    var s: DiscStart;
    if aim.w <= 0.0 {
        s.origin = disc_point(axis, centre, r, u1, u2);
        s.inv_pdf = PI * r * r;
        return s;
    }
    let tb = orthonormal_basis(axis);
    let phi = 2.0 * PI * u2;
    let dir = tb[0] * cos(phi) + tb[1] * sin(phi);
    let d = aim.xyz - centre;
    let towards = d - axis * dot(d, axis);
    let near = aim.w * NEAR_SCALE;
    let whole = 1.0 - AIM_FRACTION - NEAR_FRACTION;
    var branch = 2u;
    if u1 < AIM_FRACTION {
        branch = 0u;
    } else if u1 < AIM_FRACTION + NEAR_FRACTION {
        branch = 1u;
    }
    var offset: vec3f;
    if branch == 0u {
        offset = towards + dir * (aim.w * sqrt(u1 / AIM_FRACTION));
    } else if branch == 1u {
        offset = towards + dir * (near * sqrt((u1 - AIM_FRACTION) / NEAR_FRACTION));
    } else {
        offset = dir * (r * sqrt((u1 - AIM_FRACTION - NEAR_FRACTION) / whole));
    }
    let from_aim = length(offset - towards);
    let in_aim = branch == 0u || from_aim <= aim.w;
    let in_near = branch <= 1u || from_aim <= near;
    let in_whole = branch == 2u || length(offset) <= r;
    let p = select(0.0, AIM_FRACTION / (PI * aim.w * aim.w), in_aim)
        + select(0.0, NEAR_FRACTION / (PI * near * near), in_near)
        + select(0.0, whole / (PI * r * r), in_whole);
    s.origin = centre - axis * r + offset;
    s.inv_pdf = 1.0 / p;
    return s;
}

// disc_start's density per unit area at `offset` from the disc's centre (lights.rs:
// disc_density).
fn disc_density(axis: vec3f, centre: vec3f, r: f32, aim: vec4f, offset: vec3f) -> f32 {
    let in_disc = length(offset) <= r;
    if aim.w <= 0.0 {
        return select(0.0, 1.0 / (PI * r * r), in_disc);
    }
    let d = aim.xyz - centre;
    let towards = d - axis * dot(d, axis);
    let near = aim.w * NEAR_SCALE;
    let whole = 1.0 - AIM_FRACTION - NEAR_FRACTION;
    let from_aim = length(offset - towards);
    return select(0.0, AIM_FRACTION / (PI * aim.w * aim.w), from_aim <= aim.w)
        + select(0.0, NEAR_FRACTION / (PI * near * near), from_aim <= near)
        + select(0.0, whole / (PI * r * r), in_disc);
}

// Shirley and Chiu's concentric map of the unit square onto the unit disc, area-preserving
// (guide.rs: concentric).
fn concentric(u: f32, v: f32) -> vec2f {
    let a = 2.0 * u - 1.0;
    let b = 2.0 * v - 1.0;
    if a == 0.0 && b == 0.0 {
        return vec2f(0.0);
    }
    var r: f32;
    var phi: f32;
    if abs(a) > abs(b) {
        r = a;
        phi = 0.25 * PI * (b / a);
    } else {
        r = b;
        phi = 0.5 * PI - 0.25 * PI * (a / b);
    }
    return r * vec2f(cos(phi), sin(phi));
}

// Its inverse (guide.rs: concentric_inverse).
fn concentric_inverse(x: f32, y: f32) -> vec2f {
    let q = 0.25 * PI;
    let r = sqrt(x * x + y * y);
    var phi = atan2(y, x);
    if phi < -q {
        phi += 2.0 * PI;
    }
    var ab: vec2f;
    if phi < q {
        ab = vec2f(r, r * phi / q);
    } else if phi < 3.0 * q {
        ab = vec2f(-r * (phi - 2.0 * q) / q, r);
    } else if phi < 5.0 * q {
        ab = vec2f(-r, -r * (phi - PI) / q);
    } else {
        ab = vec2f(r * (phi - 6.0 * q) / q, -r);
    }
    return clamp((ab + 1.0) * 0.5, vec2f(0.0), vec2f(1.0));
}

// The sky's direction bin of direction `to_sky` (guide.rs: env_direction_bin).
fn env_direction_bin(to_sky: vec3f) -> u32 {
    let band = min(u32((to_sky.y + 1.0) * 0.5 * f32(GUIDE_ENV_BANDS)), GUIDE_ENV_BANDS - 1u);
    let u = atan2(to_sky.x, -to_sky.z) / (2.0 * PI);
    let sector = min(u32((u - floor(u)) * f32(GUIDE_ENV_BANDS)), GUIDE_ENV_BANDS - 1u);
    return band * GUIDE_ENV_BANDS + sector;
}

// The guide disc's position bin of disc coordinates (x, y) in units of its radius, NO_BIN
// outside (guide.rs: position_bin).
fn position_bin(x: f32, y: f32) -> u32 {
    if x * x + y * y > 1.0 {
        return NO_BIN;
    }
    let uv = concentric_inverse(x, y);
    let i = min(u32(uv.x * f32(GUIDE_POSITIONS)), GUIDE_POSITIONS - 1u);
    let j = min(u32(uv.y * f32(GUIDE_POSITIONS)), GUIDE_POSITIONS - 1u);
    return j * GUIDE_POSITIONS + i;
}

// Word k of the guide's table.
fn guide_word(k: u32) -> u32 {
    return atomicLoad(&photon_guide[params.guide_table + k]);
}

// A guided light's table for one direction bin: the first word of its cdf (0 where the
// direction is not learned yet) and its counter bins' first (NO_BIN where the light is not
// guided).
struct GuideData {
    cdf: u32,
    first_bin: u32,
}

// Light entry e's table for direction bin d (guide.rs: GuideTable::words).
fn guide_data(e: u32, d: u32) -> GuideData {
    var g = GuideData(0u, NO_BIN);
    for (var k = 0u; k < MAX_GUIDED_LIGHTS; k++) {
        let h = k * GUIDE_HEADER_WORDS;
        if guide_word(h) == e {
            let n = GUIDE_POSITIONS * GUIDE_POSITIONS;
            let at = guide_word(h + 2u) + d * (1u + n);
            g.first_bin = guide_word(h + 3u) + d * n;
            if bitcast<f32>(guide_word(at)) > 0.0 {
                g.cdf = at + 1u;
            }
            return g;
        }
    }
    return g;
}

// The start of a guided light's photon (guide.rs: guided_start): along `axis` from the disc
// (centre, r), aimed at `aim`, with the table g: (origin, 1/p(x|ω)) and its position bin.
struct GuidedStart {
    origin: vec3f,
    inv_pdf: f32,
    position: u32,
}

fn guided_start(axis: vec3f, centre: vec3f, r: f32, aim: vec4f, g: GuideData, u1: f32, u2: f32) -> GuidedStart {
    var s: GuidedStart;
    let tb = orthonormal_basis(axis);
    // The guide disc: about the aim's projection, as wide as its surroundings; else the disc.
    var towards = vec3f(0.0);
    var radius = r;
    if aim.w > 0.0 {
        let d = aim.xyz - centre;
        towards = d - axis * dot(d, axis);
        radius = aim.w * NEAR_SCALE;
    }
    let start = centre - axis * r;
    if g.cdf == 0u {
        let d = disc_start(axis, centre, r, aim, u1, u2);
        let rel = d.origin - start - towards;
        s.origin = d.origin;
        s.inv_pdf = d.inv_pdf;
        s.position = position_bin(dot(rel, tb[0]) / radius, dot(rel, tb[1]) / radius);
        return s;
    }
    let n = GUIDE_POSITIONS * GUIDE_POSITIONS;
    var offset: vec3f;
    var p0: f32;
    // The position bin: the table's where it drew x (its own term counted: rounding at a bin's
    // edge never moves x into a bin of another weight), else x's.
    var drawn = NO_BIN;
    if u1 < GUIDED_FRACTION {
        let u = u1 / GUIDED_FRACTION;
        // The first bin whose cdf exceeds u (partition_point).
        var lo = 0u;
        var hi = n;
        while lo < hi {
            let mid = (lo + hi) / 2u;
            if bitcast<f32>(guide_word(g.cdf + mid)) <= u {
                lo = mid + 1u;
            } else {
                hi = mid;
            }
        }
        let bin = min(lo, n - 1u);
        drawn = bin;
        var below = 0.0;
        if bin > 0u {
            below = bitcast<f32>(guide_word(g.cdf + bin - 1u));
        }
        let t = clamp((u - below) / max(bitcast<f32>(guide_word(g.cdf + bin)) - below, 1e-30), 0.0, 0.9999999);
        let xy = concentric((f32(bin % GUIDE_POSITIONS) + t) / f32(GUIDE_POSITIONS), (f32(bin / GUIDE_POSITIONS) + u2) / f32(GUIDE_POSITIONS));
        offset = towards + (tb[0] * xy.x + tb[1] * xy.y) * radius;
        p0 = disc_density(axis, centre, r, aim, offset);
    } else {
        let u = min((u1 - GUIDED_FRACTION) / (1.0 - GUIDED_FRACTION), 0.9999999);
        let d = disc_start(axis, centre, r, aim, u, u2);
        offset = d.origin - start;
        p0 = 1.0 / d.inv_pdf;
    }
    let rel = offset - towards;
    s.position = drawn;
    if drawn == NO_BIN {
        s.position = position_bin(dot(rel, tb[0]) / radius, dot(rel, tb[1]) / radius);
    }
    var q = 0.0;
    if s.position != NO_BIN {
        var below = 0.0;
        if s.position > 0u {
            below = bitcast<f32>(guide_word(g.cdf + s.position - 1u));
        }
        q = (bitcast<f32>(guide_word(g.cdf + s.position)) - below) * f32(n) / (PI * radius * radius);
    }
    s.origin = start + offset;
    s.inv_pdf = 1.0 / ((1.0 - GUIDED_FRACTION) * p0 + GUIDED_FRACTION * q);
    return s;
}

// The counter bin of a guided photon (NO_BIN for none).
fn guide_bin(g: GuideData, position: u32) -> u32 {
    if g.first_bin == NO_BIN || position == NO_BIN {
        return NO_BIN;
    }
    return g.first_bin + position;
}

// `aim`: where sun and sky photons are aimed (disc_start).
fn emit_photon(u0: f32, u1: f32, u2: f32, u3: f32, u4: f32, eps: f32, aim: vec4f) -> PhotonStart {
    var s: PhotonStart;
    s.bin = NO_BIN;
    let e = light_pick(u0);
    let entry = light_entry(e);
    if entry.triangle == ENVIRONMENT_LIGHT {
        // Towards the sky along the sampled direction; the photon travels the other way, from
        // the disc across the bounding sphere: L(ω)/(p(x|ω)·pdf(ω)·pmf).
        let sky = env_sample(u3, u4);
        s.dir = -sky.xyz;
        let g = guide_data(e, env_direction_bin(sky.xyz));
        let start = guided_start(s.dir, environment.disc_centre, environment.disc_radius, aim, g, u1, u2);
        s.origin = start.origin;
        s.flux = select(vec3f(0.0), env_radiance(sky.xyz) * (start.inv_pdf / (sky.w * entry.pmf)), sky.w > 0.0);
        s.skip = NO_TRIANGLE;
        s.bin = guide_bin(g, start.position);
        return s;
    }
    if (entry.triangle & PUNCTUAL_LIGHT) == 0u {
        let l = sample_light(e, u1, u2);
        // Φ = π·Le·A/pmf.
        s.flux = l.radiance * (PI / l.pdf_area);
        s.dir = cosine_hemisphere(l.normal, u3, u4);
        s.origin = l.pos + l.normal * eps;
        s.skip = l.tri;
        return s;
    }
    let p = punctual_light(entry.triangle & ~PUNCTUAL_LIGHT);
    s.skip = NO_TRIANGLE;
    s.punctual = true;
    if p.kind == LIGHT_POINT {
        s.origin = p.position;
        s.dir = uniform_sphere(u3, u4);
        s.flux = p.intensity * (4.0 * PI / entry.pmf);
    } else if p.kind == LIGHT_SPOT {
        s.origin = p.position;
        s.dir = cone_direction(p.direction, p.cos_outer, u3, u4);
        let solid = 2.0 * PI * (1.0 - p.cos_outer);
        s.flux = p.intensity * (spot_falloff(p, dot(p.direction, s.dir)) * solid / entry.pmf);
    } else {
        let g = guide_data(e, 0u);
        let start = guided_start(p.direction, p.disc_centre, p.disc_radius, aim, g, u1, u2);
        s.origin = start.origin;
        s.dir = cone_direction(p.direction, p.cos_outer, u3, u4);
        s.flux = p.intensity * (start.inv_pdf / entry.pmf);
        s.bin = guide_bin(g, start.position);
    }
    return s;
}
