//! Surface detail of real models (issue 16): cut-outs and stochastic opacity, normal maps,
//! texture transforms and per-texel emission, against Mitsuba 3 and hand-computed images.

mod common;

use glam::{Vec2, Vec3, Vec4};
use rastergi::passes::film::Show;
use rastergi::scene::{
    AlphaMode, Camera, Light, Material, Scene, Texture, TextureRef, UvTransform, load_gltf, load_obj,
};
use rastergi::settings::RenderSettings;
use serde_json::json;

const SIZE: u32 = 96;

fn settings() -> RenderSettings {
    RenderSettings { width: SIZE, height: SIZE, photons: 1 << 12, grid_resolution: 8, ..Default::default() }
}

/// A camera straight above the origin looking down, −z up in the image.
fn top_camera(height: f32, fov: f32) -> Camera {
    Camera { eye: Vec3::new(0.0, height, 0.0), target: Vec3::ZERO, up: Vec3::NEG_Z, fov_y_deg: fov }
}

/// The camera ray through the point (x, y) of the image (pixels from the top-left corner).
fn ray(c: &Camera, x: f32, y: f32) -> Vec3 {
    let (right, up, forward) = c.frame();
    let t = (0.5 * c.fov_y_deg.to_radians()).tan();
    let ndc = Vec2::new(2.0 * x / SIZE as f32 - 1.0, 1.0 - 2.0 * y / SIZE as f32);
    (forward + right * ndc.x * t + up * ndc.y * t).normalize()
}

/// A quad in the plane y = `y`, x and z in [−h, h], facing +y, with texture coordinates
/// u = (x + h)/2h, v = (z + h)/2h (v down the image, along +z).
fn add_quad(s: &mut Scene, y: f32, h: f32, material: u32) -> Vec<[Vec3; 3]> {
    let p = [Vec3::new(-h, y, -h), Vec3::new(-h, y, h), Vec3::new(h, y, h), Vec3::new(h, y, -h)];
    let uv = |v: Vec3| Vec2::new((v.x + h) / (2.0 * h), (v.z + h) / (2.0 * h));
    let tris = [[p[0], p[1], p[2]], [p[0], p[2], p[3]]];
    for t in tris {
        s.add_textured_triangle(t, t.map(uv), material);
    }
    tris.to_vec()
}

fn texture(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> Texture {
    let texels = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| f(x, y)).collect();
    Texture { name: "t".into(), width: w, height: h, texels, linear: false }
}

#[test]
fn an_alpha_card_with_holes_matches_mitsuba() {
    // References: tests/data/README.md (alpha card): an 8×8 map_d mask (holes where 0) and a
    // d 0.5 veil under a point light, Mitsuba's mask BSDF, volpath, 4096 spp, seeds 31 and 32.
    let mut scene = load_obj(&common::data("obj/alpha_card.obj")).unwrap();
    scene.camera =
        Camera { eye: Vec3::new(0.0, 2.6, 2.4), target: Vec3::new(0.0, 0.35, 0.0), up: Vec3::Y, fov_y_deg: 45.0 };
    scene.lights.push(Light::Point { position: Vec3::new(0.15, 2.2, 0.1), intensity: Vec3::splat(6.0) });
    let modes: Vec<AlphaMode> = scene.materials.iter().map(|m| m.alpha_mode).collect();
    assert_eq!(modes.iter().filter(|&&m| m == AlphaMode::Blend).count(), 2, "{modes:?}");
    common::matches_mitsuba(
        "alpha card",
        &scene,
        rastergi::gather::HitLight::Map,
        256,
        "alpha_card_path_128",
        false,
        Show::Full,
        None,
    );
}

/// The card of the cut-out test: y = 0.5, x and z in [−0.5, 0.5], a 4 × 4 checker of holes
/// (texel (i, j) solid where i + j is even), over a floor at y = 0.
const CARD_Y: f32 = 0.5;

fn card_is_solid_at(p: Vec3) -> bool {
    if p.x.abs() >= 0.5 || p.z.abs() >= 0.5 {
        return false;
    }
    // Bilinear α of a checker crosses the cutoff ½ exactly on the texel edges.
    let (i, j) = (((p.x + 0.5) * 4.0).floor() as i32, ((p.z + 0.5) * 4.0).floor() as i32);
    (i + j) % 2 == 0
}

#[test]
fn a_cut_out_shows_and_casts_its_holes_exactly() {
    // Seen from above under a sun straight down (no penumbra): a point of the card's solid
    // texels has ρ_card·E/π, a floor point ρ_floor·E/π unless the card above it is solid (then
    // nothing: direct light only). Computed here per pixel from the geometry; pixels whose
    // footprint straddles an edge are left out.
    let camera = top_camera(3.0, 30.0);
    let mut s = Scene::new(camera);
    let floor = s.add_material(Material::diffuse("floor", Vec3::splat(0.3)));
    let mask = s.add_texture(texture(4, 4, |x, y| {
        let a = if (x + y) % 2 == 0 { 255 } else { 0 };
        [200, 200, 200, a]
    }));
    let card = s.add_material(Material {
        opacity_texture: Some(TextureRef::new(mask)),
        alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
        two_sided: true,
        ..Material::diffuse("card", Vec3::splat(0.8))
    });
    add_quad(&mut s, 0.0, 3.0, floor);
    add_quad(&mut s, CARD_Y, 0.5, card);
    s.lights.push(Light::Distant { direction: Vec3::NEG_Y, irradiance: Vec3::ONE, angular_radius: 0.0 });
    let image = common::render(&common::gpu(), &s, settings(), 16, Show::Direct);

    let pi = std::f32::consts::PI;
    let expected_at = |d: Vec3| {
        let at_card = camera.eye + d * ((camera.eye.y - CARD_Y) / -d.y);
        if card_is_solid_at(at_card) {
            return 0.8 / pi;
        }
        let at_floor = camera.eye + d * (camera.eye.y / -d.y);
        if card_is_solid_at(Vec3::new(at_floor.x, CARD_Y, at_floor.z)) { 0.0 } else { 0.3 / pi }
    };
    let (mut clean, mut wrong) = (0, Vec::new());
    for y in 0..SIZE {
        for x in 0..SIZE {
            let samples: Vec<f32> = (0..25)
                .map(|k| expected_at(ray(&camera, x as f32 + (k % 5) as f32 / 4.0, y as f32 + (k / 5) as f32 / 4.0)))
                .collect();
            if samples.iter().any(|&v| v != samples[0]) {
                continue;
            }
            clean += 1;
            let got = image.pixels[(y * SIZE + x) as usize][1];
            if (got - samples[0]).abs() > 2e-3 * (0.8 / pi) {
                wrong.push((x, y, got, samples[0]));
            }
        }
    }
    println!("cut-out: {clean} clean pixels, {} wrong: {:?}", wrong.len(), &wrong[..wrong.len().min(8)]);
    assert!(clean > (SIZE * SIZE / 2) as usize, "{clean}");
    assert!(wrong.is_empty(), "{} of {clean} pixels differ: {:?}", wrong.len(), &wrong[..wrong.len().min(8)]);
}

/// The image of a floor with a one-texel normal map under a sun travelling along `direction`,
/// seen from above (Show::Direct, the centre pixels' mean).
fn normal_mapped_floor(texel: [u8; 3], scale: f32, direction: Vec3) -> f32 {
    let mut s = Scene::new(top_camera(2.0, 20.0));
    let map = s.add_texture(Texture { linear: true, ..texture(1, 1, |_, _| [texel[0], texel[1], texel[2], 255]) });
    let floor = s.add_material(Material {
        normal_texture: Some(TextureRef::new(map)),
        normal_scale: scale,
        ..Material::diffuse("floor", Vec3::splat(0.5))
    });
    let tris = add_quad(&mut s, 0.0, 2.0, floor);
    let uvs: Vec<[Vec2; 3]> = s.uvs.clone();
    let tangents = rastergi::scene::mikktspace(&tris, &uvs, None);
    s.tangents = tangents;
    s.lights.push(Light::Distant { direction: direction.normalize(), irradiance: Vec3::ONE, angular_radius: 0.0 });
    let image = common::render(&common::gpu(), &s, settings(), 4, Show::Direct);
    let centre: Vec<f32> = (40..56)
        .flat_map(|y| (40..56).map(move |x| (x, y)))
        .map(|(x, y)| image.pixels[(y * SIZE + x) as usize][0])
        .collect();
    centre.iter().sum::<f32>() / centre.len() as f32
}

#[test]
fn a_normal_map_turns_the_shading_normal_as_its_texels_say() {
    // The floor's tangent frame: u along +x, v (down the image) along +z, so glTF's bitangent
    // (+Y of the map, up the image) is −z and the normal +y. A texel c gives the tangent-space
    // normal m = (2c/255 − 1)·(s, s, 1), the world normal normalize(m.x x̂ − m.y ẑ + m.z ŷ), and
    // the radiance ρ/π · E · max(0, n · −d) under a sun travelling along d.
    let a = 30f32.to_radians();
    let texel = [128u8, (127.5 + 127.5 * a.sin()).round() as u8, (127.5 + 127.5 * a.cos()).round() as u8];
    let expected = |scale: f32, d: Vec3| {
        let m = (Vec3::from_array(texel.map(|c| c as f32 / 255.0)) * 2.0 - Vec3::ONE) * Vec3::new(scale, scale, 1.0);
        let n = (Vec3::X * m.x - Vec3::Z * m.y + Vec3::Y * m.z).normalize();
        0.5 / std::f32::consts::PI * n.dot(-d.normalize()).max(0.0)
    };
    for (scale, d) in
        [(1.0, Vec3::new(0.0, -1.0, 1.0)), (1.0, Vec3::new(0.0, -1.0, -1.0)), (0.5, Vec3::new(0.0, -1.0, 1.0))]
    {
        let got = normal_mapped_floor(texel, scale, d);
        let want = expected(scale, d);
        println!("normal map, scale {scale}, sun along {d}: {got} against {want}");
        assert!((got - want).abs() < 3e-3 * want, "scale {scale}, sun along {d}: {got} against {want}");
    }
    // The map tilts the normal towards −z: a sun from −z (travelling +z) gives more than a flat
    // floor's cos 45°, one from +z less.
    let flat = 0.5 / std::f32::consts::PI * std::f32::consts::FRAC_1_SQRT_2;
    assert!(
        expected(1.0, Vec3::new(0.0, -1.0, 1.0)) > 1.2 * flat && expected(1.0, Vec3::new(0.0, -1.0, -1.0)) < 0.8 * flat
    );
}

#[test]
fn an_emissive_texture_emits_per_texel_in_the_eye_and_as_a_light() {
    // A ceiling quad emitting Le × texel (left half of the image 1, right half 0.25, in linear
    // terms: sRGB codes 255 and 137) above a white floor; the eye sees the texels, and the
    // floor's irradiance from them is the closed-form integral over each half, by quadrature.
    let mut s = Scene::new(Camera {
        eye: Vec3::new(0.0, 0.5, 2.5),
        target: Vec3::new(0.0, 0.5, 0.0),
        up: Vec3::Y,
        fov_y_deg: 50.0,
    });
    let code = 137u8;
    let quarter = rastergi::textures::srgb_to_linear(code);
    assert!((quarter - 0.25).abs() < 0.005, "{quarter}");
    let tex = s.add_texture(texture(64, 1, |x, _| if x < 32 { [255, 255, 255, 255] } else { [code, code, code, 255] }));
    let floor = s.add_material(Material::diffuse("floor", Vec3::ONE));
    let light = s.add_material(Material {
        emission: Vec3::splat(2.0),
        emission_texture: Some(TextureRef::new(tex)),
        ..Material::diffuse("light", Vec3::ZERO)
    });
    add_quad(&mut s, 0.0, 3.0, floor);
    // The emitter y = 1, x, z in [−0.5, 0.5], facing down, u along +x.
    let (a, b, c, d) =
        (Vec3::new(-0.5, 1.0, -0.5), Vec3::new(0.5, 1.0, -0.5), Vec3::new(0.5, 1.0, 0.5), Vec3::new(-0.5, 1.0, 0.5));
    let uv = |p: Vec3| Vec2::new(p.x + 0.5, p.z + 0.5);
    for t in [[a, b, c], [a, c, d]] {
        s.add_textured_triangle(t, t.map(uv), light);
    }
    let le = |x: f32| 2.0 * if x < 0.0 { 1.0 } else { quarter };
    let image =
        common::render(&common::gpu(), &s, RenderSettings { width: 64, height: 64, ..settings() }, 64, Show::Direct);
    // Irradiance at floor point p: Σ Le(x) cos θ cos θ' / r² dA over a 200 × 200 grid.
    let irradiance = |p: Vec3| {
        let n = 200;
        let mut e = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let x = Vec3::new(-0.5 + (i as f32 + 0.5) / n as f32, 1.0, -0.5 + (j as f32 + 0.5) / n as f32);
                let v = x - p;
                let r2 = v.length_squared();
                let cos = v.y / r2.sqrt();
                e += (le(x.x) * cos * cos / r2) as f64 / (n * n) as f64;
            }
        }
        e as f32
    };
    let cam = s.camera;
    let (right, up, forward) = cam.frame();
    let t = (0.5 * cam.fov_y_deg.to_radians()).tan();
    let hit = |x: u32, y: u32, plane: f32| {
        let ndc = Vec2::new(2.0 * (x as f32 + 0.5) / 64.0 - 1.0, 1.0 - 2.0 * (y as f32 + 0.5) / 64.0);
        let dir = (forward + right * ndc.x * t + up * ndc.y * t).normalize();
        cam.eye + dir * ((plane - cam.eye.y) / dir.y)
    };
    // The floor's 4 × 4 blocks below the light: their mean against the quadrature's.
    let mut worst = 0.0f32;
    for (bx, by) in [(16u32, 56u32), (30, 56), (44, 56), (30, 48)] {
        let block = || (by..by + 4).flat_map(|y| (bx..bx + 4).map(move |x| (x, y)));
        let got: f32 = block().map(|(x, y)| image.pixels[(y * 64 + x) as usize][0]).sum::<f32>() / 16.0;
        let want: f32 = block().map(|(x, y)| irradiance(hit(x, y, 0.0))).sum::<f32>() / 16.0 / std::f32::consts::PI;
        println!("floor block ({bx}, {by}): {got} against {want}");
        worst = worst.max((got / want - 1.0).abs());
    }
    // 64 iterations of one light sample: about 1 % of noise in a block's mean.
    assert!(worst < 0.03, "{worst}");
    // The eye sees the emitter's front from below: Le × its texel.
    let mut seen = 0;
    for y in 0..32 {
        for x in 0..64 {
            let p = hit(x, y, 1.0);
            if p.x.abs() < 0.45 && p.x.abs() > 0.05 && p.z.abs() < 0.45 {
                let got = image.pixels[(y * 64 + x) as usize][0];
                assert!((got - le(p.x)).abs() < 2e-3 * le(p.x), "pixel ({x}, {y}) on the light at {p}: {got}");
                seen += 1;
            }
        }
    }
    assert!(seen > 20, "{seen}");
}

#[test]
fn gltf_alpha_normal_maps_emissive_textures_and_texture_transforms_are_read() {
    let dir = tempfile::tempdir().unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([255, 128, 0, 100])).save(dir.path().join("base.png")).unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([128, 128, 255, 255])).save(dir.path().join("normal.png")).unwrap();
    let uvs: [[f32; 2]; 3] = [[0.0, 1.0], [1.0, 1.0], [0.0, 0.0]];
    let transform = json!({ "KHR_texture_transform": { "offset": [0, 1], "rotation": std::f32::consts::FRAC_PI_2, "scale": [0.5, 0.5] } });
    let doc = json!({
        "asset": { "version": "2.0" },
        "extensionsUsed": ["KHR_texture_transform"],
        "images": [{ "uri": "base.png" }, { "uri": "normal.png" }],
        "textures": [{ "source": 0 }, { "source": 1 }],
        "materials": [
            {
                "pbrMetallicRoughness": {
                    "baseColorFactor": [1, 1, 1, 0.8],
                    "baseColorTexture": { "index": 0, "extensions": transform }
                },
                "normalTexture": { "index": 1, "scale": 0.7, "extensions": transform },
                "emissiveTexture": { "index": 0 },
                "emissiveFactor": [1, 1, 1],
                "alphaMode": "MASK",
                "alphaCutoff": 0.3
            },
            { "alphaMode": "BLEND", "pbrMetallicRoughness": { "baseColorFactor": [1, 1, 1, 0.25] } }
        ],
        "meshes": [{ "primitives": [
            { "attributes": { "POSITION": 0, "TEXCOORD_0": 1 }, "material": 0 },
            { "attributes": { "POSITION": 0 }, "material": 1 }
        ] }],
        "nodes": [{ "mesh": 0 }],
        "scenes": [{ "nodes": [0] }],
        "scene": 0
    });
    let doc = common::with_unit_triangle(doc, &[("VEC2", uvs.as_flattened())]);
    let path = dir.path().join("m.gltf");
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    let scene = load_gltf(&path).unwrap();
    let m = &scene.materials[scene.material_ids[0] as usize];
    assert_eq!(m.alpha_mode, AlphaMode::Mask { cutoff: 0.3 });
    assert_eq!(m.opacity, 0.8);
    // α from the base colour texture, placed as it is.
    let base = m.albedo_texture.unwrap();
    assert_eq!(m.opacity_texture, Some(TextureRef { texture: base, transform: m.albedo_transform }));
    assert!(!scene.textures[base].linear);
    // The extension's worked example: offset (0, 1), rotation 90°, scale ½ reads "the lower
    // left quadrant of the image, rotated clockwise 90°": (0, 0) ↦ (0, 1), (1, 0) ↦ (0, ½),
    // (0, 1) ↦ (½, 1).
    for (uv, want) in [((0.0, 0.0), (0.0, 1.0)), ((1.0, 0.0), (0.0, 0.5)), ((0.0, 1.0), (0.5, 1.0))] {
        let got = m.albedo_transform.apply(Vec2::new(uv.0, uv.1));
        assert!((got - Vec2::new(want.0, want.1)).length() < 1e-6, "{uv:?} ↦ {got}");
    }
    let normal = m.normal_texture.unwrap();
    assert!(scene.textures[normal.texture].linear, "normal maps are linear data");
    assert_eq!(normal.transform, m.albedo_transform);
    assert_eq!(m.normal_scale, 0.7);
    let emissive = m.emission_texture.unwrap();
    assert_eq!((emissive.texture, emissive.transform), (base, UvTransform::IDENTITY));
    assert_eq!(m.emission, Vec3::ONE);
    // MikkTSpace tangents for the normal-mapped triangle (no TANGENT in the file): along +u,
    // which runs along +x here, handedness +1 (v runs down the image along −y).
    let t = scene.material_ids.iter().position(|&id| id == scene.material_ids[0]).unwrap();
    for tangent in scene.tangents[t] {
        assert!((tangent - Vec4::new(1.0, 0.0, 0.0, 1.0)).length() < 1e-5, "{tangent}");
    }
    let blend = scene.materials.iter().find(|m| m.alpha_mode == AlphaMode::Blend).unwrap();
    assert_eq!((blend.opacity, blend.opacity_texture), (0.25, None));
}

#[test]
fn obj_opacity_emissive_maps_and_texture_options_are_read() {
    let dir = tempfile::tempdir().unwrap();
    // A grey mask (no alpha channel): its first channel is the opacity.
    image::GrayImage::from_pixel(2, 2, image::Luma([64])).save(dir.path().join("mask.png")).unwrap();
    image::RgbaImage::from_pixel(2, 2, image::Rgba([10, 20, 30, 40])).save(dir.path().join("rgba.png")).unwrap();
    std::fs::write(
        dir.path().join("m.mtl"),
        "newmtl masked\nKd 0.5 0.5 0.5\nmap_d -s 2 2 1 mask.png\n\
         newmtl veil\nd 0.25\n\
         newmtl tr\nTr 0.75\n\
         newmtl cut\nmap_Kd -o 0.25 0.5 rgba.png\nmap_d rgba.png\n\
         newmtl glow\nKe 3 3 3\nmap_Ke -bm 0.5 rgba.png\n",
    )
    .unwrap();
    let mut obj = String::from("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n");
    for name in ["masked", "veil", "tr", "cut", "glow"] {
        obj += &format!("usemtl {name}\nf 1/1 2/2 3/3\n");
    }
    std::fs::write(dir.path().join("m.obj"), obj).unwrap();
    let scene = load_obj(&dir.path().join("m.obj")).unwrap();
    let by_name = |n: &str| scene.materials.iter().find(|m| m.name == n).unwrap();
    let masked = by_name("masked");
    assert_eq!((masked.alpha_mode, masked.opacity), (AlphaMode::Blend, 1.0));
    let mask = masked.opacity_texture.unwrap();
    assert!(scene.textures[mask.texture].texels.iter().all(|t| t[3] == 64), "the grey value is the opacity");
    // -s 2 2: OBJ (u, v) ↦ (2u, 2v); in the scene's v-down coordinates (u, v) ↦ (2u, 2v − 1).
    assert_eq!(mask.transform, UvTransform([[2.0, 0.0, 0.0], [0.0, 2.0, -1.0]]));
    assert_eq!((by_name("veil").alpha_mode, by_name("veil").opacity), (AlphaMode::Blend, 0.25));
    assert_eq!((by_name("tr").alpha_mode, by_name("tr").opacity), (AlphaMode::Blend, 0.25));
    let cut = by_name("cut");
    // The same image as colour and as opacity: its alpha channel is read where it has one.
    let (albedo, opacity) = (cut.albedo_texture.unwrap(), cut.opacity_texture.unwrap());
    assert_eq!(albedo, opacity.texture);
    assert!(scene.textures[albedo].texels.iter().all(|t| *t == [10, 20, 30, 40]));
    assert_eq!(cut.albedo_transform, UvTransform([[1.0, 0.0, 0.25], [0.0, 1.0, -0.5]]));
    let glow = by_name("glow");
    assert_eq!((glow.emission, glow.emission_texture.map(|t| t.texture)), (Vec3::splat(3.0), Some(albedo)));
    assert_eq!(glow.alpha_mode, AlphaMode::Opaque);
}

#[test]
fn gltf_tangents_follow_the_transform_and_flip_handedness_when_mirrored() {
    // A triangle in z = 0 (front +z) with TANGENT (1, 0, 0, +1): bitangent w · n × t = +y.
    let dir = tempfile::tempdir().unwrap();
    image::RgbaImage::from_pixel(1, 1, image::Rgba([128, 128, 255, 255])).save(dir.path().join("n.png")).unwrap();
    let uvs: [[f32; 2]; 3] = [[0.0, 1.0], [1.0, 1.0], [0.0, 0.0]];
    let tangents: [[f32; 4]; 3] = [[1.0, 0.0, 0.0, 1.0]; 3];
    let file = |scale: [f32; 3]| {
        let doc = json!({
            "asset": { "version": "2.0" },
            "images": [{ "uri": "n.png" }],
            "textures": [{ "source": 0 }],
            "materials": [{ "normalTexture": { "index": 0 } }],
            "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0, "TEXCOORD_0": 1, "TANGENT": 2 }, "material": 0 }] }],
            "nodes": [{ "mesh": 0, "scale": scale }],
            "scenes": [{ "nodes": [0] }],
            "scene": 0
        });
        let doc = common::with_unit_triangle(doc, &[("VEC2", uvs.as_flattened()), ("VEC4", tangents.as_flattened())]);
        let path = dir.path().join("t.gltf");
        std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
        load_gltf(&path).unwrap()
    };
    let s = file([1.0; 3]);
    assert_eq!(s.tangents[0], [Vec4::new(1.0, 0.0, 0.0, 1.0); 3]);
    // Mirrored in x: the tangent mirrors with the surface, and w flips so that the bitangent
    // w · n × t is still the mirrored bitangent M(+y) = +y (n stays +z: the corners swap).
    let s = file([-1.0, 1.0, 1.0]);
    let t = &s.triangles[0];
    let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
    assert!((n - Vec3::Z).length() < 1e-6, "{n}");
    for tangent in s.tangents[0] {
        assert_eq!(tangent, Vec4::new(-1.0, 0.0, 0.0, -1.0));
        assert!((n.cross(tangent.truncate()) * tangent.w - Vec3::Y).length() < 1e-6);
    }
}
