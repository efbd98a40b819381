// The guides' tables made from what the passes learned (gather/guide.rs): per cell in use and
// per guide, each direction bin's weight from its sum over its count, smoothed towards the
// cell's mean by a few pseudo-samples — the gather guide's the bin's mean radiance, the guided
// sky's (passes/sky_guide.rs) the block's environment mass times its mean openness — and the
// cumulative weights are what the guides draw from; none (no guiding) before the cell has
// counted enough samples. A table
// whose bins counted GATHER_GUIDE_DECAY samples or more has its sums and counts halved first,
// so the counters never overflow and the table follows what recent iterations found.

@group(0) @binding(0) var<storage, read_write> photon_guide: array<atomic<u32>>;

// Makes the table at offset t of entry e: the gather's — each bin's mean radiance smoothed
// towards the cell's mean by GATHER_GUIDE_PRIOR pseudo-samples, no weights before the cell
// counted GATHER_GUIDE_MIN_SAMPLES; `sky`: the guided sky's — each block's mean openness
// smoothed by SKY_GUIDE_PRIOR pseudo-samples, times the block's mass, no weights before
// SKY_GUIDE_MIN_SAMPLES.
fn build_table(e: u32, t: u32, sky: bool) {
    var most = 0u;
    var all_sums = 0.0;
    var all_counts = 0u;
    for (var b = 0u; b < GATHER_GUIDE_BINS; b++) {
        let count = atomicLoad(&photon_guide[guide_entry_word(e, t + GATHER_GUIDE_BINS + b)]);
        most = max(most, count);
        all_counts += count;
        all_sums += f32(atomicLoad(&photon_guide[guide_entry_word(e, t + b)]));
    }
    let halve = most >= GATHER_GUIDE_DECAY;
    let blocks = guide_header_u32(13u) * guide_header_u32(14u);
    let learned = all_counts >= select(GATHER_GUIDE_MIN_SAMPLES, SKY_GUIDE_MIN_SAMPLES, sky);
    let mean = all_sums / f32(max(all_counts, 1u));
    var acc = 0.0;
    for (var b = 0u; b < GATHER_GUIDE_BINS; b++) {
        let s = guide_entry_word(e, t + b);
        let c = guide_entry_word(e, t + GATHER_GUIDE_BINS + b);
        var sum = atomicLoad(&photon_guide[s]);
        var count = atomicLoad(&photon_guide[c]);
        if halve {
            sum /= 2u;
            count /= 2u;
            atomicStore(&photon_guide[s], sum);
            atomicStore(&photon_guide[c], count);
        }
        if sky {
            if learned && b < blocks {
                let open = (f32(sum) + SKY_GUIDE_PRIOR * mean) / (f32(count) + SKY_GUIDE_PRIOR);
                acc += open * sky_block_mass(b);
            }
        } else if learned {
            acc += (f32(sum) + GATHER_GUIDE_PRIOR * mean) / (f32(count) + GATHER_GUIDE_PRIOR);
        }
        atomicStore(&photon_guide[guide_entry_word(e, t + 2u * GATHER_GUIDE_BINS + b)], bitcast<u32>(acc));
    }
}

@compute @workgroup_size(64)
fn build_guide(@builtin(global_invocation_id) gid: vec3u, @builtin(num_workgroups) groups: vec3u) {
    let e = gid.x + gid.y * groups.x * 64u;
    if e >= guide_header_u32(7u) || atomicLoad(&photon_guide[guide_entry_word(e, 0u)]) == 0u {
        return;
    }
    if gather_guide_table() != GUIDE_NO_TABLE {
        build_table(e, gather_guide_table(), false);
    }
    if sky_guide_table() != GUIDE_NO_TABLE {
        build_table(e, sky_guide_table(), true);
    }
}
