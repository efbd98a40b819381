// Eye pass (gbuffer.rs): vertices pulled from the scene's triangle buffer; each fragment
// stores (triangle + 1, b1, b2) of the nearest surface.

struct VertexOut {
    @builtin(position) clip: vec4f,
    @location(0) bary: vec2f,
    @location(1) @interpolate(flat) tri: u32,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VertexOut {
    let tri = vi / 3u;
    let corner = vi % 3u;
    let t = triangles[tri];
    var p = t.v0;
    var b = vec2f(0.0, 0.0);
    if corner == 1u {
        p = t.v1;
        b = vec2f(1.0, 0.0);
    } else if corner == 2u {
        p = t.v2;
        b = vec2f(0.0, 1.0);
    }
    var out: VertexOut;
    out.clip = frame.view_proj * vec4f(p, 1.0);
    out.bary = b;
    out.tri = tri;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4u {
    return vec4u(in.tri + 1u, bitcast<u32>(in.bary.x), bitcast<u32>(in.bary.y), 0u);
}
