// Rays counted (`--count-rays`, gpu_scene.rs): every query of `trace` adds one to a 64-bit count
// kept as two words, low then high (WGSL has no 64-bit atomics: the query that wraps the low
// word round carries one into the high word).

@group(0) @binding(16) var<storage, read_write> ray_count: array<atomic<u32>>;

fn count_ray() {
    if atomicAdd(&ray_count[0], 1u) == 0xffffffffu {
        atomicAdd(&ray_count[1], 1u);
    }
}
