// Eye pass by ray casting (gbuffer.rs, `EyeMethod::Trace`): the G-buffer the rasterizer writes
// (gbuffer.wgsl) — (triangle + 1, b1, b2, texture level of detail) of the nearest surface at
// the pixel's jittered sample, 0 where nothing is seen — found by casting the camera ray
// through that sample into the BVH instead. The level of detail comes from ray differentials
// (eye_ray.wgsl) where the rasterizer takes screen-space derivatives; a cut-out's hole or a
// stochastic opacity lets the ray through as it lets the rasterizer's fragment be discarded.
// Drawing every triangle costs the same for 40 × 23 pixels as for the window; a ray a pixel
// costs by the pixel: a coarse preview of a large scene is cheaper traced.

@group(2) @binding(0) var visibility: texture_storage_2d<rgba32uint, write>;

const EYE_FAR: f32 = 3.0e38;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.resolution) {
        return;
    }
    start_alpha_stream();
    let hit = trace(frame.eye, camera_direction(gid.xy), 0.0, EYE_FAR, NO_TRIANGLE, NO_TRIANGLE, false);
    var v = vec4u(0u);
    if hit.tri != NO_TRIANGLE {
        var lod = 0.0;
        if frame.texture_footprint != 0u
            && (materials[triangles[hit.tri].material].material.flags & MATERIAL_TEXTURED) != 0u {
            lod = primary_lod(hit.tri, gid.xy);
        }
        v = vec4u(hit.tri + 1u, bitcast<u32>(hit.b1), bitcast<u32>(hit.b2), bitcast<u32>(lod));
    }
    textureStore(visibility, vec2i(gid.xy), v);
}
