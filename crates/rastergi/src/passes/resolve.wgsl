// Resolve (film.rs): mean of the accumulated sums → linear RGB and display RGBA8 (`main`);
// or a linear image that is already a mean, such as the denoiser's, → the same two
// (`resolve_image`, with `film` bound to that image: one vec4 per pixel).

@group(0) @binding(0) var<uniform> params: Resolve;
@group(0) @binding(1) var<storage, read> film: array<vec4f>;
@group(0) @binding(2) var<storage, read_write> linear_out: array<vec4f>;
@group(0) @binding(3) var<storage, read_write> display_out: array<u32>;

// The film's layout, without the frame: `film_add` is not used here.
fn film_slot(component: u32, pixel: u32, n_pixels: u32) -> u32 {
    return component * n_pixels + pixel;
}

// The sRGB transfer function (IEC 61966-2-1).
fn srgb_encode(c: vec3f) -> vec3f {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3f(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3f(0.0031308));
}

// The display encoding of a linear value: 2^exposure · value, clamped, sRGB, 8 bits.
fn display_encode(mean: vec3f) -> u32 {
    let display = srgb_encode(clamp(mean * params.scale, vec3f(0.0), vec3f(1.0)));
    return pack4x8unorm(vec4f(display, 1.0));
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= params.resolution) {
        return;
    }
    let pixel = gid.y * params.resolution.x + gid.x;
    let n = params.resolution.x * params.resolution.y;
    let direct = film[film_slot(FILM_DIRECT, pixel, n)].rgb;
    let indirect = film[film_slot(FILM_INDIRECT, pixel, n)].rgb;
    var sum = direct + indirect;
    if params.show == 1u {
        sum = direct;
    } else if params.show == 2u {
        sum = indirect;
    } else if params.show == 3u {
        sum = film[film_slot(FILM_PHOTON_VIEW, pixel, n)].rgb;
    }
    let mean = sum / f32(max(params.samples, 1u));
    linear_out[pixel] = vec4f(mean, 1.0);
    display_out[pixel] = display_encode(mean);
}

@compute @workgroup_size(8, 8)
fn resolve_image(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= params.resolution) {
        return;
    }
    let pixel = gid.y * params.resolution.x + gid.x;
    let mean = film[pixel].rgb;
    linear_out[pixel] = vec4f(mean, 1.0);
    display_out[pixel] = display_encode(mean);
}
