// The photon budget's measurements (photons/budget.rs): a snapshot of the film where a photon
// pass starts, and at its end the sums over the pixels of
//   e² = (x − x₋)²    the pass's mean x against the previous pass's x₋: the two maps' noise and
//                     the two passes' iterations';
//   x                 (for the log: variances relative to the mean);
// with v a pixel's value (the mean of R, G, B of its direct and indirect sums) and x the mean
// of v over the pass's iterations. Pixels that saw light itself (the film's seen-light count)
// are left out, as the error estimate leaves them out.

@group(0) @binding(0) var<uniform> params: Budget;
@group(0) @binding(1) var<storage, read> film: array<vec4f>;
// Per pixel: (v at the pass's start, the previous pass's mean x₋, unused, unused).
@group(0) @binding(2) var<storage, read_write> snapshots: array<vec4f>;
// Per workgroup: (Σ e², Σ x, pixels counted, unused).
@group(0) @binding(3) var<storage, read_write> partials: array<vec4f>;

const BUDGET_GROUP: u32 = 64u;

var<workgroup> sums: array<vec4f, BUDGET_GROUP>;

// The pixel's value: the mean over R, G, B of its direct and indirect sums, and whether it saw
// light itself.
fn budget_value(p: u32) -> vec2f {
    let direct = film[FILM_DIRECT * params.pixels + p];
    let indirect = film[FILM_INDIRECT * params.pixels + p];
    let v = (direct.rgb + indirect.rgb) / 3.0;
    return vec2f(v.r + v.g + v.b, direct.a);
}

fn budget_pixel(gid: vec3u, groups: vec3u) -> u32 {
    return gid.x + gid.y * groups.x * BUDGET_GROUP;
}

@compute @workgroup_size(64)
fn start(@builtin(global_invocation_id) gid: vec3u, @builtin(num_workgroups) groups: vec3u) {
    let p = budget_pixel(gid, groups);
    if p < params.pixels {
        snapshots[p].x = budget_value(p).x;
    }
}

@compute @workgroup_size(64)
fn end(
    @builtin(global_invocation_id) gid: vec3u,
    @builtin(local_invocation_index) local: u32,
    @builtin(workgroup_id) wg: vec3u,
    @builtin(num_workgroups) groups: vec3u,
) {
    let p = budget_pixel(gid, groups);
    var s = vec4f(0.0);
    if p < params.pixels {
        let value = budget_value(p);
        let snap = snapshots[p];
        let x = (value.x - snap.x) / params.iterations;
        if value.y == 0.0 {
            let e = select(0.0, x - snap.y, params.has_previous != 0u);
            s = vec4f(e * e, x, 1.0, 0.0);
        }
        // The next pass starts where this one ends.
        snapshots[p] = vec4f(value.x, x, 0.0, 0.0);
    }
    sums[local] = s;
    workgroupBarrier();
    for (var half = BUDGET_GROUP / 2u; half > 0u; half /= 2u) {
        if local < half {
            sums[local] += sums[local + half];
        }
        workgroupBarrier();
    }
    if local == 0u {
        partials[wg.x + wg.y * groups.x] = sums[0];
    }
}
