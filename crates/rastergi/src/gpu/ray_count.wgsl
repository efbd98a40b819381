// Rays counted (`--count-rays`, gpu_scene.rs): every query of `trace` adds one to a 64-bit count
// kept as two words, low then high (WGSL has no 64-bit atomics: the query that wraps the low
// word round carries one into the high word). One count per use of the rays (the eye's and
// direct light's, the gather's, the photons'): shader::for_rays puts the constant
// RAY_COUNT_WORD, the first word of the shader's count, before this.

@group(0) @binding(16) var<storage, read_write> ray_count: array<atomic<u32>>;

fn count_ray() {
    if atomicAdd(&ray_count[RAY_COUNT_WORD], 1u) == 0xffffffffu {
        atomicAdd(&ray_count[RAY_COUNT_WORD + 1u], 1u);
    }
}
