// The film's second half-accumulation (film.rs, Film::begin_iteration): the sums of the
// iterations of odd blocks. Opening a block subtracts the film's sums from it, closing the
// block adds them back, so it gains what the block added.

@group(0) @binding(0) var<storage, read> film: array<vec4f>;
@group(0) @binding(1) var<storage, read_write> half_sums: array<vec4f>;

// Element gid.x + gid.y · (groups along x · 64) of the flat arrays.
@compute @workgroup_size(64)
fn open_block(@builtin(global_invocation_id) gid: vec3u, @builtin(num_workgroups) groups: vec3u) {
    let i = gid.x + gid.y * groups.x * 64u;
    if i < arrayLength(&half_sums) {
        half_sums[i] -= film[i];
    }
}

@compute @workgroup_size(64)
fn close_block(@builtin(global_invocation_id) gid: vec3u, @builtin(num_workgroups) groups: vec3u) {
    let i = gid.x + gid.y * groups.x * 64u;
    if i < arrayLength(&half_sums) {
        half_sums[i] += film[i];
    }
}
