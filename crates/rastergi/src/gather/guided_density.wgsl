// The guided gather's density (gather/guide.rs), for the passes that know the visible point:
// the traced gather and the direct pass, which weigh the sky's two estimates with it.

// Whether the gather's directions at p are drawn from entry e's guided mixture (total weight
// `total`): where its cell has learned something and p's surface is Lambertian (elsewhere the
// BSDF's own sampling draws them).
fn gather_guided_at(p: VisiblePoint, total: f32) -> bool {
    return total > 0.0 && surface_is_lambertian(p.x);
}

// The guided gather's density of direction w at visible point p (per steradian): the
// mixture's F_b·cos θ/π on the cosine warp's bin b of w (gather_guide_sample), where p is
// guided; p's own scattering's density (gather_density) elsewhere.
fn guided_gather_density(p: VisiblePoint, e: u32, total: f32, w: vec3f) -> f32 {
    let scatter = gather_density(p, w);
    if !gather_guided_at(p, total) || scatter <= 0.0 {
        return scatter;
    }
    return scatter * gather_guide_factor(e, total, gather_guide_bin(p.ns, w));
}
