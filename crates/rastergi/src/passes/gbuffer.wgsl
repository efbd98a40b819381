// Eye pass (gbuffer.rs): vertices pulled from the scene's triangle buffer; each fragment
// stores (triangle + 1, b1, b2, texture level of detail) of the nearest surface.

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> RasterVertex {
    return raster_vertex(vi, frame.view_proj, true);
}

// The level of detail comes from the texture coordinates' change to the neighbouring pixels
// (screen-space derivatives), as a fragment shader's implicit texture sampling would do. They
// are taken of an interpolated input, not of values loaded in the fragment shader: helper
// invocations outside the triangle may not load memory (lavapipe's read zeros). Where the
// material lets the eye through (a cut-out's hole, stochastic opacity), the fragment is
// discarded and the surface behind it is seen.
@fragment
fn fs_main(in: RasterVertex) -> @location(0) vec4u {
    let dx = dpdx(in.uv);
    let dy = dpdy(in.uv);
    let t = triangles[in.tri];
    var lod = 0.0;
    if frame.texture_footprint != 0u && (materials[t.material].material.flags & MATERIAL_TEXTURED) != 0u {
        lod = albedo_lod(t.material, dx, dy);
    }
    start_alpha_stream();
    if (t.flags & TRIANGLE_HAS_HOLES) != 0u && passes_through(in.tri, in.bary.x, in.bary.y, lod) {
        discard;
    }
    return vec4u(in.tri + 1u, bitcast<u32>(in.bary.x), bitcast<u32>(in.bary.y), bitcast<u32>(lod));
}
