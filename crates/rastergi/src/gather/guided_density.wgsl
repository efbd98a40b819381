// The guided gather's density (gather/guide.rs), for the passes that know the visible point:
// the traced gather and the direct pass, which weigh the sky's two estimates with it.

// The guided gather's density of direction w at visible point p (per steradian): the mixture
// (1 − g)·p_scatter(w) + g·q(w) of p's own scattering (gather_density) and entry e's table
// (total weight `total`; where it is 0, the scattering alone).
fn guided_gather_density(p: VisiblePoint, e: u32, total: f32, w: vec3f) -> f32 {
    let scatter = gather_density(p, w);
    if total <= 0.0 || (scatter <= 0.0 && gather_cosine(p, w) <= 0.0) {
        return scatter;
    }
    return (1.0 - GATHER_GUIDE_FRACTION) * scatter + GATHER_GUIDE_FRACTION * gather_guide_pdf(e, total, w);
}
