// Shared by the denoiser's passes (denoise/mod.rs): the luminance and the albedo a light value is
// divided by (its own where a channel exceeds DEMODULATION_MIN, else 1).

fn luminance(c: vec3f) -> f32 {
    return dot(c, vec3f(0.2126, 0.7152, 0.0722));
}

fn demodulation(albedo: vec3f) -> vec3f {
    return select(vec3f(1.0), albedo, albedo > vec3f(DEMODULATION_MIN));
}
