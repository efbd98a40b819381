// A point on a surface: position, front-face geometric normal, shading normal (interpolated,
// in the geometric normal's hemisphere; the geometric normal where the triangle has none)
// and material: its base colour `albedo`, emission, flags and scattering model (bsdf.wgsl;
// metallic and roughness with their texture applied).
struct Surface {
    pos: vec3f,
    normal: vec3f,
    shading: vec3f,
    albedo: vec3f,
    emission: vec3f,
    flags: u32,
    tri: u32,
    metallic: f32,
    roughness: f32,
    specular: f32,
    ior: f32,
    transmission: f32,
    specular_color: vec3f,
    clearcoat: f32,
    clearcoat_roughness: f32,
}

// Vertex `vi` of the scene drawn as one non-indexed triangle list (vertex pulling in the
// raster passes): its position, its barycentrics (b1, b2) and its triangle.
struct TriangleVertex {
    pos: vec3f,
    bary: vec2f,
    tri: u32,
    // The triangle has no area (TRIANGLE_ZERO_AREA).
    zero_area: bool,
}

fn triangle_vertex(vi: u32) -> TriangleVertex {
    let tri = vi / 3u;
    let corner = vi % 3u;
    let t = triangles[tri];
    let zero_area = (t.flags & TRIANGLE_ZERO_AREA) != 0u;
    if corner == 1u {
        return TriangleVertex(t.v1, vec2f(1.0, 0.0), tri, zero_area);
    } else if corner == 2u {
        return TriangleVertex(t.v2, vec2f(0.0, 1.0), tri, zero_area);
    }
    return TriangleVertex(t.v0, vec2f(0.0, 0.0), tri, zero_area);
}

// A raster pass's vertex (`vs_main` of the G-buffer and of the gather's ray views): clip
// position, and the barycentrics and triangle its fragments read; with texture coordinates
// where the pass asks for them (the G-buffer's level of detail: their screen-space
// derivatives), else zero.
struct RasterVertex {
    @builtin(position) clip: vec4f,
    @location(0) bary: vec2f,
    @location(1) @interpolate(flat) tri: u32,
    @location(2) uv: vec2f,
}

// A triangle of zero area (collinear corners: published meshes carry them; flagged when the
// scene is uploaded) has no normal and no surface, and no ray hits it; but projected, rounding
// can leave its corners a sliver apart, and a rasterizer then covers pixels with it at
// barycentrics far outside [0, 1] (the shared classroom's ceiling: NaN pixels). Its corners
// are put outside the clip volume, so no raster pass draws it.
fn raster_vertex(vi: u32, view_proj: mat4x4f, with_uv: bool) -> RasterVertex {
    let v = triangle_vertex(vi);
    var uv = vec2f(0.0);
    if with_uv {
        uv = surface_uv(v.tri, v.bary.x, v.bary.y);
    }
    if v.zero_area {
        return RasterVertex(vec4f(2.0, 2.0, 2.0, 1.0), v.bary, v.tri, uv);
    }
    return RasterVertex(view_proj * vec4f(v.pos, 1.0), v.bary, v.tri, uv);
}

fn triangle_normal(t: Triangle) -> vec3f {
    return normalize(cross(t.v1 - t.v0, t.v2 - t.v0));
}

// Texture coordinates at barycentrics (b1, b2) of triangle `tri` (PreparedScene::uv_at).
fn surface_uv(tri: u32, b1: f32, b2: f32) -> vec2f {
    let i = scene_offset(DATA_UVS) + 6u * min(tri, scene_offset(DATA_UV_TRIANGLES) - 1u);
    let uv = array<vec2f, 3>(vec2f(scene_f32(i), scene_f32(i + 1u)), vec2f(scene_f32(i + 2u), scene_f32(i + 3u)),
        vec2f(scene_f32(i + 4u), scene_f32(i + 5u)));
    return uv[0] * (1.0 - b1 - b2) + uv[1] * b1 + uv[2] * b2;
}

// The texture of slot s at the triangle's texture coordinates uv and level of detail lod.
fn slot_sample(s: TextureSlot, uv: vec2f, lod: f32) -> vec4f {
    let st = vec2f(dot(s.u, vec3f(uv, 1.0)), dot(s.v, vec3f(uv, 1.0)));
    return atlas_sample(s.texture, st, lod);
}

// The shading normal at barycentrics (b1, b2) of triangle `tri` of geometric normal n and
// material mi: its corners' normals interpolated and normalised, turned into n's hemisphere (n
// where the triangle has none or they cancel), perturbed by the material's normal map
// (PreparedScene::shading_normal_at); `textured`: the material reads some texture.
fn shading_normal(tri: u32, b1: f32, b2: f32, n: vec3f, mi: u32, textured: bool, uv: vec2f) -> vec3f {
    let w = vec3f(1.0 - b1 - b2, b1, b2);
    var ns = n;
    if SCENE_NORMALS {
        let i = scene_offset(DATA_NORMALS) + 9u * min(tri, scene_offset(DATA_NORMAL_TRIANGLES) - 1u);
        var v = vec3f(0.0);
        for (var k = 0u; k < 3u; k++) {
            v += w[k] * scene_vec3(i + 3u * k);
        }
        let len = length(v);
        if len >= 1e-6 {
            v /= len;
            ns = select(-v, v, dot(v, n) >= 0.0);
        }
    }
    if !textured {
        return ns;
    }
    let map = materials[mi].maps.normal_map;
    if map.texture == NO_TEXTURE {
        return ns;
    }
    let j = scene_offset(DATA_TANGENTS) + 12u * min(tri, scene_offset(DATA_TANGENT_TRIANGLES) - 1u);
    var t = vec4f(0.0);
    for (var k = 0u; k < 3u; k++) {
        t += w[k] * scene_vec4(j + 4u * k);
    }
    return perturb_normal(n, ns, t, slot_sample(map, uv, 0.0).rgb, materials[mi].maps.normal_scale);
}

// surface::perturb_normal: ns perturbed by the normal-map texel c in the frame (t', b, ns).
fn perturb_normal(n: vec3f, ns: vec3f, t: vec4f, c: vec3f, scale: f32) -> vec3f {
    var tangent = t.xyz - ns * dot(ns, t.xyz);
    if dot(tangent, tangent) < 1e-12 {
        return ns;
    }
    tangent = normalize(tangent);
    let bitangent = cross(ns, tangent) * select(1.0, -1.0, t.w < 0.0);
    let m = (2.0 * c - 1.0) * vec3f(scale, scale, 1.0);
    let v = tangent * m.x + bitangent * m.y + ns * m.z;
    if dot(v, v) < 1e-12 {
        return ns;
    }
    return bend_towards(normalize(v), n);
}

// The opacity α of material mi (its factor `opacity`) at texture coordinates uv
// (PreparedScene::opacity_at).
fn surface_opacity(mi: u32, opacity: f32, uv: vec2f, lod: f32) -> f32 {
    let map = materials[mi].maps.opacity_map;
    if map.texture == NO_TEXTURE {
        return opacity;
    }
    return opacity * slot_sample(map, uv, lod).a;
}

// Whether a ray (or a fragment) meeting triangle `tri` at barycentrics (b1, b2) passes through
// it (PreparedScene::passes_through): through a cut-out where α < its cutoff; through a
// stochastic surface where a uniform hashed from the point and alpha_seed is ≥ α.
fn passes_through(tri: u32, b1: f32, b2: f32, lod: f32) -> bool {
    if !SCENE_HOLES {
        return false;
    }
    let mi = triangles[tri].material;
    let m = materials[mi].material;
    if (m.flags & (MATERIAL_ALPHA_MASK | MATERIAL_ALPHA_BLEND)) == 0u {
        return false;
    }
    let a = surface_opacity(mi, m.opacity, surface_uv(tri, b1, b2), lod);
    if (m.flags & MATERIAL_ALPHA_MASK) != 0u {
        return a < materials[mi].maps.alpha_cutoff;
    }
    let u = unit_f32(pcg_hash(pcg_hash(pcg_hash(tri ^ alpha_seed) ^ bitcast<u32>(b1)) ^ bitcast<u32>(b2)));
    return u >= a;
}

// The radiance emitter triangle `tri` sends from barycentrics (b1, b2) as a light sample or a
// photon sees it (PreparedScene::emitter_radiance): none from a cut-out's hole, α × its
// emission on a stochastic surface.
fn emitter_radiance(tri: u32, b1: f32, b2: f32) -> vec3f {
    let mi = triangles[tri].material;
    let m = materials[mi].material;
    if !(SCENE_TEXTURES || SCENE_HOLES) || (m.flags & (MATERIAL_TEXTURED | MATERIAL_ALPHA_MASK | MATERIAL_ALPHA_BLEND)) == 0u {
        return m.emission;
    }
    let uv = surface_uv(tri, b1, b2);
    let le = surface_emission(mi, m.emission, uv);
    if (m.flags & MATERIAL_ALPHA_MASK) != 0u {
        return select(le, vec3f(0.0), surface_opacity(mi, m.opacity, uv, 0.0) < materials[mi].maps.alpha_cutoff);
    }
    if (m.flags & MATERIAL_ALPHA_BLEND) != 0u {
        return le * surface_opacity(mi, m.opacity, uv, 0.0);
    }
    return le;
}

// The emitted radiance of material mi (its factor `emission`) at texture coordinates uv
// (PreparedScene::emission_at).
fn surface_emission(mi: u32, emission: vec3f, uv: vec2f) -> vec3f {
    let map = materials[mi].maps.emission_map;
    if map.texture == NO_TEXTURE {
        return emission;
    }
    return emission * slot_sample(map, uv, 0.0).rgb;
}

// A shading normal ns seen from direction v (unit, towards the viewer): unchanged where it
// faces v, else bent in the plane of ns and v until it is just past perpendicular to v (the
// surface seen from behind its shading normal would be black or lit from below).
fn bend_towards(ns: vec3f, v: vec3f) -> vec3f {
    let c = dot(ns, v);
    if c >= 0.0 {
        return ns;
    }
    return normalize(ns + (1e-3 - c) * v);
}

// The level of detail of material mi's albedo texture where the triangle's texture coordinates
// change by dx and dy across a pixel: those changes placed by the texture's transform.
fn albedo_lod(mi: u32, dx: vec2f, dy: vec2f) -> f32 {
    let s = materials[mi].maps.albedo_map;
    let a = mat2x2f(vec2f(s.u.x, s.v.x), vec2f(s.u.y, s.v.y));
    return texture_lod(s.texture, a * dx, a * dy);
}

// Barycentrics (b1, b2) of the point p of triangle t's plane.
fn plane_barycentrics(t: Triangle, p: vec3f) -> vec2f {
    let e1 = t.v1 - t.v0;
    let e2 = t.v2 - t.v0;
    let d = p - t.v0;
    let d11 = dot(e1, e1);
    let d12 = dot(e1, e2);
    let d22 = dot(e2, e2);
    let det = d11 * d22 - d12 * d12;
    if det == 0.0 {
        return vec2f(0.0);
    }
    let p1 = dot(d, e1);
    let p2 = dot(d, e2);
    return vec2f(d22 * p1 - d12 * p2, d11 * p2 - d12 * p1) / det;
}

// The surface at barycentrics (b1, b2) of triangle `tri`, its albedo texture (if any) read at
// level of detail `lod`, the others at level 0 (PreparedScene::albedo_at, emission_at,
// shading_normal_at).
fn surface_at(tri: u32, b1: f32, b2: f32, lod: f32) -> Surface {
    let t = triangles[tri];
    let mi = t.material;
    let m = materials[mi].material;
    let textured = SCENE_TEXTURES && (m.flags & MATERIAL_TEXTURED) != 0u;
    var uv = vec2f(0.0);
    if textured {
        uv = surface_uv(tri, b1, b2);
    }
    var s: Surface;
    s.pos = t.v0 * (1.0 - b1 - b2) + t.v1 * b1 + t.v2 * b2;
    s.normal = triangle_normal(t);
    s.shading = shading_normal(tri, b1, b2, s.normal, mi, textured, uv);
    s.albedo = m.albedo;
    s.emission = m.emission;
    if textured {
        let maps = materials[mi].maps;
        if maps.albedo_map.texture != NO_TEXTURE {
            s.albedo *= slot_sample(maps.albedo_map, uv, lod).rgb;
        }
        if maps.emission_map.texture != NO_TEXTURE {
            s.emission *= slot_sample(maps.emission_map, uv, 0.0).rgb;
        }
    }
    s.flags = m.flags;
    s.tri = tri;
    s.metallic = m.metallic;
    s.roughness = m.roughness;
    s.specular = m.specular;
    s.specular_color = m.specular_color;
    s.ior = m.ior;
    s.transmission = m.transmission;
    s.clearcoat = m.clearcoat;
    s.clearcoat_roughness = m.clearcoat_roughness;
    if textured {
        let mr_map = materials[mi].maps.metal_rough_map;
        if mr_map.texture != NO_TEXTURE {
            let mr = slot_sample(mr_map, uv, 0.0);
            s.roughness *= mr.g;
            s.metallic *= mr.b;
        }
        let t_map = materials[mi].maps.transmission_map;
        if t_map.texture != NO_TEXTURE {
            s.transmission = clamp(s.transmission * slot_sample(t_map, uv, 0.0).r, 0.0, 1.0);
        }
        let s_map = materials[mi].maps.specular_map;
        if s_map.texture != NO_TEXTURE {
            s.specular = clamp(s.specular * slot_sample(s_map, uv, 0.0).a, 0.0, 1.0);
        }
        let c_map = materials[mi].maps.specular_color_map;
        if c_map.texture != NO_TEXTURE {
            s.specular_color *= slot_sample(c_map, uv, 0.0).rgb;
        }
        let k_map = materials[mi].maps.clearcoat_map;
        if k_map.texture != NO_TEXTURE {
            s.clearcoat *= slot_sample(k_map, uv, 0.0).r;
        }
        let kr_map = materials[mi].maps.clearcoat_roughness_map;
        if kr_map.texture != NO_TEXTURE {
            s.clearcoat_roughness *= slot_sample(kr_map, uv, 0.0).g;
        }
    }
    return s;
}

// The model at a surface point (PreparedScene::bsdf_at).
fn surface_bsdf(s: Surface) -> Bsdf {
    let r = clamp(s.roughness, 0.0, 1.0);
    let rc = clamp(s.clearcoat_roughness, 0.0, 1.0);
    return Bsdf(s.albedo, clamp(s.metallic, 0.0, 1.0), r * r, s.specular, s.specular_color, s.ior, s.transmission,
        (s.flags & MATERIAL_THIN) != 0u, (s.flags & MATERIAL_SINGLE_SCATTERING) == 0u, clamp(s.clearcoat, 0.0, 1.0),
        rc * rc);
}

// Whether the surface scatters by Dirac deltas alone (a perfect mirror or smooth glass, no
// diffuse or glossy lobe): eye and gather rays continue through it (specular.wgsl,
// gather_radiance).
fn surface_purely_specular(s: Surface) -> bool {
    let b = surface_bsdf(s);
    let opaque = (1.0 - b.metallic) * (1.0 - b.transmission);
    return bsdf_is_smooth(b) && opaque <= 0.0 && !rough_coat(b);
}

// Whether eye and gather rays go on through the surface rather than stop at it: a purely
// specular one, or glass without a diffuse base, rough or smooth (its light comes from
// behind it, which a stop on its surface cannot gather; Material::passes_rays).
fn surface_passes_rays(s: Surface) -> bool {
    let opaque = (1.0 - clamp(s.metallic, 0.0, 1.0)) * (1.0 - s.transmission);
    return SCENE_PASSES_RAYS && opaque <= 0.0 && (surface_purely_specular(s) || s.transmission > 0.0);
}

// For a ray arriving along d at a surface that scatters by a delta lobe and by others too (a
// smooth specular layer over a diffuse base, a smooth partly metallic surface, a smooth clear
// coat over a rough model): the probability
// pd with which bsdf_sample picks a delta lobe there, and for a uniform u0 the first uniform of
// a scatter_at that picks the delta lobe u0 falls in where u0 < pd (−1 where u0 ≥ pd: a
// non-delta lobe). pd = 0 elsewhere (no delta lobe, or one that passes rays anyway).
struct DeltaChoice {
    pd: f32,
    u: f32,
}

fn surface_delta_choice(s: Surface, d: vec3f, u0: f32) -> DeltaChoice {
    var c = DeltaChoice(0.0, -1.0);
    if !SCENE_PASSES_RAYS || surface_is_lambertian(s) || surface_passes_rays(s) {
        return c;
    }
    let a = arrival(s, d);
    let coat_delta = a.b.clearcoat > 0.0 && !rough_coat(a.b);
    let base_delta = bsdf_is_smooth(a.b);
    if !coat_delta && !base_delta {
        return c;
    }
    let lp = lobe_probabilities(a.b, abs(a.wo.z));
    // The lobes in bsdf_sample's order: the coat (delta when smooth), then metal, layer (delta
    // when smooth), diffuse, glass.
    let pc = select(0.0, lp.coat, coat_delta);
    let p = select(vec4f(0.0), lp.under * vec4f(1.0, 1.0, 0.0, 1.0), base_delta);
    c.pd = pc + p.x + p.y + p.w;
    if u0 < pc {
        c.u = u0;
        return c;
    }
    var rest = u0 - pc;
    var start = lp.coat;
    for (var k = 0u; k < 4u; k++) {
        if rest < p[k] {
            c.u = start + rest;
            return c;
        }
        rest -= p[k];
        start += lp.under[k];
    }
    return c;
}

// Whether the surface scatters as a plain Lambertian one, f = ρ/π.
fn surface_is_lambertian(s: Surface) -> bool {
    return !SCENE_BSDF || (s.flags & MATERIAL_LAMBERTIAN) != 0u;
}

// The albedo with which a point reflects the photon map's irradiance towards wo (a unit
// vector away from the surface): ρ, or the diffuse equivalent of a glossy or specular surface
// seen from wo (bsdf_diffuse_equivalent, an approximation).
fn surface_rho(s: Surface, wo: vec3f) -> vec3f {
    if surface_is_lambertian(s) {
        return s.albedo;
    }
    return bsdf_diffuse_equivalent(surface_bsdf(s), dot(s.shading, wo));
}

// A ray arriving along d at surface s, scattered by its BSDF from three uniforms u (radiance
// transport): the new direction, its weight f·|cos|/pdf, the origin just off the surface on
// the new direction's side (eps away), and whether it was a delta lobe. `ok` is false where nothing
// scatters or the geometric and the shading side of the direction disagree. Solid glass hit
// from behind is left: its relative index inverts. (The eye's and the gather's specular
// chains; the path tracer and the photon tracer do the same with their own bookkeeping.)
struct Scatter {
    dir: vec3f,
    weight: vec3f,
    origin: vec3f,
    delta: bool,
    ok: bool,
    // The density the direction was drawn with and its |cos θ| to the shading normal.
    pdf: f32,
    cos: f32,
}

// A ray arriving along d at surface s, in the terms its BSDF is sampled in: the model with the
// relative index seen from the ray's side (solid glass hit from behind: inverted), the shading
// frame on that side (bent towards the ray), the direction back along the ray in it, and the
// geometric normal on that side.
struct Arrival {
    b: Bsdf,
    frame: mat3x3f,
    wo: vec3f,
    n: vec3f,
}

fn arrival(s: Surface, d: vec3f) -> Arrival {
    let front = dot(s.normal, d) < 0.0;
    let sf = shading_frame(bend_towards(select(-s.shading, s.shading, front), -d));
    var b = surface_bsdf(s);
    if !front && !b.thin {
        b.ior = 1.0 / b.ior;
    }
    return Arrival(b, sf, to_local(sf, -d), select(-s.normal, s.normal, front));
}

fn scatter_at(s: Surface, d: vec3f, u: vec3f, eps: f32) -> Scatter {
    return scatter_from(s.pos, arrival(s, d), u, eps);
}

// scatter_at for the arrival a at the surface point pos.
fn scatter_from(pos: vec3f, a: Arrival, u: vec3f, eps: f32) -> Scatter {
    var r: Scatter;
    r.ok = false;
    let n = a.n;
    let bs = bsdf_sample(a.b, a.wo, u, TRANSPORT_RADIANCE);
    if !bs.ok {
        return r;
    }
    r.dir = normalize(a.frame * bs.wi);
    let below = dot(n, r.dir) < 0.0;
    if (bs.wi.z < 0.0) != below || dot(n, r.dir) == 0.0 {
        return r;
    }
    r.weight = bs.weight;
    r.origin = pos + select(n, -n, below) * eps;
    r.delta = bs.delta;
    r.pdf = bs.pdf;
    r.cos = abs(bs.wi.z);
    r.ok = true;
    return r;
}

