// The gather's uniforms (gather/estimator.rs, GatherUniforms), read by the ray-view raster
// stages and the estimator passes.

struct Gather {
    // Raster: the ray view of `direction`, the direction being rasterized.
    view_proj: mat4x4f,
    direction: vec3f,
    bundle: u32,
    // Directions this iteration; each estimate is weighted 1/count.
    count: u32,
    // Trace: all of them (xyz).
    directions: array<vec4f, MAX_DIRECTIONS>,
}
