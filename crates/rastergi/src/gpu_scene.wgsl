// The scene, bind group 0 of every pass that reads it (gpu_scene.rs).

struct Triangle {
    v0: vec3f,
    material: u32,
    v1: vec3f,
    _pad0: u32,
    v2: vec3f,
    _pad1: u32,
}

// Bit 0 of flags: the back face reflects too.
struct Material {
    albedo: vec3f,
    flags: u32,
    emission: vec3f,
    _pad: u32,
}

struct BvhNode {
    min: vec3f,
    offset: u32,
    max: vec3f,
    count: u32,
}

struct LightEntry {
    triangle: u32,
    cdf: f32,
    pmf: f32,
    area: f32,
}

@group(0) @binding(0) var<storage, read> triangles: array<Triangle>;
@group(0) @binding(1) var<storage, read> materials: array<Material>;
@group(0) @binding(2) var<storage, read> bvh_nodes: array<BvhNode>;
@group(0) @binding(3) var<storage, read> lights: array<LightEntry>;

const MATERIAL_TWO_SIDED: u32 = 1u;

// A point on a surface: position, front-face geometric normal and material.
struct Surface {
    pos: vec3f,
    normal: vec3f,
    albedo: vec3f,
    emission: vec3f,
    flags: u32,
    tri: u32,
}

fn triangle_normal(t: Triangle) -> vec3f {
    return normalize(cross(t.v1 - t.v0, t.v2 - t.v0));
}

// The surface at barycentrics (b1, b2) of triangle `tri`.
fn surface_at(tri: u32, b1: f32, b2: f32) -> Surface {
    let t = triangles[tri];
    let m = materials[t.material];
    var s: Surface;
    s.pos = t.v0 * (1.0 - b1 - b2) + t.v1 * b1 + t.v2 * b2;
    s.normal = triangle_normal(t);
    s.albedo = m.albedo;
    s.emission = m.emission;
    s.flags = m.flags;
    s.tri = tri;
    return s;
}

// Whether the scene has emitters: an empty light table is stored as one zero entry (a
// binding cannot be empty), whose pmf is 0.
fn has_lights() -> bool {
    return lights[0].pmf > 0.0;
}

// The light entry whose cdf interval holds u: the first with u < cdf (LightTable::pick).
fn light_pick(u: f32) -> u32 {
    var lo = 0u;
    var hi = arrayLength(&lights) - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if lights[mid].cdf <= u {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

struct LightSample {
    pos: vec3f,
    normal: vec3f,
    radiance: vec3f,
    // Probability density of `pos` per unit area: pmf(triangle) / area(triangle).
    pdf_area: f32,
    tri: u32,
}

// A point on the emitters: a triangle chosen by power, then uniformly on it.
fn sample_light(u0: f32, u1: f32, u2: f32) -> LightSample {
    let e = lights[light_pick(u0)];
    let t = triangles[e.triangle];
    let b = uniform_triangle_bary(u1, u2);
    var s: LightSample;
    s.pos = t.v0 * b.x + t.v1 * b.y + t.v2 * b.z;
    s.normal = triangle_normal(t);
    s.radiance = materials[t.material].emission;
    s.pdf_area = e.pmf / e.area;
    s.tri = e.triangle;
    return s;
}
