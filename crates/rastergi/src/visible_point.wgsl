// The eye's visible point of a G-buffer texel (gbuffer.rs): (triangle + 1, b1, b2, λ), 0 where
// nothing is seen.

struct VisiblePoint {
    // The surface at the point (meaningful where `seen`).
    x: Surface,
    // Its geometric normal on the side facing the eye.
    n: vec3f,
    // Its shading normal on that side, bent towards the eye where it faces away from it
    // (bend_towards): what every estimate at the point weighs directions by.
    ns: vec3f,
    // The eye sees a surface here.
    seen: bool,
    // The eye sees the surface's front face.
    front: bool,
    // The side facing the eye reflects: a front face, or either face of a two-sided surface.
    ok: bool,
}

fn visible_point(g: vec4u) -> VisiblePoint {
    var p: VisiblePoint;
    p.seen = g.x != 0u;
    p.front = false;
    p.ok = false;
    if !p.seen {
        return p;
    }
    p.x = surface_at(g.x - 1u, bitcast<f32>(g.y), bitcast<f32>(g.z), bitcast<f32>(g.w));
    p.front = dot(p.x.normal, frame.eye - p.x.pos) > 0.0;
    p.n = select(-p.x.normal, p.x.normal, p.front);
    p.ns = bend_towards(select(-p.x.shading, p.x.shading, p.front), normalize(frame.eye - p.x.pos));
    p.ok = p.front || (p.x.flags & MATERIAL_TWO_SIDED) != 0u;
    return p;
}
