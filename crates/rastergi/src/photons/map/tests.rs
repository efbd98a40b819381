use std::collections::HashMap;

use glam::{UVec3, Vec3};

use crate::gpu::limits::test_limits as limits;
use crate::scene::{Aabb, Camera, Material, Scene, cornell_box, triangle_area, triangle_normal};

use super::*;
use crate::sampling::{Rng, uniform_sphere};

fn scene_of_quads(quads: &[[Vec3; 4]]) -> Scene {
    let cam = Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
    let mut s = Scene::new(cam);
    let m = s.add_material(Material::diffuse("m", Vec3::ONE));
    for q in quads {
        s.add_quad(*q, m);
    }
    s
}

/// The grid of 4³ cells 0.25 wide from the origin and the layout in it of a scene holding
/// one square, from (0, 0, z) to (1, 1, z).
fn unit_square_layout(z: f32) -> (GridSpec, MapLayout) {
    let s = scene_of_quads(&[[
        Vec3::new(0.0, 0.0, z),
        Vec3::new(1.0, 0.0, z),
        Vec3::new(1.0, 1.0, z),
        Vec3::new(0.0, 1.0, z),
    ]]);
    let grid = GridSpec::uniform(Vec3::ZERO, 0.25, UVec3::new(4, 4, 4));
    let layout = MapLayout::new(&s, &grid);
    (grid, layout)
}

/// The angle between two unit vectors, in degrees.
fn angle(a: Vec3, b: Vec3) -> f32 {
    a.dot(b).clamp(-1.0, 1.0).acos().to_degrees()
}

#[test]
fn axis_normals_lie_in_the_central_bin_of_their_face_and_every_bin_is_used() {
    for (face, n) in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z].into_iter().enumerate() {
        assert_eq!(orientation_bin(n), (face * FACE_DIVISIONS + 1) * FACE_DIVISIONS + 1, "{n}");
    }
    // Random directions: all 54 bins occur, and within a bin no two are farther apart than
    // the central bin's diagonal, 2·atan(√2/3) = 50.48°.
    let mut rng = Rng::new(3, 0, 0);
    let mut members: Vec<Vec<Vec3>> = vec![Vec::new(); BINS];
    for _ in 0..20_000 {
        let n = uniform_sphere(rng.next_f32(), rng.next_f32());
        members[orientation_bin(n)].push(n);
    }
    let widest = 2.0 * (2f32.sqrt() / 3.0).atan().to_degrees();
    for (b, m) in members.iter().enumerate() {
        assert!(!m.is_empty(), "bin {b} never used");
        for x in m.iter().step_by(7) {
            for y in m.iter().step_by(11) {
                assert!(angle(*x, *y) <= widest + 0.01, "bin {b}: {x} and {y} {}° apart", angle(*x, *y));
            }
        }
    }
}

#[test]
fn parallel_planes_farther_apart_than_the_offset_step_never_share_a_key() {
    let grid = GridSpec::uniform(Vec3::ZERO, 0.25, UVec3::splat(8));
    let step = OFFSET_STEP * grid.cell;
    let mut rng = Rng::new(5, 0, 0);
    for _ in 0..2000 {
        let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0;
        let gap = step * (1.0 + 2.0 * rng.next_f32());
        let c = grid.coarse().cell_of(p);
        let (a, b) = (TrianglePlane::new(-Vec3::Y, p), TrianglePlane::new(-Vec3::Y, p + Vec3::Y * gap));
        for back in [false, true] {
            assert_ne!(a.key(&grid.coarse(), c, back), b.key(&grid.coarse(), c, back), "{p} {gap}");
        }
    }
    // The same plane through any of its points: one key per cell.
    let c = UVec3::new(2, 1, 3);
    let k = TrianglePlane::new(Vec3::Y, Vec3::new(0.1, 0.37, 0.2)).key(&grid.coarse(), c, false);
    assert_eq!(TrianglePlane::new(Vec3::Y, Vec3::new(1.9, 0.37, 1.3)).key(&grid.coarse(), c, false), k);
}

#[test]
fn clipped_areas_sum_to_the_scene_area_per_plane_key() {
    let scene = cornell_box();
    for resolution in [1, 7, 32] {
        let grid = GridSpec::new(&scene.bounds(), resolution);
        let layout = MapLayout::new(&scene, &grid);
        let mut expected: HashMap<u32, f64> = HashMap::new();
        // Per orientation bin: the bin is the key's low bits, below the region.
        for (i, t) in scene.triangles.iter().enumerate() {
            *expected.entry(layout.planes[i].bins[0]).or_default() += triangle_area(t) as f64;
            if scene.material_of(i).two_sided {
                *expected.entry(layout.planes[i].bins[1]).or_default() += triangle_area(t) as f64;
            }
        }
        let mut got: HashMap<u32, f64> = HashMap::new();
        for (k, a) in layout.table.keys.iter().zip(&layout.area) {
            if k[0] != EMPTY {
                *got.entry(k[1] & ((1 << REGION_SHIFT) - 1)).or_default() += a;
            }
        }
        assert_eq!(got.len(), expected.len(), "bins at {resolution}");
        for (bin, e) in &expected {
            let g = got.get(bin).copied().unwrap_or(0.0);
            assert!((g - e).abs() < 1e-5 * e.max(1.0), "bin {bin} at {resolution}: {g} vs {e}");
        }
    }
}

#[test]
fn a_refined_grid_keeps_every_area_once_and_puts_fine_cells_in_its_region_only() {
    // Cornell's box with its middle refined 4×: per orientation bin, the areas of both
    // levels sum to the scene's; every slot inside the region is a fine one (of a quarter
    // the side), every one outside a coarse one; each deposit point finds the slot of its
    // own level.
    let scene = cornell_box();
    let region = Aabb { min: Vec3::new(-0.5, -0.3, -0.4), max: Vec3::new(0.2, 0.6, 0.5) };
    let grid = GridSpec::new(&scene.bounds(), 16).refined(&region, 4);
    let fine = grid.fine().expect("a fine level");
    assert_eq!(fine.cell, grid.cell / 4.0);
    let layout = MapLayout::new(&scene, &grid);
    let mut expected: HashMap<u32, f64> = HashMap::new();
    for (i, t) in scene.triangles.iter().enumerate() {
        *expected.entry(layout.planes[i].bins[0]).or_default() += triangle_area(t) as f64;
        if scene.material_of(i).two_sided {
            *expected.entry(layout.planes[i].bins[1]).or_default() += triangle_area(t) as f64;
        }
    }
    let mut got: HashMap<u32, f64> = HashMap::new();
    let (mut coarse_slots, mut fine_slots) = (0, 0);
    for (k, a) in layout.table.keys.iter().zip(&layout.area) {
        if k[0] != EMPTY {
            *got.entry(k[1] & ((1 << REGION_SHIFT) - 1)).or_default() += a;
            if k[0] >= fine.base { fine_slots += 1 } else { coarse_slots += 1 }
        }
    }
    assert!(coarse_slots > 0 && fine_slots > 0);
    for (bin, e) in &expected {
        let g = got.get(bin).copied().unwrap_or(0.0);
        assert!((g - e).abs() < 1e-5 * e.max(1.0), "bin {bin}: {g} vs {e}");
    }
    let mut rng = Rng::new(4, 0, 0);
    for _ in 0..4000 {
        let tri = (rng.next_u32() as usize) % scene.triangles.len();
        let t = &scene.triangles[tri];
        let p = crate::sampling::uniform_triangle(t, rng.next_f32(), rng.next_f32());
        let level = grid.lattice_at(p);
        let inside = grid.is_refined(grid.coarse().cell_of(p));
        assert_eq!(level.base > 0, inside, "{p}");
        if let Some(s) = layout.deposit_slot(tri, false, p) {
            assert_eq!(layout.table.keys[s][0] >= fine.base, inside, "{p}");
        }
    }
}

#[test]
fn points_on_walls_that_lie_on_cell_boundaries_find_their_slot() {
    // The sunroom's walls at z = 0 and x = 0 lie on cell boundaries of its grids (centred
    // on the origin) at some resolutions; cell_of's f32 rounding put their points in the
    // cell below, their area (clipped exactly) in the cell above, and every photon landing
    // there was lost: all of some walls at 274, 287, 329 and 379 cells, the progressive
    // passes' resolutions from 228. Now every point of every triangle finds its slot, in
    // both levels of the refined grid and in the plain one.
    let scene = crate::scene::generate::sunroom();
    let region = Aabb { min: Vec3::new(-0.4, 0.0, -3.45), max: Vec3::new(6.4, 3.2, 5.4) };
    let mut rng = Rng::new(8, 0, 0);
    for r in [228, 274, 287, 329, 379] {
        for refine in [10, 1] {
            let grid = GridSpec::new(&scene.bounds(), r).refined(&region, refine);
            let layout = MapLayout::new(&scene, &grid);
            for (i, t) in scene.triangles.iter().enumerate() {
                for _ in 0..200 {
                    let p = crate::sampling::uniform_triangle(t, rng.next_f32(), rng.next_f32());
                    assert!(layout.deposit_slot(i, false, p).is_some(), "{r} cells, refined {refine}: {p} on {i}");
                }
            }
        }
    }
}

#[test]
fn a_uniform_map_reads_uniform_across_the_two_levels() {
    // Φ = 2·A in every slot of both levels: E = 2 at any point, beside the region's border
    // too (a lookup counts only cells of its own level).
    let scene = cornell_box();
    let region = Aabb { min: Vec3::new(-0.2, -0.2, -0.2), max: Vec3::new(0.3, 0.3, 0.3) };
    let grid = GridSpec::new(&scene.bounds(), 8).refined(&region, 3);
    let layout = MapLayout::new(&scene, &grid);
    let flux = layout.area.iter().map(|&a| [2.0 * a; 3]).collect();
    let n = layout.table.capacity();
    let map = PhotonMap { layout, flux, flux_sq: vec![0.0; n], deposits: vec![0; n], dropped: 0 };
    let mut rng = Rng::new(6, 0, 0);
    for _ in 0..2000 {
        let tri = (rng.next_u32() as usize) % scene.triangles.len();
        let p = crate::sampling::uniform_triangle(&scene.triangles[tri], rng.next_f32(), rng.next_f32());
        let e = map.irradiance_on(tri, false, p);
        assert!((e[0] - 2.0).abs() < 1e-9, "{tri} {p}: {e:?}");
    }
}

#[test]
fn the_cornell_light_and_the_ceiling_above_it_never_share_a_slot() {
    let scene = cornell_box();
    let grid = GridSpec::new(&scene.bounds(), 64);
    let layout = MapLayout::new(&scene, &grid);
    // The ceiling at y = 1 and the light at y = 0.99 (3.1 cm cells), both facing down:
    // in every cell holding light, the light's slot holds the light's area alone.
    let lights = scene.emissive_triangles();
    let light_area: f64 = lights.iter().map(|&i| triangle_area(&scene.triangles[i as usize]) as f64).sum();
    let mut slots = std::collections::HashSet::new();
    let mut ceiling_cells = 0;
    let mut rng = Rng::new(9, 0, 0);
    for _ in 0..4000 {
        let p = Vec3::new(rng.next_f32() * 0.46 - 0.23, 0.99, rng.next_f32() * 0.38 - 0.18);
        let i = lights[0] as usize;
        slots.insert(layout.deposit_slot(i, false, p).expect("the light's slot"));
        let q = Vec3::new(p.x, 1.0, p.z);
        let c = grid.coarse().cell_of(q);
        let (cell, key) = (grid.coarse().index(c), TrianglePlane::new(-Vec3::Y, q).key(&grid.coarse(), c, false));
        if layout.table.find(cell, key | layout.region(cell, key, q) << REGION_SHIFT).is_some() {
            ceiling_cells += 1;
        }
    }
    let total: f64 = slots.iter().map(|&s| layout.area[s]).sum();
    assert!((total - light_area).abs() < 1e-6, "light slots hold {total}, the light {light_area}");
    assert!(ceiling_cells > 0, "the ceiling shares the light's cells");
}

#[test]
fn a_unit_square_on_a_cell_boundary_plane_splits_its_area_exactly() {
    // A square in the plane z = 0.3, from (0,0) to (1,1), in a grid of cells 0.25 wide:
    // every cell it crosses gets exactly 0.0625.
    let (grid, layout) = unit_square_layout(0.3);
    for y in 0..4 {
        for x in 0..4 {
            let c = UVec3::new(x, y, 1);
            let e = layout
                .table
                .find(grid.coarse().index(c), layout.planes[0].key(&grid.coarse(), c, false))
                .expect("a slot");
            assert!((layout.area[e] - 0.0625).abs() < 1e-9, "cell ({x},{y}): {}", layout.area[e]);
        }
    }
    assert_eq!(layout.table.len(), 16);
}

#[test]
fn a_square_exactly_on_a_cell_boundary_counts_once_in_the_cell_its_photons_land_in() {
    let (grid, layout) = unit_square_layout(0.5);
    let total: f64 = layout.area.iter().sum();
    assert!((total - 1.0).abs() < 1e-9, "area counted {total} times");
    assert_eq!(grid.coarse().cell_of(Vec3::new(0.3, 0.3, 0.5)).z, 2);
    let e = layout.deposit_slot(0, false, Vec3::new(0.3, 0.3, 0.5)).expect("the slot photons land in");
    assert!((layout.area[e] - 0.0625).abs() < 1e-9);
}

#[test]
fn a_grid_whose_slots_exceed_the_binding_limit_degrades_to_coarser_cells() {
    let scene = cornell_box();
    let roomy =
        wgpu::Limits { max_storage_buffer_binding_size: 1 << 30, max_buffer_size: 1 << 32, ..Default::default() };
    let asked = MapLayout::within(&scene, &scene.bounds(), 32, None, &roomy).unwrap();
    assert_eq!(asked.grid, GridSpec::new(&scene.bounds(), 32));
    // 1 MiB binds 65 536 lookup values; 256³ cells would need millions.
    let tight =
        wgpu::Limits { max_storage_buffer_binding_size: 1 << 20, max_buffer_size: 1 << 32, ..Default::default() };
    let coarse = MapLayout::within(&scene, &scene.bounds(), 256, None, &tight).unwrap();
    let used = coarse.grid.dims.max_element();
    assert!(used < 256 && 256 % used == 0, "{used}");
    assert!(check_photon_slots(&tight, &coarse).is_ok());
    assert!(coarse.table.capacity() as u64 * 16 <= 1 << 20);
    // The coarser map is a whole map: every triangle's area is in it.
    let total: f64 = coarse.area.iter().sum();
    let expected: f64 = scene.triangles.iter().map(|t| triangle_area(t) as f64).sum();
    assert!((total - expected).abs() < 1e-4 * expected, "{total} vs {expected}");
}

#[test]
fn lookup_of_a_uniform_map_returns_the_uniform_irradiance_anywhere() {
    // Φ = 3·A in every slot: E = 3 wherever interpolated, even at borders and next to
    // cells without that plane. Three quads of different planes, areas varied by their
    // cuts through the cells.
    let s = scene_of_quads(&[
        [Vec3::new(0.0, 0.0, 0.1), Vec3::new(2.9, 0.0, 0.1), Vec3::new(2.9, 1.7, 0.1), Vec3::new(0.0, 1.7, 0.1)],
        [Vec3::new(0.2, 0.3, 0.0), Vec3::new(0.2, 2.9, 0.0), Vec3::new(0.2, 2.9, 2.1), Vec3::new(0.2, 0.3, 2.1)],
        [Vec3::new(0.0, 2.3, 0.0), Vec3::new(0.0, 2.3, 2.9), Vec3::new(1.1, 2.3, 2.9), Vec3::new(1.1, 2.3, 0.0)],
    ]);
    let grid = GridSpec::uniform(Vec3::ZERO, 1.0, UVec3::new(3, 3, 3));
    let layout = MapLayout::new(&s, &grid);
    let flux = layout.area.iter().map(|&a| [3.0 * a; 3]).collect();
    let n = layout.table.capacity();
    let map = PhotonMap { layout, flux, flux_sq: vec![0.0; n], deposits: vec![0; n], dropped: 0 };
    for (tri, p) in [(0, Vec3::new(0.01, 0.01, 0.1)), (0, Vec3::new(2.8, 1.6, 0.1)), (2, Vec3::new(0.3, 0.5, 1.5))] {
        let e = map.irradiance_on(tri, false, p);
        assert!((e[0] - 3.0).abs() < 1e-9, "{tri} {p}: {e:?}");
    }
    let e = map.irradiance(Vec3::new(0.5, 2.3, 2.5), triangle_normal(&s.triangles[4]));
    assert!((e[0] - 3.0).abs() < 1e-9, "{e:?}");
}

#[test]
fn photon_cells_need_31_bit_indices_and_the_slots_must_fit_the_bindings() {
    let bounds = crate::scene::Aabb { min: glam::Vec3::ZERO, max: glam::Vec3::ONE };
    let l = limits(128);
    // 1280³ = 2.10·10⁹ cells fit 31 bits (the top bit marks caustic twins), 1300³ = 2.20·10⁹
    // do not.
    assert!(check_photon_grid(&l, &GridSpec::new(&bounds, 1280)).is_ok());
    let e = check_photon_grid(&l, &GridSpec::new(&bounds, 1300)).unwrap_err().to_string();
    assert!(e.contains("1300x1300x1300") && e.contains("--grid"), "{e}");
    // The largest per-entry binding is the lookup values' 16 bytes; all counters share a
    // buffer of 24 bytes per entry.
    let scene = crate::scene::cornell_box();
    let layout = MapLayout::new(&scene, &GridSpec::new(&scene.bounds(), 32));
    let entries = layout.table.capacity() as u64;
    let fits = wgpu::Limits {
        max_storage_buffer_binding_size: entries * 16,
        max_buffer_size: entries * 24,
        ..Default::default()
    };
    assert!(check_photon_slots(&fits, &layout).is_ok());
    let narrow = wgpu::Limits { max_storage_buffer_binding_size: entries * 16 - 4, ..fits.clone() };
    let e = check_photon_slots(&narrow, &layout).unwrap_err().to_string();
    assert!(e.contains("lookup values") && e.contains("32x32x32") && e.contains("--grid"), "{e}");
    let short = wgpu::Limits { max_buffer_size: entries * 24 - 1, ..fits };
    let e = check_photon_slots(&short, &layout).unwrap_err().to_string();
    assert!(e.contains("one buffer"), "{e}");
}
