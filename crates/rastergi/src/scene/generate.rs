//! Procedural scenes, and the built-in scene names every front end accepts:
//!
//! - `cornell`: Mitsuba 3's Cornell box ([`super::cornell_box`]);
//! - `atrium`: a colonnaded hall lit through three windows and a skylight ([`atrium`]), the
//!   scene beyond the Cornell box (`scenes/atrium.obj` is the same scene as OBJ + MTL);
//! - `spheres:N`: about N triangles of tessellated spheres on a floor under an area light
//!   ([`spheres`]), for measuring scale (`spheres:1000000` is a million triangles);
//! - `rooms`, `rooms:closed`: two rooms split by a wall 2 cm thick, lit in one, seen from the
//!   other, through a doorway or with none ([`rooms`]): the thin-wall case of the photon map;
//! - `sunroom`: a room lit by the sun through two windows, standing on a ground plane 200 m
//!   across ([`sunroom`]): the exported-interior case (add a sky with `--env`).
//!
//! Every surface here is built from quads oriented by an explicit outward normal, so the
//! front faces (and the emitters' emitting sides) never depend on the order corners are
//! listed in.

use glam::Vec3;

use super::{Camera, Material, Scene, cornell_box};
use crate::error::{Error, Result};

/// The built-in scene names, as shown in help texts and error messages.
pub const BUILTIN_NAMES: &str =
    "cornell, atrium, spheres:N (about N triangles), rooms, rooms:closed, glossy-room, sunroom";

/// Largest triangle count `spheres:N` accepts: 2²⁸ triangles are 16 GiB of corners, far
/// past what any GPU binds as one buffer, so larger requests are typos.
pub const MAX_GENERATED_TRIANGLES: usize = 1 << 28;

/// The built-in scene called `name`, `Ok(None)` if `name` is not a built-in name (it may be
/// a file), or an error if it is one with a bad parameter (`spheres:abc`).
pub fn builtin(name: &str) -> Result<Option<Scene>> {
    let bad = |message: String| Error::InvalidScene(format!("built-in scene '{name}': {message}"));
    match name.split_once(':') {
        None if name == "cornell" => Ok(Some(cornell_box())),
        None if name == "atrium" => Ok(Some(atrium())),
        None if name == "rooms" => Ok(Some(rooms(true))),
        None if name == "glossy-room" => Ok(Some(glossy_room())),
        None if name == "sunroom" => Ok(Some(sunroom())),
        Some(("rooms", "closed")) => Ok(Some(rooms(false))),
        Some(("spheres", count)) => {
            let n: usize = count
                .trim()
                .replace('_', "")
                .parse()
                .map_err(|_| bad(format!("'{count}' is not a triangle count; write e.g. spheres:1000000")))?;
            if !(1..=MAX_GENERATED_TRIANGLES).contains(&n) {
                return Err(bad(format!("the triangle count must lie in 1..={MAX_GENERATED_TRIANGLES}")));
            }
            Ok(Some(spheres(n)))
        }
        _ => Ok(None),
    }
}

/// Adds the planar quad `q` as two triangles whose front faces look along `outward`.
fn add_quad_facing(scene: &mut Scene, mut q: [Vec3; 4], outward: Vec3, material: u32) {
    if (q[1] - q[0]).cross(q[2] - q[0]).dot(outward) < 0.0 {
        q.reverse();
    }
    scene.add_quad(q, material);
}

/// An axis-aligned box, its faces looking outwards.
pub fn add_box(scene: &mut Scene, lo: Vec3, hi: Vec3, material: u32) {
    add_box_facing(scene, lo, hi, material, 1.0);
}

/// An axis-aligned box whose faces look outwards (`facing` 1) or inwards (−1: a room's shell).
fn add_box_facing(scene: &mut Scene, lo: Vec3, hi: Vec3, material: u32, facing: f32) {
    for axis in 0..3 {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        for (side, at) in [(-1.0f32, lo[axis]), (1.0, hi[axis])] {
            let corner = |a: f32, b: f32| {
                let mut p = Vec3::ZERO;
                p[axis] = at;
                p[u] = a;
                p[v] = b;
                p
            };
            let q = [corner(lo[u], lo[v]), corner(hi[u], lo[v]), corner(hi[u], hi[v]), corner(lo[u], hi[v])];
            add_quad_facing(scene, q, Vec3::AXES[axis] * side * facing, material);
        }
    }
}

/// Half the thickness of the wall between the two [`rooms`].
pub const ROOMS_HALF_WALL: f32 = 0.01;

/// Two rooms side by side along x, each 2 × 2.5 × 3 m (x ∈ [−2, 0] lit, x ∈ [0, 2] dark),
/// split by a wall 2 cm thick at x = 0 — with a doorway 0.8 × 2 m in it (`doorway`) or
/// none. A 0.8 × 0.8 m light on the lit room's ceiling; the camera stands in the dark room's
/// far corner looking at the wall. Closed, the dark room receives no light at all: every
/// pixel's radiance is exactly zero, so any light seen there is the photon map's leak.
pub fn rooms(doorway: bool) -> Scene {
    let camera =
        Camera { eye: Vec3::new(1.9, 1.4, 1.4), target: Vec3::new(-0.2, 0.7, -0.4), up: Vec3::Y, fov_y_deg: 65.0 };
    let mut s = Scene::new(camera);
    let white = s.add_material(Material::diffuse("white", Vec3::splat(0.75)));
    let light =
        s.add_material(Material { emission: Vec3::splat(8.0), ..Material::diffuse("light", Vec3::splat(0.75)) });
    let (lo, hi) = (Vec3::new(-2.0, 0.0, -1.5), Vec3::new(2.0, 2.5, 1.5));
    add_box_facing(&mut s, lo, hi, white, -1.0); // the shell, facing in
    // The wall, as boxes around the doorway (z ∈ [−0.4, 0.4], y < 2).
    let w = ROOMS_HALF_WALL;
    if doorway {
        add_box(&mut s, Vec3::new(-w, 0.0, lo.z), Vec3::new(w, hi.y, -0.4), white);
        add_box(&mut s, Vec3::new(-w, 0.0, 0.4), Vec3::new(w, hi.y, hi.z), white);
        add_box(&mut s, Vec3::new(-w, 2.0, -0.4), Vec3::new(w, hi.y, 0.4), white);
    } else {
        add_box(&mut s, Vec3::new(-w, 0.0, lo.z), Vec3::new(w, hi.y, hi.z), white);
    }
    let y = hi.y - 0.02;
    add_quad_facing(
        &mut s,
        [Vec3::new(-1.4, y, -0.4), Vec3::new(-0.6, y, -0.4), Vec3::new(-0.6, y, 0.4), Vec3::new(-1.4, y, 0.4)],
        -Vec3::Y,
        light,
    );
    s
}

/// The sun of [`sunroom`]: azimuth 200°, elevation 35° (`--sun 200,35,…`), 3 W/m², a delta
/// direction (`--sun-size 0`).
pub const SUNROOM_SUN: (f32, f32, f32) = (200.0, 35.0, 3.0);

/// A room 6 × 3 × 5 m inside (x ∈ [0, 6], z ∈ [0, 5], its floor at y = 0.05) with walls and a
/// roof 20 cm thick, standing on a ground plane 200 m across (y = 0) as exported interiors
/// stand on their terrain. Two windows 1.5 × 1.3 m in the south wall (z = 0) let in the sun
/// ([`SUNROOM_SUN`], one of the scene's lights: a patch of sunlight on the floor) and, with
/// `--env`, the sky; the walls are light grey (0.7), the floor wood-coloured, an albedo-1
/// white sofa and a grey-blue table stand in the room. The camera stands in the north-west
/// corner looking at the windows and the sunlit floor. 84 triangles.
pub fn sunroom() -> Scene {
    let camera =
        Camera { eye: Vec3::new(0.6, 1.7, 4.6), target: Vec3::new(3.8, 0.7, 0.8), up: Vec3::Y, fov_y_deg: 70.0 };
    let mut s = Scene::new(camera);
    let ground = s.add_material(Material::diffuse("ground", Vec3::new(0.20, 0.24, 0.16)));
    let wall = s.add_material(Material::diffuse("wall", Vec3::splat(0.7)));
    let floor = s.add_material(Material::diffuse("floor", Vec3::new(0.45, 0.32, 0.2)));
    let sofa = s.add_material(Material::diffuse("sofa", Vec3::ONE));
    let table = s.add_material(Material::diffuse("table", Vec3::new(0.3, 0.4, 0.5)));
    let r = 100.0;
    add_quad_facing(
        &mut s,
        [Vec3::new(-r, 0.0, -r), Vec3::new(r, 0.0, -r), Vec3::new(r, 0.0, r), Vec3::new(-r, 0.0, r)],
        Vec3::Y,
        ground,
    );
    let (t, h, f) = (0.2, 3.0, 0.05);
    add_box(&mut s, Vec3::new(-t, 0.0, -t), Vec3::new(6.0 + t, f, 5.0 + t), floor);
    add_box(&mut s, Vec3::new(-t, h, -t), Vec3::new(6.0 + t, h + t, 5.0 + t), wall); // roof
    add_box(&mut s, Vec3::new(-t, f, 5.0), Vec3::new(6.0 + t, h, 5.0 + t), wall); // north
    add_box(&mut s, Vec3::new(-t, f, 0.0), Vec3::new(0.0, h, 5.0), wall); // west
    add_box(&mut s, Vec3::new(6.0, f, 0.0), Vec3::new(6.0 + t, h, 5.0), wall); // east
    // The south wall around windows x ∈ [1, 2.5] and [3.5, 5], y ∈ [0.9, 2.2].
    let (sill, head) = (0.9, 2.2);
    add_box(&mut s, Vec3::new(-t, f, -t), Vec3::new(6.0 + t, sill, 0.0), wall);
    add_box(&mut s, Vec3::new(-t, head, -t), Vec3::new(6.0 + t, h, 0.0), wall);
    for (x0, x1) in [(-t, 1.0), (2.5, 3.5), (5.0, 6.0 + t)] {
        add_box(&mut s, Vec3::new(x0, sill, -t), Vec3::new(x1, head, 0.0), wall);
    }
    // Furniture: a sofa (seat and back) against the east wall, a table in the sunbeam.
    add_box(&mut s, Vec3::new(5.0, f, 1.5), Vec3::new(5.9, 0.5, 3.5), sofa);
    add_box(&mut s, Vec3::new(5.6, 0.5, 1.5), Vec3::new(5.9, 0.95, 3.5), sofa);
    add_box(&mut s, Vec3::new(2.0, 0.7, 2.6), Vec3::new(3.2, 0.76, 3.4), table);
    let sun = Vec3::new(SUNROOM_SUN.0.to_radians().sin(), 0.0, SUNROOM_SUN.0.to_radians().cos())
        * SUNROOM_SUN.1.to_radians().cos()
        + Vec3::Y * SUNROOM_SUN.1.to_radians().sin();
    s.lights.push(super::Light::Distant {
        direction: -sun.normalize(),
        irradiance: Vec3::splat(SUNROOM_SUN.2),
        angular_radius: 0.0,
    });
    s
}

/// A room 4 × 2.5 × 3 m with a rough metal floor (roughness 0.3) and a table with a polished
/// top (a dielectric layer of roughness 0.1 over dark wood) on metal legs, lit by a 0.8 × 0.8 m
/// light on the ceiling; white walls, one red and one green. Light the floor and the table
/// reflect glossily reaches the walls and the ceiling: the scene of issue 31's gather test.
pub fn glossy_room() -> Scene {
    let camera =
        Camera { eye: Vec3::new(1.7, 1.5, 1.3), target: Vec3::new(-0.3, 0.6, -0.5), up: Vec3::Y, fov_y_deg: 60.0 };
    let mut s = Scene::new(camera);
    let white = s.add_material(Material::diffuse("white", Vec3::splat(0.75)));
    let red = s.add_material(Material::diffuse("red", Vec3::new(0.63, 0.07, 0.05)));
    let green = s.add_material(Material::diffuse("green", Vec3::new(0.12, 0.45, 0.09)));
    let floor = s.add_material(Material {
        metallic: 1.0,
        roughness: 0.3,
        ..Material::diffuse("rough metal floor", Vec3::new(0.91, 0.78, 0.55))
    });
    let top = s.add_material(Material {
        specular: 1.0,
        roughness: 0.1,
        ..Material::diffuse("polished table top", Vec3::new(0.30, 0.14, 0.06))
    });
    let legs = s.add_material(Material {
        metallic: 1.0,
        roughness: 0.4,
        ..Material::diffuse("table legs", Vec3::new(0.9, 0.9, 0.9))
    });
    let light =
        s.add_material(Material { emission: Vec3::splat(10.0), ..Material::diffuse("light", Vec3::splat(0.75)) });
    let (lo, hi) = (Vec3::new(-2.0, 0.0, -1.5), Vec3::new(2.0, 2.5, 1.5));
    let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    // The shell, facing in: floor, ceiling, back (z = lo), front (z = hi), left red, right green.
    for (corners, facing, material) in [
        ([c(lo.x, 0.0, lo.z), c(hi.x, 0.0, lo.z), c(hi.x, 0.0, hi.z), c(lo.x, 0.0, hi.z)], Vec3::Y, floor),
        ([c(lo.x, hi.y, lo.z), c(hi.x, hi.y, lo.z), c(hi.x, hi.y, hi.z), c(lo.x, hi.y, hi.z)], -Vec3::Y, white),
        ([c(lo.x, 0.0, lo.z), c(hi.x, 0.0, lo.z), c(hi.x, hi.y, lo.z), c(lo.x, hi.y, lo.z)], Vec3::Z, white),
        ([c(lo.x, 0.0, hi.z), c(hi.x, 0.0, hi.z), c(hi.x, hi.y, hi.z), c(lo.x, hi.y, hi.z)], -Vec3::Z, white),
        ([c(lo.x, 0.0, lo.z), c(lo.x, 0.0, hi.z), c(lo.x, hi.y, hi.z), c(lo.x, hi.y, lo.z)], Vec3::X, red),
        ([c(hi.x, 0.0, lo.z), c(hi.x, 0.0, hi.z), c(hi.x, hi.y, hi.z), c(hi.x, hi.y, lo.z)], -Vec3::X, green),
    ] {
        add_quad_facing(&mut s, corners, facing, material);
    }
    // The table: a top 1.4 × 0.05 × 0.8 m at 0.75 m on four legs 5 cm square.
    let (t_lo, t_hi) = (c(-1.2, 0.70, -0.9), c(0.2, 0.75, -0.1));
    add_box(&mut s, t_lo, t_hi, top);
    for (x, z) in [
        (t_lo.x + 0.05, t_lo.z + 0.05),
        (t_hi.x - 0.10, t_lo.z + 0.05),
        (t_lo.x + 0.05, t_hi.z - 0.10),
        (t_hi.x - 0.10, t_hi.z - 0.10),
    ] {
        add_box(&mut s, c(x, 0.0, z), c(x + 0.05, t_lo.y, z + 0.05), legs);
    }
    let y = hi.y - 0.01;
    add_quad_facing(&mut s, [c(-0.9, y, -0.4), c(-0.1, y, -0.4), c(-0.1, y, 0.4), c(-0.9, y, 0.4)], -Vec3::Y, light);
    s
}

/// A UV sphere: `segments` around the axis, `segments / 2` rings from pole to pole;
/// `2·segments·(rings − 1)` triangles, front faces outwards, smooth (radial shading normals).
pub fn add_sphere(scene: &mut Scene, centre: Vec3, radius: f32, segments: u32, material: u32) {
    let segments = segments.max(3);
    let rings = (segments / 2).max(2);
    let point = |ring: u32, seg: u32| {
        let theta = std::f32::consts::PI * ring as f32 / rings as f32;
        let phi = std::f32::consts::TAU * (seg % segments) as f32 / segments as f32;
        centre + radius * Vec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
    };
    for ring in 0..rings {
        for seg in 0..segments {
            let (a, b) = (point(ring, seg), point(ring, seg + 1));
            let (c, d) = (point(ring + 1, seg + 1), point(ring + 1, seg));
            // Seen from outside, a → b runs along φ and b → c down towards the −y pole, so
            // (a, b, d) and (b, c, d) wind counter-clockwise; at the poles one is degenerate.
            // Smooth: each corner's shading normal is the sphere's radial direction.
            let normal = |p: Vec3| (p - centre) / radius;
            if ring > 0 {
                scene.add_triangle([a, b, d], material);
                scene.set_last_normals([a, b, d].map(normal));
            }
            if ring + 1 < rings {
                scene.add_triangle([b, c, d], material);
                scene.set_last_normals([b, c, d].map(normal));
            }
        }
    }
}

/// Triangles of [`add_sphere`] with `segments` segments.
fn sphere_triangles(segments: u32) -> usize {
    let rings = (segments.max(3) / 2).max(2);
    2 * segments.max(3) as usize * (rings as usize - 1)
}

/// An open cylinder (no caps) along +y from `base`, `sides` faces, front faces outwards,
/// smooth (radial shading normals).
fn add_cylinder(scene: &mut Scene, base: Vec3, radius: f32, height: f32, sides: u32, material: u32) {
    for k in 0..sides {
        let angle = |k: u32| std::f32::consts::TAU * k as f32 / sides as f32;
        let (a0, a1) = (angle(k), angle(k + 1));
        let p = |a: f32, y: f32| base + Vec3::new(radius * a.cos(), y, radius * a.sin());
        let radial = |a: f32| Vec3::new(a.cos(), 0.0, a.sin());
        // Seen from outside with +y up, angle a1 lies to the left of a0 (the angle turns from
        // +x towards +z): (a0 top, a1 top, a1 bottom, a0 bottom) winds counter-clockwise.
        let q = [p(a0, height), p(a1, height), p(a1, 0.0), p(a0, 0.0)];
        let n = [radial(a0), radial(a1), radial(a1), radial(a0)];
        let [i, j, l] =
            if (q[1] - q[0]).cross(q[2] - q[0]).dot(radial(0.5 * (a0 + a1))) >= 0.0 { [0, 1, 2] } else { [0, 2, 1] };
        scene.add_triangle([q[i], q[j], q[l]], material);
        scene.set_last_normals([n[i], n[j], n[l]]);
        let [i, j, l] =
            if (q[2] - q[0]).cross(q[3] - q[0]).dot(radial(0.5 * (a0 + a1))) >= 0.0 { [0, 2, 3] } else { [0, 3, 2] };
        scene.add_triangle([q[i], q[j], q[l]], material);
        scene.set_last_normals([n[i], n[j], n[l]]);
    }
}

/// A linear-RGB albedo for a hue in [0, 1) at the given saturation and value.
fn hue(h: f32, saturation: f32, value: f32) -> Vec3 {
    let k = |n: f32| {
        let k = (n + h * 6.0) % 6.0;
        value - value * saturation * k.min(4.0 - k).clamp(0.0, 1.0)
    };
    // HSV to sRGB, then sRGB to linear (a gamma of 2.2 is close enough for a test scene).
    Vec3::new(k(5.0), k(3.0), k(1.0)).powf(2.2)
}

/// About `triangles` triangles (at least 8): an m × m grid of UV spheres in eight colours on
/// a grey floor, lit by a square area light overhead, with a camera looking down on them at
/// an angle. m grows as the fourth root of the count (a million triangles: 16 × 16 spheres
/// of about 4 000 triangles each), so large scenes have both many objects and fine meshes.
pub fn spheres(triangles: usize) -> Scene {
    let fixed = 4; // floor and light
    let budget = triangles.saturating_sub(fixed).max(8);
    let m = ((budget as f64 / 4000.0).sqrt().ceil() as usize).clamp(1, 64);
    let count = m * m;
    // 2·s·(s/2 − 1) = s² − 2s triangles per sphere of s segments (s even): the finest s that
    // fits every sphere, then as many spheres as fit at s + 2.
    let mut segments = ((1.0 + (1.0 + budget as f64 / count as f64).sqrt()).round() as u32).max(4) & !1;
    while segments > 4 && sphere_triangles(segments) * count > budget {
        segments -= 2;
    }
    let extra = sphere_triangles(segments + 2) - sphere_triangles(segments);
    let finer = (budget.saturating_sub(sphere_triangles(segments) * count) / extra).min(count);

    let half = 0.5 * m as f32;
    let camera = Camera {
        eye: Vec3::new(0.3 * half, 1.2 * half + 1.5, 1.8 * half + 2.5),
        target: Vec3::new(0.0, 0.0, 0.15 * half),
        up: Vec3::Y,
        fov_y_deg: 45.0,
    };
    let mut s = Scene::new(camera);
    let floor = s.add_material(Material::diffuse("floor", Vec3::splat(0.6)));
    let light =
        s.add_material(Material { emission: Vec3::new(6.0, 5.6, 5.0), ..Material::diffuse("light", Vec3::ZERO) });
    let colours: Vec<u32> = (0..8)
        .map(|k| s.add_material(Material::diffuse(&format!("sphere{k}"), hue(k as f32 / 8.0, 0.65, 0.85))))
        .collect();

    let extent = half + 1.5;
    let floor_quad = [
        Vec3::new(-extent, 0.0, -extent),
        Vec3::new(extent, 0.0, -extent),
        Vec3::new(extent, 0.0, extent),
        Vec3::new(-extent, 0.0, extent),
    ];
    add_quad_facing(&mut s, floor_quad, Vec3::Y, floor);
    let (h, l) = (half + 2.0, 0.4 * half + 0.5);
    let light_quad = [Vec3::new(-l, h, -l), Vec3::new(l, h, -l), Vec3::new(l, h, l), Vec3::new(-l, h, l)];
    add_quad_facing(&mut s, light_quad, Vec3::NEG_Y, light);

    let radius = 0.4;
    for i in 0..m {
        for j in 0..m {
            let centre = Vec3::new(i as f32 - half + 0.5, radius, j as f32 - half + 0.5);
            let segments = if i * m + j < finer { segments + 2 } else { segments };
            add_sphere(&mut s, centre, radius, segments, colours[(i * 3 + j * 5) % colours.len()]);
        }
    }
    s
}

/// One arcade: a wall `thickness` thick in the plane x = `x`, from `y_spring` to `y_top`,
/// pierced by semicircular arches between consecutive column centres `columns` (along z),
/// each arch `column_width` narrower than its bay.
fn add_arcade(
    scene: &mut Scene,
    x: f32,
    thickness: f32,
    columns: &[f32],
    column_width: f32,
    (y_spring, y_top): (f32, f32),
    material: u32,
) {
    const ARCH_SEGMENTS: u32 = 16;
    let (x0, x1) = (x - 0.5 * thickness, x + 0.5 * thickness);
    let hw = 0.5 * column_width;
    let (z_first, z_last) = (columns[0] - hw, columns[columns.len() - 1] + hw);
    let at = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    // Top, ends, and the flat undersides above the columns.
    add_quad_facing(
        scene,
        [at(x0, y_top, z_first), at(x1, y_top, z_first), at(x1, y_top, z_last), at(x0, y_top, z_last)],
        Vec3::Y,
        material,
    );
    for (z, n) in [(z_first, Vec3::NEG_Z), (z_last, Vec3::Z)] {
        add_quad_facing(
            scene,
            [at(x0, y_spring, z), at(x1, y_spring, z), at(x1, y_top, z), at(x0, y_top, z)],
            n,
            material,
        );
    }
    for &c in columns {
        add_quad_facing(
            scene,
            [at(x0, y_spring, c - hw), at(x1, y_spring, c - hw), at(x1, y_spring, c + hw), at(x0, y_spring, c + hw)],
            Vec3::NEG_Y,
            material,
        );
    }
    // Each bay: the faces at x0 and x1 between the arch and the bay's rectangle, as quads
    // between the arch and its radial projection onto the rectangle (the rectangle's upper
    // corners are among the angles, so every quad is convex and planar), and the vault.
    for pair in columns.windows(2) {
        let (zc, half_bay) = (0.5 * (pair[0] + pair[1]), 0.5 * (pair[1] - pair[0]));
        let radius = half_bay - hw;
        let height = y_top - y_spring;
        let corner = height.atan2(half_bay);
        let mut angles: Vec<f32> =
            (0..=ARCH_SEGMENTS).map(|k| std::f32::consts::PI * k as f32 / ARCH_SEGMENTS as f32).collect();
        angles.extend([corner, std::f32::consts::PI - corner]);
        angles.sort_by(f32::total_cmp);
        angles.dedup_by(|a, b| (*a - *b).abs() < 1e-4);
        let arch = |a: f32| (zc + radius * a.cos(), y_spring + radius * a.sin());
        let rim = |a: f32| {
            let (c, s) = (a.cos(), a.sin());
            let t = (half_bay / c.abs().max(1e-6)).min(height / s.abs().max(1e-6));
            (zc + t * c, y_spring + t * s)
        };
        for w in angles.windows(2) {
            let (a0, a1) = (w[0], w[1]);
            let (p0, p1, r0, r1) = (arch(a0), arch(a1), rim(a0), rim(a1));
            for (xf, n) in [(x0, Vec3::NEG_X), (x1, Vec3::X)] {
                let q = [at(xf, p0.1, p0.0), at(xf, p1.1, p1.0), at(xf, r1.1, r1.0), at(xf, r0.1, r0.0)];
                add_quad_facing(scene, q, n, material);
            }
            // The vault faces the arch's centre.
            let mid = 0.5 * (a0 + a1);
            let inward = Vec3::new(0.0, -mid.sin(), -mid.cos());
            let q = [at(x0, p0.1, p0.0), at(x1, p0.1, p0.0), at(x1, p1.1, p1.0), at(x0, p1.1, p1.0)];
            add_quad_facing(scene, q, inward, material);
        }
    }
}

/// The hall's camera: standing at the entrance, looking down the nave.
pub const ATRIUM_CAMERA: Camera =
    Camera { eye: Vec3::new(0.5, 1.7, 2.85), target: Vec3::new(-0.7, 1.35, -6.0), up: Vec3::Y, fov_y_deg: 60.0 };

/// A closed hall 8 m wide, 9 m deep and 4.5 m high: a nave between two arcades of four
/// round columns each, three tall warm windows in the terracotta left wall, a cool skylight
/// over the nave, a teal right wall, a blue back wall, a checkered stone floor, a blue
/// sphere and a golden block on it. The windows light the left aisle and throw the
/// columns' soft shadows across the nave; the coloured walls bleed onto the floor, the
/// columns and the ceiling. About 2 500 triangles; every material is two-sided, as an
/// OBJ file's would be, so the built-in scene and `scenes/atrium.obj` are the same.
pub fn atrium() -> Scene {
    let mut s = Scene::new(ATRIUM_CAMERA);
    let material = |s: &mut Scene, name: &str, albedo: Vec3, emission: Vec3| {
        s.add_material(Material { emission, two_sided: true, ..Material::diffuse(name, albedo) })
    };
    let none = Vec3::ZERO;
    let stone_light = material(&mut s, "stone_light", Vec3::new(0.72, 0.66, 0.58), none);
    let stone_dark = material(&mut s, "stone_dark", Vec3::new(0.32, 0.29, 0.27), none);
    let plaster = material(&mut s, "plaster", Vec3::new(0.78, 0.77, 0.74), none);
    let terracotta = material(&mut s, "terracotta", Vec3::new(0.66, 0.24, 0.13), none);
    let teal = material(&mut s, "teal", Vec3::new(0.10, 0.42, 0.38), none);
    let blue = material(&mut s, "blue", Vec3::new(0.14, 0.20, 0.58), none);
    let marble = material(&mut s, "marble", Vec3::new(0.82, 0.80, 0.76), none);
    let glaze = material(&mut s, "glaze", Vec3::new(0.10, 0.22, 0.70), none);
    let gold = material(&mut s, "gold", Vec3::new(0.80, 0.56, 0.12), none);
    let window = material(&mut s, "window", none, Vec3::new(16.0, 12.0, 7.5));
    let sky = material(&mut s, "sky", none, Vec3::new(0.8, 1.05, 1.5));

    let (x0, x1, y1, z0, z1) = (-4.0f32, 4.0f32, 4.5f32, -6.0f32, 3.0f32);
    // Floor: 1 m tiles in a checker.
    for i in 0..8 {
        for k in 0..9 {
            let (x, z) = (x0 + i as f32, z0 + k as f32);
            let q = [
                Vec3::new(x, 0.0, z),
                Vec3::new(x + 1.0, 0.0, z),
                Vec3::new(x + 1.0, 0.0, z + 1.0),
                Vec3::new(x, 0.0, z + 1.0),
            ];
            add_quad_facing(&mut s, q, Vec3::Y, if (i + k) % 2 == 0 { stone_light } else { stone_dark });
        }
    }
    let wall = |s: &mut Scene, q: [Vec3; 4], n: Vec3, m: u32| add_quad_facing(s, q, n, m);
    let p = Vec3::new;
    wall(&mut s, [p(x0, y1, z0), p(x1, y1, z0), p(x1, y1, z1), p(x0, y1, z1)], Vec3::NEG_Y, plaster);
    wall(&mut s, [p(x0, 0.0, z0), p(x1, 0.0, z0), p(x1, y1, z0), p(x0, y1, z0)], Vec3::Z, blue);
    wall(&mut s, [p(x0, 0.0, z1), p(x1, 0.0, z1), p(x1, y1, z1), p(x0, y1, z1)], Vec3::NEG_Z, plaster);
    wall(&mut s, [p(x1, 0.0, z0), p(x1, 0.0, z1), p(x1, y1, z1), p(x1, y1, z0)], Vec3::NEG_X, teal);
    wall(&mut s, [p(x0, 0.0, z0), p(x0, 0.0, z1), p(x0, y1, z1), p(x0, y1, z0)], Vec3::X, terracotta);
    // Windows: emitters 2 cm in front of the left wall, facing into the hall.
    for zc in [-3.0f32, -1.0, 1.0] {
        let x = x0 + 0.02;
        let q = [p(x, 1.0, zc - 0.5), p(x, 1.0, zc + 0.5), p(x, 3.3, zc + 0.5), p(x, 3.3, zc - 0.5)];
        wall(&mut s, q, Vec3::X, window);
    }
    // Skylight: a strip under the ceiling over the nave, facing down.
    let y = y1 - 0.02;
    wall(&mut s, [p(-0.8, y, -4.5), p(0.8, y, -4.5), p(0.8, y, 0.5), p(-0.8, y, 0.5)], Vec3::NEG_Y, sky);

    // Two arcades on round columns.
    let columns = [-4.0f32, -2.0, 0.0, 2.0];
    for x in [-2.0f32, 2.0] {
        for &z in &columns {
            add_cylinder(&mut s, p(x, 0.0, z), 0.18, 2.6, 16, marble);
            // Plinths reach 1 cm under the floor: no face coincides with it.
            add_box(&mut s, p(x - 0.22, -0.01, z - 0.22), p(x + 0.22, 0.12, z + 0.22), marble);
        }
        add_arcade(&mut s, x, 0.4, &columns, 0.4, (2.6, 3.5), plaster);
    }
    add_sphere(&mut s, p(0.7, 0.55, -2.6), 0.55, 32, glaze);
    // The block, turned 30° about y, its bottom 1 cm under the floor.
    let (c, half) = (p(-0.6, 0.395, -0.4), p(0.45, 0.405, 0.3));
    let first = s.triangles.len();
    add_box(&mut s, -half, half, gold);
    let turn = glam::Quat::from_rotation_y(30f32.to_radians());
    for t in &mut s.triangles[first..] {
        *t = t.map(|v| c + turn * v);
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{triangle_area, triangle_normal};

    /// Whether every triangle of a closed surface faces away from `inside`, judged by the
    /// signed volume of the tetrahedron (inside, triangle): positive for outward windings.
    fn signed_volume(tris: &[[Vec3; 3]], inside: Vec3) -> f32 {
        tris.iter().map(|t| (t[0] - inside).dot((t[1] - inside).cross(t[2] - inside)) / 6.0).sum()
    }

    #[test]
    fn sphere_is_closed_outward_and_has_the_counted_triangles() {
        for segments in [4, 8, 32, 64] {
            let mut s = Scene::new(ATRIUM_CAMERA);
            let m = s.add_material(Material::diffuse("m", Vec3::ONE * 0.5));
            add_sphere(&mut s, Vec3::new(1.0, 2.0, 3.0), 0.5, segments, m);
            assert_eq!(s.triangles.len(), sphere_triangles(segments));
            // Enclosed volume equals the polyhedron's, which approaches 4/3·π·r³ from below.
            let v = signed_volume(&s.triangles, Vec3::new(1.0, 2.0, 3.0));
            let sphere = 4.0 / 3.0 * std::f32::consts::PI * 0.125;
            assert!(v > 0.0 && v <= sphere * 1.0001, "segments {segments}: volume {v} vs {sphere}");
            if segments >= 32 {
                assert!(v > 0.97 * sphere, "segments {segments}: volume {v} vs {sphere}");
            }
        }
    }

    #[test]
    fn spheres_scene_has_about_the_requested_triangles() {
        for n in [1usize, 100, 10_000, 250_000, 1_000_000] {
            let s = spheres(n);
            s.validate().unwrap();
            let got = s.triangles.len();
            println!("spheres:{n} → {got} triangles");
            // Short by at most one step of one sphere's refinement once there are many triangles.
            assert!(got as f64 <= (n as f64 * 1.01).max(300.0), "spheres:{n} gave {got}");
            let floor = if n >= 10_000 { 0.97 } else { 0.5 };
            assert!(got as f64 >= floor * n as f64, "spheres:{n} gave only {got}");
            assert!(s.emitted_power().min_element() > 0.0);
        }
    }

    #[test]
    fn builtin_names_parse_and_bad_parameters_are_errors() {
        assert_eq!(builtin("cornell").unwrap().unwrap().triangles.len(), cornell_box().triangles.len());
        assert!(builtin("atrium").unwrap().is_some());
        assert!(builtin("spheres:1_000").unwrap().is_some());
        assert!(builtin("scene.obj").unwrap().is_none());
        for bad in ["spheres:", "spheres:abc", "spheres:0", "spheres:-5", "spheres:999999999999"] {
            let e = builtin(bad).unwrap_err().to_string();
            assert!(e.contains(bad), "'{e}' does not name '{bad}'");
        }
    }

    #[test]
    fn atrium_is_closed_lit_from_inside_and_every_side_faces_as_built() {
        let s = atrium();
        s.validate().unwrap();
        let b = s.bounds();
        assert_eq!((b.min, b.max), (Vec3::new(-4.0, -0.01, -6.0), Vec3::new(4.0, 4.5, 3.0)));
        assert!(ATRIUM_CAMERA.eye.cmpgt(b.min).all() && ATRIUM_CAMERA.eye.cmplt(b.max).all());
        // Emitters face into the hall: the windows +x, the skylight −y.
        let lights = s.emissive_triangles();
        assert_eq!(lights.len(), 8);
        for &i in &lights {
            let n = triangle_normal(&s.triangles[i as usize]);
            assert!(n == Vec3::X || n == Vec3::NEG_Y, "emitter {i} faces {n}");
        }
        // The room's six sides enclose the hall: their windings give its volume.
        let walls = ["plaster", "blue", "teal", "terracotta", "stone_light", "stone_dark"];
        let (lo, hi) = (Vec3::new(-4.0, 0.0, -6.0), Vec3::new(4.0, 4.5, 3.0));
        let on_side =
            |t: &[Vec3; 3]| (0..3).any(|a| t.iter().all(|p| p[a] == lo[a]) || t.iter().all(|p| p[a] == hi[a]));
        let room: Vec<[Vec3; 3]> = (0..s.triangles.len())
            .filter(|&i| walls.contains(&s.material_of(i).name.as_str()) && on_side(&s.triangles[i]))
            .map(|i| s.triangles[i])
            .collect();
        let inside = -signed_volume(&room, Vec3::new(0.0, 2.0, 0.0));
        assert!((inside - 8.0 * 4.5 * 9.0).abs() < 1e-2, "room walls enclose {inside} m³");
        let area: f32 = s.triangles.iter().map(triangle_area).sum();
        assert!(area > 300.0 && s.triangles.len() < 4000, "area {area}, {} triangles", s.triangles.len());
    }
}
