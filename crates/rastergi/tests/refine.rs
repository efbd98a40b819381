//! The viewer's frame budget (`session::refine`): an iteration run in row bands is the whole
//! iteration bit for bit; the image shown in the middle of one, and a preview blended in, are
//! what the film's sums and the preview's say (computed here on the CPU); and after a camera
//! move, previews and bands leave the film exactly what a fresh render of the new view gives.

mod common;

use rastergi::gather::GatherMethod;
use rastergi::gpu::Gpu;
use rastergi::gpu::consts::{FILM_DIRECT, FILM_INDIRECT};
use rastergi::passes::film::{FilmState, Show};
use rastergi::progressive::Denoising;
use rastergi::renderer::Renderer;
use rastergi::scene::{Scene, cornell_box};
use rastergi::session::interactive::Interactive;
use rastergi::settings::RenderSettings;

/// An image size whose height is no multiple of the bands' rows nor of the 8-row workgroups.
const SIZE: (u32, u32) = (40, 27);

fn settings(gather: GatherMethod) -> RenderSettings {
    RenderSettings {
        width: SIZE.0,
        height: SIZE.1,
        photons: 1 << 13,
        grid_resolution: 10,
        gather,
        pass_iterations: 2,
        seed: 5,
        ..Default::default()
    }
}

/// The mean of the full image at pixel `p` of `s`, from its sums, with `n` iterations there.
fn mean(s: &FilmState, p: usize, n: u32) -> [f32; 3] {
    let pixels = (s.width * s.height) as usize;
    let at = |c: u32, ch: usize| s.sums[(c as usize * pixels + p) * 4 + ch];
    [0, 1, 2].map(|ch| if n == 0 { 0.0 } else { (at(FILM_DIRECT, ch) + at(FILM_INDIRECT, ch)) / n as f32 })
}

#[test]
fn an_iteration_in_row_bands_is_the_whole_iteration_bit_for_bit() {
    let gpu = common::gpu();
    let scene = cornell_box();
    for gather in [GatherMethod::Trace, GatherMethod::Raster] {
        let mut whole = Renderer::new(&gpu, &scene, settings(gather)).unwrap();
        let mut banded = Renderer::new(&gpu, &scene, settings(gather)).unwrap();
        whole.enable_denoiser().unwrap();
        banded.enable_denoiser().unwrap();
        // Five iterations, photon passes of two: bands of 5 rows (the last of 2), then 1, 13.
        for (i, rows) in [5, 5, 1, 13, 5].into_iter().enumerate() {
            whole.iterate().unwrap();
            let mut bands = 0;
            while !banded.iterate_rows(rows).unwrap() {
                bands += 1;
                assert_eq!(banded.rows_ahead(), (bands * rows).min(SIZE.1));
                assert_eq!(banded.samples(), i as u32, "an iteration counts once its last band is in");
            }
            assert_eq!(bands, SIZE.1.div_ceil(rows) - 1);
            assert_eq!(banded.rows_ahead(), 0);
        }
        let (a, b) = (whole.film_state().unwrap(), banded.film_state().unwrap());
        assert!(a.sums == b.sums && a.half == b.half, "{gather:?}: the banded film differs from the whole one");
        assert_eq!((a.samples, a.half_samples), (b.samples, b.half_samples));
        assert!(
            whole.read_guides().unwrap() == banded.read_guides().unwrap(),
            "{gather:?}: the denoiser's guides differ"
        );
    }
}

#[test]
fn the_image_in_the_middle_of_a_banded_iteration_counts_its_rows_once_more() {
    let gpu = common::gpu();
    let mut r = Renderer::new(&gpu, &cornell_box(), settings(GatherMethod::Trace)).unwrap();
    for _ in 0..2 {
        r.iterate().unwrap();
    }
    assert!(!r.iterate_rows(11).unwrap());
    let state = r.film_state().unwrap();
    let shown = r.read_linear(Show::Full).unwrap();
    for (p, got) in shown.pixels.iter().enumerate() {
        let n = if (p as u32) / SIZE.0 < 11 { 3 } else { 2 };
        let want = mean(&state, p, n);
        for c in 0..3 {
            assert!((got[c] - want[c]).abs() <= 1e-6 * want[c].abs().max(1.0), "pixel {p}: {got:?} against {want:?}");
        }
    }
}

/// The blend of `film` (with `rows_ahead`) and the preview `pre` weighted `w`, as
/// `Film::encode_resolve_preview` documents it, at every pixel: none where the film has an
/// iteration and its samples show an edge of light (the shares of the pixel that saw light,
/// the direct component's fourth channel, differ in the pixel's 3 × 3 neighbourhood); where
/// the film has an iteration and no edge, only the preview's taps whose share of light is the
/// film pixel's; all of them where the film has none.
fn blend(film: &FilmState, rows_ahead: u32, pre: &FilmState, pre_rows_ahead: u32, w: f32) -> Vec<[f32; 3]> {
    let (fw, fh, pw, ph) = (film.width, film.height, pre.width, pre.height);
    let pixels = (fw * fh) as usize;
    // (share of the samples that saw light, the iterations) at (x, y).
    let share = |x: u32, y: u32| {
        let n = film.samples + u32::from(y < rows_ahead);
        let seen = film.sums[(FILM_DIRECT as usize * pixels + (y * fw + x) as usize) * 4 + 3];
        (seen / n.max(1) as f32, n)
    };
    let edge = |x: u32, y: u32| {
        let (s, n) = share(x, y);
        let near = |a: u32, len: u32| a.saturating_sub(1)..=(a + 1).min(len - 1);
        n > 0 && near(y, fh).any(|qy| near(x, fw).any(|qx| matches!(share(qx, qy), (t, m) if m > 0 && t != s)))
    };
    let mut out = Vec::new();
    for y in 0..fh {
        for x in 0..fw {
            let n = film.samples + u32::from(y < rows_ahead);
            let p = (y * fw + x) as usize;
            let sum = [0, 1, 2].map(|ch| {
                film.sums[(FILM_DIRECT as usize * pixels + p) * 4 + ch]
                    + film.sums[(FILM_INDIRECT as usize * pixels + p) * 4 + ch]
            });
            let px = (x as f32 + 0.5) * pw as f32 / fw as f32 - 0.5;
            let py = (y as f32 + 0.5) * ph as f32 / fh as f32 - 0.5;
            let (bx, by) = (px.floor(), py.floor());
            let (fx, fy) = (px - bx, py - by);
            let own = (n > 0).then(|| share(x, y).0);
            let (mut taps, mut tw) = ([0.0f32; 3], 0.0f32);
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let qx = (bx + dx as f32).clamp(0.0, pw as f32 - 1.0) as u32;
                let qy = (by + dy as f32).clamp(0.0, ph as f32 - 1.0) as u32;
                let wt = if dx == 1 { fx } else { 1.0 - fx } * if dy == 1 { fy } else { 1.0 - fy };
                let m = pre.samples + u32::from(qy < pre_rows_ahead);
                let q = (qy * pw + qx) as usize;
                let seen = pre.sums[(FILM_DIRECT as usize * (pw * ph) as usize + q) * 4 + 3] / m.max(1) as f32;
                if m > 0 && wt > 0.0 && own.is_none_or(|s| s == seen) {
                    let v = mean(pre, q, m);
                    (0..3).for_each(|c| taps[c] += wt * v[c]);
                    tw += wt;
                }
            }
            let weight = n as f32;
            let wp = if tw > 0.0 && !edge(x, y) { w * tw / ((1.0 + weight) * (1.0 + weight)) } else { 0.0 };
            let preview = taps.map(|t| if tw > 0.0 { t / tw } else { 0.0 });
            let total = [0, 1, 2].map(|c| sum[c] + wp * preview[c]);
            let all = weight + wp;
            out.push(total.map(|t| if all == 0.0 { 0.0 } else { t / all }));
        }
    }
    out
}

#[test]
fn a_preview_is_blended_in_as_its_weight_and_the_films_iterations_say() {
    let gpu = common::gpu();
    let mut r = Renderer::new(&gpu, &cornell_box(), settings(GatherMethod::Trace)).unwrap();
    for scale in [4, 2] {
        for _ in 0..3 {
            while !r.iterate_preview_rows(scale, 3).unwrap() {}
        }
    }
    // The ½ preview one band into its fourth iteration; the film none, then one and a band.
    assert!(!r.iterate_preview_rows(2, 4).unwrap());
    let pre = r.preview_film(2).unwrap();
    assert_eq!((pre.samples, pre.rows_ahead, pre.width, pre.height), (3, 4, 20, 14));
    let pre_state = pre.read_state(&gpu).unwrap();
    let check = |r: &mut Renderer, w: f32| {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        r.encode_resolve_blend(&mut enc, (Show::Full, 0.0), Some((2, w)));
        gpu.queue.submit([enc.finish()]);
        let shown = r.film().read_linear_buffer(&gpu).unwrap();
        let want = blend(&r.film_state().unwrap(), r.rows_ahead(), &pre_state, 4, w);
        for (p, (got, want)) in shown.pixels.iter().zip(&want).enumerate() {
            for c in 0..3 {
                assert!(
                    (got[c] - want[c]).abs() <= 1e-5 * want[c].abs().max(1.0),
                    "pixel {p}: {got:?} against {want:?}"
                );
            }
        }
    };
    check(&mut r, 3.0);
    r.iterate().unwrap();
    assert!(!r.iterate_rows(9).unwrap());
    check(&mut r, 3.0);
    check(&mut r, 0.5);
}

#[test]
fn the_view_before_a_move_is_shown_where_the_new_view_sees_the_same_triangles() {
    // A small step, and an orbit of 70° that sees the red wall from outside (its back, which
    // the old view saw lit from inside: not the same surface).
    let scene = cornell_box();
    let step = {
        let mut c = scene.camera;
        c.eye += glam::Vec3::new(0.08, 0.03, 0.0);
        c
    };
    let orbit = {
        let mut c = rastergi::camera_control::CameraControl::new(&scene.camera, &scene.bounds());
        c.orbit(70f32.to_radians(), 0.0);
        c.camera()
    };
    // Pixels whose old pixel saw the same side of the same triangle, measured: 581 and 34 of
    // the 1080 (at 40 × 27 the old pixel's jittered point often lies on a neighbouring
    // triangle or behind an edge).
    check_reprojection(step, 500);
    check_reprojection(orbit, 30);
}

/// After `M` iterations of the Cornell box's view, a move to `camera`: the shown image (the
/// film has no iteration yet and there is no preview) against the re-projection computed on
/// the CPU, which must find at least `at_least` valid pixels.
fn check_reprojection(camera: rastergi::scene::Camera, at_least: usize) {
    const M: u32 = 3;
    let gpu = common::gpu();
    let scene = cornell_box();
    let prepared = rastergi::surface::PreparedScene::new(&scene);
    let mut r = fixed_map(&gpu, &scene);
    for _ in 0..M {
        r.iterate().unwrap();
    }
    let (old, old_g, old_camera) = (r.film_state().unwrap(), r.read_gbuffer().unwrap(), r.camera());
    r.set_camera(camera).unwrap();
    assert!(r.reproject().unwrap());
    assert!(!r.reproject().unwrap(), "once per view");
    let new_g = r.read_gbuffer().unwrap();
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    r.encode_resolve_blend(&mut enc, (Show::Full, 0.0), None);
    gpu.queue.submit([enc.finish()]);
    let shown = r.film().read_linear_buffer(&gpu).unwrap();
    // On the CPU: each pixel's point through the old view to the old pixel; the old mean there
    // where the old pixel saw the same side of the same triangle (its last iteration's
    // G-buffer), else nothing.
    let back = |v: &common::VisiblePoint, eye: glam::Vec3| v.normal.dot(eye - v.pos) < 0.0;
    let (w, h) = SIZE;
    let near = rastergi::passes::frame::near_plane(&prepared.bounds);
    let vp = rastergi::passes::frame::view_projection(&old_camera, w, h, near, glam::Vec2::ZERO);
    let (mut valid, mut differ) = (0, 0);
    for (p, got) in shown.pixels.iter().enumerate() {
        let expected = common::VisiblePoint::decode(&prepared.scene, new_g[p]).and_then(|v| {
            let clip = vp * v.pos.extend(1.0);
            let (x, y) = ((clip.x / clip.w + 1.0) * 0.5 * w as f32, (1.0 - clip.y / clip.w) * 0.5 * h as f32);
            let q = (y.floor() as usize) * w as usize + x.floor() as usize;
            let inside = clip.w > 0.0 && (0.0..w as f32).contains(&x) && (0.0..h as f32).contains(&y);
            let old_v = common::VisiblePoint::decode(&prepared.scene, old_g[*inside.then_some(&q)?])?;
            let same = old_v.tri == v.tri && back(&old_v, old_camera.eye) == back(&v, camera.eye);
            same.then(|| mean(&old, q, M))
        });
        valid += usize::from(expected.is_some());
        let want = expected.unwrap_or([0.0; 3]);
        if (0..3).any(|c| (got[c] - want[c]).abs() > 1e-5 * want[c].abs().max(1.0)) {
            differ += 1;
        }
    }
    let n = (w * h) as usize;
    // A point on a pixel's boundary may round to either neighbour on the GPU.
    assert!(differ <= n / 100, "{differ} of {n} pixels differ from the re-projection computed here ({valid} valid)");
    assert!(valid >= at_least, "{valid} of {n} pixels see what the old view saw");
}

/// After a move, where the view before it is kept (re-projected) and a coarse preview's taps
/// straddle an edge of light (an emitter, the sky), the preview is not blended in: its pixels
/// spread the light's radiance over their neighbours (a halo ten pixels wide around the Cornell
/// box's light at 1280 × 720, half a second after a stop), which the kept pixel does not. The
/// film has no iteration; the shown image there must be the history's alone, bit for bit the
/// resolve without the preview; elsewhere the preview still counts.
#[test]
fn a_coarse_preview_does_not_spread_light_over_the_kept_view() {
    const M: u32 = 3;
    let gpu = common::gpu();
    let scene = cornell_box();
    let mut r = fixed_map(&gpu, &scene);
    for _ in 0..M {
        r.iterate().unwrap();
    }
    let mut camera = r.camera();
    camera.eye += glam::Vec3::new(0.08, 0.03, 0.0);
    r.set_camera(camera).unwrap();
    assert!(r.reproject().unwrap());
    let shown = |r: &mut Renderer, preview: Option<(u32, f32)>| {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        r.encode_resolve_blend(&mut enc, (Show::Full, 0.0), preview);
        gpu.queue.submit([enc.finish()]);
        r.film().read_linear_buffer(&gpu).unwrap()
    };
    let kept = shown(&mut r, None);
    for _ in 0..3 {
        while !r.iterate_preview_rows(4, 4).unwrap() {}
    }
    let blended = shown(&mut r, Some((4, 3.0)));
    let pre = r.preview_film(4).unwrap();
    let (pw, ph, m) = (pre.width, pre.height, pre.samples);
    let pre = pre.read_state(&gpu).unwrap();
    let (fw, fh) = SIZE;
    // The preview's taps at each window pixel (as resolve.wgsl's preview_mean): whether the
    // shares of their samples that saw light differ.
    let seen =
        |qx: u32, qy: u32| pre.sums[(FILM_DIRECT as usize * (pw * ph) as usize + (qy * pw + qx) as usize) * 4 + 3];
    let (mut straddling, mut changed) = (0, 0);
    for y in 0..fh {
        for x in 0..fw {
            let px = (x as f32 + 0.5) * pw as f32 / fw as f32 - 0.5;
            let py = (y as f32 + 0.5) * ph as f32 / fh as f32 - 0.5;
            let (bx, by) = (px.floor(), py.floor());
            let (fx, fy) = (px - bx, py - by);
            let shares: Vec<f32> = [(0, 0), (1, 0), (0, 1), (1, 1)]
                .into_iter()
                .filter(|&(dx, dy)| (if dx == 1 { fx } else { 1.0 - fx }) * (if dy == 1 { fy } else { 1.0 - fy }) > 0.0)
                .map(|(dx, dy)| {
                    let qx = (bx + dx as f32).clamp(0.0, pw as f32 - 1.0) as u32;
                    let qy = (by + dy as f32).clamp(0.0, ph as f32 - 1.0) as u32;
                    seen(qx, qy) / m as f32
                })
                .collect();
            let edge = shares.iter().any(|&s| s != shares[0]);
            let p = (y * fw + x) as usize;
            let (k, b) = (kept.pixels[p], blended.pixels[p]);
            // A kept pixel: the history's nonzero mean (the box's walls and light).
            if k.iter().any(|&c| c > 0.0) {
                if edge {
                    straddling += 1;
                    assert!(
                        (0..3).all(|c| (b[c] - k[c]).abs() <= 1e-5 * k[c].abs().max(1.0)),
                        "pixel ({x}, {y}): the preview spread its light over the kept {k:?}: {b:?}"
                    );
                } else if (0..3).any(|c| (b[c] - k[c]).abs() > 1e-5 * k[c].abs().max(1.0)) {
                    changed += 1;
                }
            }
        }
    }
    // Measured: 239 kept pixels whose taps straddle an edge (the light's, the box's opening
    // onto the black sky), 343 others that the preview changed.
    assert!(straddling >= 100, "{straddling} kept pixels whose taps straddle an edge of light");
    assert!(changed >= 150, "the preview changed only {changed} kept pixels away from edges of light");
}

/// A scene's renderer for the interactive tests: one fixed photon map, so that a fresh
/// renderer's film and one continued after a move can agree bit for bit.
fn fixed_map(gpu: &Gpu, scene: &Scene) -> Renderer {
    let s = RenderSettings { photon_passes: 1, ..settings(GatherMethod::Trace) };
    Renderer::new(gpu, scene, s).unwrap()
}

#[test]
fn after_a_move_previews_and_bands_leave_the_film_of_a_fresh_render() {
    const N: u32 = 4;
    let gpu = common::gpu();
    let scene = cornell_box();
    let mut view = Interactive::new(Box::new(fixed_map(&gpu, &scene)), Show::Full, 0.0);
    // A budget no iteration fits: the coarsest preview while moving, bands of a row or so.
    view.set_frame_budget(1e-6);
    let mut camera = scene.camera;
    for step in 0..3 {
        camera.eye += glam::Vec3::new(0.05, 0.02 * step as f32, 0.0);
        view.set_camera(camera).unwrap();
        assert_eq!(view.frame(u32::MAX).unwrap(), 0, "a moving camera gets a preview, not the window's iterations");
        assert_eq!(view.renderer().samples(), 0);
        let (scale, weight) = view.refine().blend().expect("a preview is shown while moving");
        assert!(scale >= 2 && weight == 1.0, "{scale} {weight}");
    }
    // Still: the previews refine, then the window's iterations accumulate in bands.
    let mut frames = 0;
    while view.renderer().samples() < N {
        view.frame(N - view.renderer().samples()).unwrap();
        frames += 1;
        assert!(frames < 10_000, "the view never converged");
    }
    assert!(view.refine().refined());
    assert!(frames > (N * SIZE.1) as usize / 4, "{frames} frames: the window's iterations ran in bands");
    // As many restarts as the view had (each turns the gather's directions on), to the same
    // cameras.
    let mut fresh = fixed_map(&gpu, &scene);
    let mut c = scene.camera;
    for step in 0..3 {
        c.eye += glam::Vec3::new(0.05, 0.02 * step as f32, 0.0);
        fresh.set_camera(c).unwrap();
    }
    for _ in 0..N {
        fresh.iterate().unwrap();
    }
    let (a, b) = (view.renderer().film_state().unwrap(), fresh.film_state().unwrap());
    assert!(a.sums == b.sums, "the film after the move differs from a fresh render of the view");
}
