// The gather's uniforms (gather/estimator.rs, GatherUniforms), read by the ray-view raster
// stages and the estimator passes.

struct Gather {
    // Raster: the ray view of `direction`, the direction being rasterized.
    view_proj: mat4x4f,
    direction: vec3f,
    bundle: u32,
    // Directions this iteration; each estimate is weighted 1/count.
    count: u32,
    // Trace: 1 where each pixel draws its own directions (then `directions` is unused) and the
    // key of the pixels' scramble seeds.
    per_pixel: u32,
    pixel_key: u32,
    // The sample index of the iteration's first direction (i·K), and the index among the
    // iteration's directions of the ray view's (raster): direction k has sample index
    // first_index + k.
    first_index: u32,
    current: u32,
    // Trace, shared directions: all of them (xyz).
    directions: array<vec4f, MAX_DIRECTIONS>,
}
