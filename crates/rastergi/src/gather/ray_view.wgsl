// Ray-view rasterization of the final gather (gather/ray_view.rs): the depth-complexity
// count and the back-to-front depth peel (raster.rs), and the per-texel fragment lists
// (lists.rs).

@group(1) @binding(0) var<uniform> gather: Gather;

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> RasterVertex {
    return raster_vertex(vi, gather.view_proj, false);
}

// Whether the fragment is a hole of its surface (passes_through), decided the same way in the
// count, the peel and the lists: the stream of stochastic opacity is the direction's.
fn is_hole(in: RasterVertex) -> bool {
    alpha_seed = pcg_hash(gather.pixel_key ^ pcg_hash(gather.first_index + gather.current));
    return (triangles[in.tri].flags & TRIANGLE_HAS_HOLES) != 0u && passes_through(in.tri, in.bary.x, in.bary.y, 0.0);
}

// Depth complexity: fragments per texel, and their maximum over the ray view.
@group(1) @binding(1) var<storage, read_write> counts: array<atomic<u32>>;
@group(1) @binding(2) var<storage, read_write> max_count: atomic<u32>;

@fragment
fn fs_count(in: RasterVertex) -> @location(0) vec4u {
    if is_hole(in) {
        discard;
    }
    let texel = vec2u(in.clip.xy);
    let n = atomicAdd(&counts[texel.y * gather.bundle + texel.x], 1u) + 1u;
    atomicMax(&max_count, n);
    return vec4u(0u);
}

// Peel: the farthest fragment strictly nearer than the previous layer (depth test Greater).
@group(1) @binding(1) var previous_layer: texture_2d<u32>;

@fragment
fn fs_peel(in: RasterVertex) -> @location(0) vec4u {
    if is_hole(in) {
        discard;
    }
    let previous = bitcast<f32>(textureLoad(previous_layer, vec2u(in.clip.xy), 0).w);
    if in.clip.z >= previous {
        discard;
    }
    return vec4u(in.tri + 1u, bitcast<u32>(in.bary.x), bitcast<u32>(in.bary.y), bitcast<u32>(in.clip.z));
}

// Fragment lists: every fragment prepends its triangle to its texel's list. heads[texel] is
// the first node + 1 (0: empty); node i is (triangle, next node + 1). The pool holds at most
// arrayLength(&nodes) fragments: lists.rs sizes it to a bound on any view's fragments.
@group(1) @binding(1) var<storage, read_write> heads: array<atomic<u32>>;
@group(1) @binding(2) var<storage, read_write> nodes: array<vec2u>;
@group(1) @binding(3) var<storage, read_write> node_count: atomic<u32>;

@fragment
fn fs_list(in: RasterVertex) -> @location(0) vec4u {
    if is_hole(in) {
        discard;
    }
    let node = atomicAdd(&node_count, 1u);
    if node < arrayLength(&nodes) {
        let texel = vec2u(in.clip.xy);
        let next = atomicExchange(&heads[texel.y * gather.bundle + texel.x], node + 1u);
        nodes[node] = vec2u(in.tri, next);
    }
    return vec4u(0u);
}
