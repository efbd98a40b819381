// Ray-view rasterization of the final gather (gather.rs): the depth-complexity count and
// the back-to-front depth peel.

struct Gather {
    view_proj: mat4x4f,
    direction: vec3f,
    bundle: u32,
}

@group(1) @binding(0) var<uniform> gather: Gather;

struct VertexOut {
    @builtin(position) clip: vec4f,
    @location(0) bary: vec2f,
    @location(1) @interpolate(flat) tri: u32,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VertexOut {
    let v = triangle_vertex(vi);
    var out: VertexOut;
    out.clip = gather.view_proj * vec4f(v.pos, 1.0);
    out.bary = v.bary;
    out.tri = v.tri;
    return out;
}

// Depth complexity: fragments per texel, and their maximum over the ray view.
@group(1) @binding(1) var<storage, read_write> counts: array<atomic<u32>>;
@group(1) @binding(2) var<storage, read_write> max_count: atomic<u32>;

@fragment
fn fs_count(in: VertexOut) -> @location(0) vec4u {
    let texel = vec2u(in.clip.xy);
    let n = atomicAdd(&counts[texel.y * gather.bundle + texel.x], 1u) + 1u;
    atomicMax(&max_count, n);
    return vec4u(0u);
}

// Peel: the farthest fragment strictly nearer than the previous layer (depth test Greater).
@group(1) @binding(1) var previous_layer: texture_2d<u32>;

@fragment
fn fs_peel(in: VertexOut) -> @location(0) vec4u {
    let previous = bitcast<f32>(textureLoad(previous_layer, vec2u(in.clip.xy), 0).w);
    if in.clip.z >= previous {
        discard;
    }
    return vec4u(in.tri + 1u, bitcast<u32>(in.bary.x), bitcast<u32>(in.bary.y), bitcast<u32>(in.clip.z));
}
