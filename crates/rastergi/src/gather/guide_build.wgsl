// The gather guide's tables made from what the gather learned (gather/guide.rs): per cell in
// use, each direction bin's weight is its mean radiance (its sum over its count), and the
// cumulative weights are what gather_guide_sample draws from. A cell whose bins counted
// GATHER_GUIDE_DECAY samples or more has its sums and counts halved first, so the counters
// never overflow and the table follows what recent iterations found.

@group(0) @binding(0) var<storage, read_write> photon_guide: array<atomic<u32>>;

@compute @workgroup_size(64)
fn build_guide(@builtin(global_invocation_id) gid: vec3u, @builtin(num_workgroups) groups: vec3u) {
    let e = gid.x + gid.y * groups.x * 64u;
    if e >= guide_header_u32(7u) || atomicLoad(&photon_guide[guide_entry_word(e, 0u)]) == 0u {
        return;
    }
    var most = 0u;
    for (var b = 0u; b < GATHER_GUIDE_BINS; b++) {
        most = max(most, atomicLoad(&photon_guide[guide_entry_word(e, 1u + GATHER_GUIDE_BINS + b)]));
    }
    let halve = most >= GATHER_GUIDE_DECAY;
    var acc = 0.0;
    for (var b = 0u; b < GATHER_GUIDE_BINS; b++) {
        let s = guide_entry_word(e, 1u + b);
        let c = guide_entry_word(e, 1u + GATHER_GUIDE_BINS + b);
        var sum = atomicLoad(&photon_guide[s]);
        var count = atomicLoad(&photon_guide[c]);
        if halve {
            sum /= 2u;
            count /= 2u;
            atomicStore(&photon_guide[s], sum);
            atomicStore(&photon_guide[c], count);
        }
        if count > 0u {
            acc += f32(sum) / f32(count);
        }
        atomicStore(&photon_guide[guide_entry_word(e, 1u + 2u * GATHER_GUIDE_BINS + b)], bitcast<u32>(acc));
    }
}
