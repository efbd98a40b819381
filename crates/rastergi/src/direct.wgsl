// Direct pass (direct.rs): emission + next-event estimation with BVH shadow rays.

@group(2) @binding(0) var gbuffer: texture_2d<u32>;
// Film: component c of pixel p at c·W·H + p; 0 direct (incl. emission), 1 indirect, 2 photon view.
@group(2) @binding(1) var<storage, read_write> film: array<vec4f>;

const STREAM_DIRECT: u32 = 0x0d1ec7u;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.resolution) {
        return;
    }
    let pixel = gid.y * frame.resolution.x + gid.x;
    let g = textureLoad(gbuffer, gid.xy, 0);
    var radiance = vec3f(0.0);
    if g.x != 0u {
        let s = surface_at(g.x - 1u, bitcast<f32>(g.y), bitcast<f32>(g.z), bitcast<f32>(g.w));
        let front = dot(s.normal, frame.eye - s.pos) > 0.0;
        if front {
            radiance = s.emission;
        }
        if has_lights() && (front || (s.flags & MATERIAL_TWO_SIDED) != 0u) {
            let n = select(-s.normal, s.normal, front);
            let origin = s.pos + n * frame.ray_epsilon;
            var rng = rng_new(frame.seed ^ STREAM_DIRECT, pixel, frame.iteration);
            var sum = vec3f(0.0);
            for (var k = 0u; k < frame.light_samples; k++) {
                let u0 = rng_f32(&rng);
                let u1 = rng_f32(&rng);
                let u2 = rng_f32(&rng);
                let l = sample_light(u0, u1, u2);
                let to_light = l.pos - origin;
                let dist2 = dot(to_light, to_light);
                let dist = sqrt(dist2);
                let w = to_light / dist;
                let cos_x = dot(n, w);
                let cos_y = -dot(l.normal, w);
                if cos_x > 0.0 && cos_y > 0.0 && !occluded(origin, w, frame.ray_epsilon, dist * (1.0 - 1e-4), s.tri, l.tri) {
                    sum += l.radiance * (cos_x * cos_y / (dist2 * l.pdf_area));
                }
            }
            radiance += s.albedo / PI * sum / f32(frame.light_samples);
        }
    }
    film[pixel] += vec4f(radiance, 0.0);
}
