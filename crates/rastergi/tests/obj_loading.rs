//! `load_obj` against hand-written OBJ/MTL fixtures in `tests/data/obj/`: the triangles,
//! materials and emitted power it must produce, and the files it must refuse with an error
//! (never a panic) that names the file.

use std::f32::consts::PI;
use std::path::PathBuf;

use glam::Vec3;
use rastergi::scene::{Material, Scene, load_obj};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/obj").join(name)
}

fn v(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// Whether `a` and `b` are the same triangle with the same winding: equal up to a cyclic
/// rotation of the corners (a reversed order would flip the front face).
fn same_winding(a: &[Vec3; 3], b: &[Vec3; 3]) -> bool {
    (0..3).any(|r| (0..3).all(|k| a[k] == b[(k + r) % 3]))
}

/// The triangles of the scene that use a material with this name.
fn triangles_of(scene: &Scene, material: &str) -> Vec<([Vec3; 3], Material)> {
    (0..scene.triangles.len())
        .filter(|&i| scene.material_of(i).name == material)
        .map(|i| (scene.triangles[i], scene.material_of(i).clone()))
        .collect()
}

/// The triangles of the scene whose material is none of the named ones.
fn triangles_not_of(scene: &Scene, materials: &[&str]) -> Vec<([Vec3; 3], Material)> {
    (0..scene.triangles.len())
        .filter(|&i| !materials.contains(&scene.material_of(i).name.as_str()))
        .map(|i| (scene.triangles[i], scene.material_of(i).clone()))
        .collect()
}

// The geometry of scene.obj, written out by hand from the file.
const FLOOR: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 0.0, -3.0], [0.0, 0.0, -3.0]];
const LIGHT: [[f32; 3]; 3] = [[0.0, 2.0, 0.0], [0.0, 2.0, -1.0], [1.0, 2.0, 0.0]];
const WALL: [[f32; 3]; 3] = [[0.0, 0.0, -3.0], [2.0, 0.0, -3.0], [0.0, 1.5, -3.0]];

#[test]
fn scene_has_the_files_triangles_with_their_winding() {
    let scene = load_obj(&fixture("scene.obj")).unwrap();
    assert_eq!(scene.triangles.len(), 4, "a quad and two triangles make four triangles");
    assert_eq!(scene.material_ids.len(), scene.triangles.len());

    let light = triangles_of(&scene, "light");
    assert_eq!(light.len(), 1);
    assert!(same_winding(&light[0].0, &LIGHT.map(Vec3::from)), "light triangle {:?}", light[0].0);

    let wall = triangles_not_of(&scene, &["light", "grey"]);
    assert_eq!(wall.len(), 1, "the face before any usemtl");
    assert!(same_winding(&wall[0].0, &WALL.map(Vec3::from)), "wall triangle {:?}", wall[0].0);

    // The quad a b c d splits along either diagonal; both halves keep its winding.
    let floor: Vec<[Vec3; 3]> = triangles_of(&scene, "grey").into_iter().map(|(t, _)| t).collect();
    assert_eq!(floor.len(), 2, "the quad becomes two triangles");
    let [a, b, c, d] = FLOOR.map(Vec3::from);
    let splits = [[[a, b, c], [a, c, d]], [[a, b, d], [b, c, d]]];
    let matches = |split: &[[Vec3; 3]; 2]| {
        (same_winding(&floor[0], &split[0]) && same_winding(&floor[1], &split[1]))
            || (same_winding(&floor[0], &split[1]) && same_winding(&floor[1], &split[0]))
    };
    assert!(splits.iter().any(matches), "floor triangles {floor:?} are not a split of the quad {:?}", [a, b, c, d]);
}

#[test]
fn front_faces_follow_the_counter_clockwise_order_of_the_file() {
    let scene = load_obj(&fixture("scene.obj")).unwrap();
    let expected = [("grey", v(0.0, 1.0, 0.0)), ("light", v(0.0, -1.0, 0.0))];
    for (name, normal) in expected {
        for (t, _) in triangles_of(&scene, name) {
            assert_eq!(rastergi::scene::triangle_normal(&t), normal, "{name} triangle {t:?}");
        }
    }
    for (t, _) in triangles_not_of(&scene, &["light", "grey"]) {
        assert_eq!(rastergi::scene::triangle_normal(&t), v(0.0, 0.0, 1.0), "wall triangle {t:?}");
    }
}

#[test]
fn each_group_gets_its_own_material_and_faces_without_one_get_grey() {
    let scene = load_obj(&fixture("scene.obj")).unwrap();
    for (t, m) in triangles_of(&scene, "grey") {
        assert_eq!(m.albedo, v(0.2, 0.4, 0.6), "Kd of 'grey' for {t:?}");
        assert_eq!(m.emission, Vec3::ZERO);
        assert!(m.two_sided, "OBJ materials reflect on both sides");
    }
    for (_, m) in triangles_of(&scene, "light") {
        assert_eq!(m.albedo, v(0.8, 0.7, 0.6), "Kd of 'light'");
        assert_eq!(m.emission, v(10.0, 5.0, 2.0), "Ke of 'light'");
        assert!(m.two_sided);
        assert!(m.is_emitter());
    }
    for (_, m) in triangles_not_of(&scene, &["light", "grey"]) {
        assert_eq!(m.albedo, Vec3::splat(0.5), "a face without a material is 0.5 grey");
        assert_eq!(m.emission, Vec3::ZERO);
        assert!(m.two_sided);
    }
}

#[test]
fn emitted_power_is_pi_times_radiance_times_area_of_the_light() {
    let scene = load_obj(&fixture("scene.obj")).unwrap();
    // The light is a right triangle with legs 1 and 1: area 1/2; Le = (10, 5, 2).
    let expected = PI * v(10.0, 5.0, 2.0) * 0.5;
    let power = scene.emitted_power();
    assert!((power - expected).abs().max_element() < 1e-5, "Φ = {power}, expected {expected}");
    assert_eq!(scene.emissive_triangles().len(), 1);
}

#[test]
fn framing_camera_sees_every_corner_of_the_bounds() {
    let scene = load_obj(&fixture("scene.obj")).unwrap();
    let bounds = scene.bounds();
    assert_eq!((bounds.min, bounds.max), (v(0.0, 0.0, -3.0), v(2.0, 2.0, 0.0)));
    let camera = scene.camera;
    camera.validate().unwrap();
    let (right, up, forward) = camera.frame();
    let tan_half = (0.5 * camera.fov_y_deg.to_radians()).tan();
    for i in 0..8 {
        let corner = v(
            if i & 1 == 0 { bounds.min.x } else { bounds.max.x },
            if i & 2 == 0 { bounds.min.y } else { bounds.max.y },
            if i & 4 == 0 { bounds.min.z } else { bounds.max.z },
        );
        let d = corner - camera.eye;
        let depth = d.dot(forward);
        assert!(depth > 0.0, "corner {corner} is behind the camera");
        // A square image: the horizontal half-angle equals the vertical one.
        assert!(d.dot(up).abs() <= tan_half * depth, "corner {corner} is above or below the view");
        assert!(d.dot(right).abs() <= tan_half * depth, "corner {corner} is left or right of the view");
    }
}

#[test]
fn single_number_colours_mean_grey_as_in_the_mtl_format() {
    let scene = load_obj(&fixture("short_colours.obj")).unwrap();
    let m = scene.material_of(0);
    assert_eq!(m.albedo, Vec3::splat(0.25), "Kd 0.25 is Kd 0.25 0.25 0.25");
    assert_eq!(m.emission, Vec3::splat(3.0), "Ke 3 is Ke 3 3 3");
}

#[test]
fn texture_and_normal_indices_are_not_needed_and_not_checked() {
    let scene = load_obj(&fixture("bad_normal_index.obj")).unwrap();
    assert_eq!(scene.triangles, vec![[v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)]]);
}

/// Loads a file that must be refused and returns the error's message, after checking that it
/// is one line naming the file.
fn refused(path: PathBuf) -> String {
    let message = match load_obj(&path) {
        Ok(scene) => panic!("{} was accepted: {} triangles", path.display(), scene.triangles.len()),
        Err(e) => e.to_string(),
    };
    assert!(message.contains(&path.display().to_string()), "the error does not name the file: {message}");
    assert!(!message.contains('\n'), "the error is not one line: {message}");
    message
}

/// Files that must be refused, each with the words its message must contain besides the
/// file's name (none where the wording is free).
#[test]
fn missing_unreadable_and_malformed_files_are_refused() {
    let cases: [(&str, &[&str]); 11] = [
        ("no-such-scene.obj", &["no such file"]),
        // The fixtures' directory.
        ("", &["not a file"]),
        // A malformed vertex line; text that is not OBJ.
        ("malformed.obj", &[]),
        ("not_obj.obj", &[]),
        ("empty.obj", &["no faces"]),
        // A face with a vertex that does not exist.
        ("bad_index.obj", &[]),
        ("missing_mtllib.obj", &["no-such-library.mtl"]),
        // A missing second material library is not hidden by the first.
        ("second_mtllib_missing.obj", &["also-missing.mtl"]),
        // A NaN coordinate; a negative albedo.
        ("nan.obj", &["non-finite"]),
        ("negative_kd.obj", &["negative"]),
        // A colour without numbers.
        ("empty_ke.obj", &["empty_ke.mtl", "Ke"]),
    ];
    for (file, words) in cases {
        let message = refused(fixture(file));
        for word in words {
            assert!(message.contains(word), "{file}: {message}");
        }
    }
}

/// The faces of the box `min`–`max` as one-sided quads facing `inward` or outward, but the
/// face whose outward normal is `open` (if any).
fn box_faces(s: &mut Scene, min: Vec3, max: Vec3, inward: bool, open: Option<Vec3>, material: u32) {
    let c = (min + max) / 2.0;
    let h = (max - min) / 2.0;
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut n = Vec3::ZERO;
            n[axis] = sign;
            if open == Some(n) {
                continue;
            }
            let (u, w) = (Vec3::AXES[(axis + 1) % 3], Vec3::AXES[(axis + 2) % 3]);
            let (u, w) = (u * h[(axis + 1) % 3], w * h[(axis + 2) % 3]);
            let centre = c + n * h[axis];
            let mut q = [centre - u - w, centre + u - w, centre + u + w, centre - u + w];
            // Facing n (outward) or −n.
            let facing = (q[1] - q[0]).cross(q[2] - q[0]).normalize();
            if (facing.dot(n) > 0.0) == inward {
                q.reverse();
            }
            s.add_quad(q, material);
        }
    }
}

fn placeholder_camera() -> rastergi::scene::Camera {
    rastergi::scene::Camera { eye: v(0.0, 0.0, 10.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 }
}

/// Of a 16 × 16 grid of the camera's view rays, the share that meet a front face (cast here on
/// the CPU, independently of the camera's choice).
fn front_face_share(scene: &Scene, camera: &rastergi::scene::Camera) -> f32 {
    let bvh = rastergi::bvh::Bvh::build(&scene.triangles);
    let triangles = bvh.permute(&scene.triangles);
    let (right, up, forward) = camera.frame();
    let tan = (0.5 * camera.fov_y_deg.to_radians()).tan();
    let mut front = 0;
    for j in 0..16 {
        for i in 0..16 {
            let x = (2.0 * (i as f32 + 0.5) / 16.0 - 1.0) * tan;
            let y = (1.0 - 2.0 * (j as f32 + 0.5) / 16.0) * tan;
            let d = (forward + right * x + up * y).normalize();
            if let Some(h) = bvh.intersect(&triangles, camera.eye, d, 0.0, f32::INFINITY, u32::MAX, |_| true) {
                front += (rastergi::scene::triangle_normal(&triangles[h.triangle as usize]).dot(d) < 0.0) as usize;
            }
        }
    }
    front as f32 / 256.0
}

/// Issue 45: an interior exported without a camera (a hall of one-sided walls facing in, a
/// pillar, a light under the ceiling) is seen from inside: framed from outside, the camera
/// would see the walls' backs, which render black.
#[test]
fn an_interior_without_a_camera_is_seen_from_inside() {
    let mut s = Scene::new(placeholder_camera());
    let wall = s.add_material(Material::diffuse("wall", Vec3::splat(0.7)));
    let lamp = s.add_material(Material { emission: Vec3::splat(5.0), ..Material::diffuse("lamp", Vec3::ZERO) });
    box_faces(&mut s, v(0.0, 0.0, 0.0), v(8.0, 3.0, 5.0), true, None, wall);
    box_faces(&mut s, v(2.0, 0.0, 2.0), v(2.4, 3.0, 2.4), false, None, wall);
    s.add_quad([v(3.0, 2.9, 2.0), v(3.0, 2.9, 3.0), v(4.0, 2.9, 3.0), v(4.0, 2.9, 2.0)], lamp);
    let framing = Scene::framing_camera(&s.bounds());
    let camera = s.default_camera();
    camera.validate().unwrap();
    let (outside, inside) = (front_face_share(&s, &framing), front_face_share(&s, &camera));
    println!("front faces seen: framed from outside {outside:.2}, default camera {inside:.2} ({camera:?})");
    let b = s.bounds();
    assert!(b.min.cmplt(camera.eye).all() && camera.eye.cmplt(b.max).all(), "{camera:?}");
    assert!(outside < 0.1, "the framing camera sees the walls' front faces ({outside})");
    assert!(inside > 0.95, "the default camera sees back faces ({inside})");
}

/// Objects, and a box open towards +z like the Cornell box, keep the framing camera: it sees
/// them whole.
#[test]
fn objects_and_open_boxes_without_a_camera_are_framed_from_outside() {
    let mut open = Scene::new(placeholder_camera());
    let m = open.add_material(Material::diffuse("white", Vec3::splat(0.7)));
    box_faces(&mut open, v(-1.0, -1.0, -1.0), v(1.0, 1.0, 1.0), true, Some(Vec3::Z), m);
    let mut object = Scene::new(open.camera);
    let m = object.add_material(Material::diffuse("white", Vec3::splat(0.7)));
    box_faces(&mut object, v(-1.0, 0.0, -1.0), v(1.0, 0.5, 1.0), false, None, m);
    box_faces(&mut object, v(-0.2, 0.5, -0.2), v(0.2, 2.0, 0.2), false, None, m);
    for (name, s) in [("open box", &open), ("object", &object)] {
        assert_eq!(s.default_camera(), Scene::framing_camera(&s.bounds()), "{name}");
    }
    // And the loader uses the default camera.
    let scene = load_obj(&fixture("scene.obj")).unwrap();
    assert_eq!(scene.camera, scene.default_camera());
}
