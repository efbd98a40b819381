//! The session layer against what `rastergi render` produced before it existed: the settings,
//! image sizes, light overrides and refusals of a few flag combinations, written out, and the
//! run loop's stops.

use std::sync::atomic::AtomicUsize;

use glam::Vec3;

use super::run::{Limits, Observer, Stop, run};
use super::*;
use crate::scene::Framing;
use crate::settings::PhotonBudget;

/// `rastergi render cornell` (no flags): 256², fitted 2^20 photons on a 64-cell grid (the
/// figures the user guide gives for cornell), every other setting the renderer's default.
#[test]
fn cornell_with_no_flags_gets_the_fitted_defaults() {
    let options = Options { scene: "cornell".into(), ..Options::default() };
    let session = Session::load(&options).unwrap();
    // The renderer's own defaults (256², seed 0, the traced-or-rasterized `auto` gather with
    // four per-pixel directions, …) but for the fitted photon map and the front ends' balanced
    // photon budget and light samples (from one).
    let defaults = RenderSettings {
        photons: 1 << 20,
        grid_resolution: 64,
        photon_budget: crate::settings::PhotonBudget::Balanced,
        light_balance: true,
        ..RenderSettings::default()
    };
    assert_eq!(session.settings, defaults);
    assert_eq!((defaults.width, defaults.height, defaults.directions), (256, 256, 4));
}

/// `rastergi render cornell --width 96 --height 40 --seed 7 --photons 5000 --grid 20 --bundle
/// 300 --gather trace --gather-directions shared --directions 2 --light-samples 3
/// --photon-passes 4 --pass-iterations 10 --photon-budget fitted --photon-guiding off
/// --gather-guiding off --sky-guiding off --hit-light exact --photon-region scene --texture-filter bilinear
/// --show photon-map`.
#[test]
fn given_flags_are_the_settings() {
    let options = Options {
        scene: "cornell".into(),
        width: Some(96),
        height: Some(40),
        seed: 7,
        photons: Some(5000),
        grid: Some(20),
        bundle: Some(300),
        gather: GatherMethod::Trace,
        gather_directions: GatherDirections::Shared,
        directions: 2,
        light_samples: 3,
        light_balance: false,
        emitter_edges: 2,
        photon_passes: 4,
        pass_iterations: 10,
        photon_budget: PhotonBudget::Fitted,
        photon_guiding: false,
        gather_guiding: false,
        sky_guiding: false,
        hit_light: HitLight::Exact,
        photon_region: PhotonRegionChoice::Scene,
        texture_filter: TextureFilter::Bilinear,
        eye_pass: crate::settings::EyeMethod::Trace,
        show: Show::PhotonMap,
        ..Options::default()
    };
    let session = Session::load(&options).unwrap();
    let expected = RenderSettings {
        width: 96,
        height: 40,
        seed: 7,
        light_samples: 3,
        light_balance: false,
        emitter_edges: 2,
        photons: 5000,
        grid_resolution: 20,
        show_photon_map: true,
        bundle: 300,
        gather: GatherMethod::Trace,
        gather_directions: GatherDirections::Shared,
        auto_trials_on_cpu: false,
        directions: 2,
        photon_passes: 4,
        pass_iterations: 10,
        photon_budget: PhotonBudget::Fitted,
        photon_guiding: false,
        gather_guiding: false,
        sky_guiding: false,
        hit_light: HitLight::Exact,
        photon_region: PhotonRegionChoice::Scene,
        texture_filter: TextureFilter::Bilinear,
        eye_pass: crate::settings::EyeMethod::Trace,
    };
    assert_eq!(session.settings, expected);
    assert_eq!(
        Method::Path.check_show(Show::PhotonMap).unwrap_err().to_string(),
        "--method path renders the full image only; drop --show or use --method gather"
    );
    Method::Gather.check_show(Show::PhotonMap).unwrap();
}

/// A scene file's film frames the image: both sides from it, one side from its aspect
/// (rounded), or as given; 256² without a film.
#[test]
fn the_image_size_follows_the_films_framing() {
    let mut scene = crate::scene::cornell_box();
    let size = |width, height, scene: &Scene| Options { width, height, ..Options::default() }.image_size(scene);
    assert_eq!(size(None, None, &scene), (256, 256));
    assert_eq!(size(Some(100), None, &scene), (100, 256));
    scene.framing = Some(Framing { width: 640, height: 480, samples: Some(64) });
    assert_eq!(size(None, None, &scene), (640, 480));
    assert_eq!(size(Some(320), None, &scene), (320, 240));
    assert_eq!(size(None, Some(100), &scene), (133, 100));
    assert_eq!(size(Some(10), Some(10), &scene), (10, 10));
}

/// `--point`, `--sun` with an irradiance, and the refusals of `--sun`/`--sky` combinations, in
/// the command line's words.
#[test]
fn light_options_add_lights_or_are_refused() {
    let before = load_scene("cornell").unwrap();
    let point = Light::Point { position: Vec3::new(0.0, 1.0, 0.0), intensity: Vec3::splat(5.0) };
    let sun = Sun { azimuth: 90.0, elevation: 30.0, irradiance: Some(1000.0) };
    let options = Options { lights: vec![point], sun: Some(sun), sun_size: 0.0, ..Options::default() };
    let scene = options.load_scene().unwrap();
    assert_eq!(scene.lights.len(), before.lights.len() + 2);
    assert_eq!(scene.lights[before.lights.len()], point);
    let Light::Distant { direction, irradiance, angular_radius } = *scene.lights.last().unwrap() else {
        panic!("{:?}", scene.lights)
    };
    // Azimuth 90° turns from +Z to +X; 30° up: the light travels down towards −X.
    assert!((direction - Vec3::new(-0.75f32.sqrt(), -0.5, 0.0)).length() < 1e-6, "{direction}");
    assert_eq!((irradiance, angular_radius), (Vec3::splat(1000.0), 0.0));

    let refused = |options: Options| options.load_scene().unwrap_err().to_string();
    let no_irradiance = Sun { irradiance: None, ..sun };
    assert_eq!(
        refused(Options { sun: Some(no_irradiance), ..Options::default() }),
        "--sun AZIMUTH,ELEVATION needs --sky (or add IRRADIANCE: --sun AZIMUTH,ELEVATION,IRRADIANCE)"
    );
    assert_eq!(
        refused(Options { sun: Some(sun), sky: Some(3.0), ..Options::default() }),
        "with --sky the sky model gives the sun's irradiance: give --sun AZIMUTH,ELEVATION without IRRADIANCE"
    );
    assert_eq!(
        refused(Options { sky: Some(3.0), ..Options::default() }),
        "--sky needs the sun's position: give --sun AZIMUTH,ELEVATION (the scene cornell has no sun)"
    );
    assert_eq!(
        refused(Options { scene: "nothing.ply".into(), ..Options::default() }),
        format!(
            "unknown scene 'nothing.ply': use a built-in scene ({}) or a path to a .obj, .gltf, .glb or Mitsuba .xml file",
            crate::scene::generate::BUILTIN_NAMES
        )
    );
}

/// `sunroom --sky 3`: the scene's sun (35° up, azimuth 200°, a delta direction) becomes
/// the model's, of the irradiance Mitsuba 3.9.1's sunsky gives at 35° and turbidity 3 (its
/// radiance at the disc's centre, (20755.25, 16636.76, 11582.435), × the disc's solid
/// angle), same direction and disc; the sky is the environment, bright above the horizon
/// and black below it.
#[test]
fn sky_replaces_the_scenes_sun_with_the_models() {
    let before = load_scene("sunroom").unwrap();
    let scene = Options { scene: "sunroom".into(), sky: Some(3.0), ..Options::default() }.load_scene().unwrap();
    let sun = |s: &Scene| {
        let distant: Vec<_> = s.lights.iter().filter(|l| matches!(l, Light::Distant { .. })).collect();
        assert_eq!(distant.len(), 1, "{:?}", s.lights);
        *distant[0]
    };
    let (
        Light::Distant { direction: d0, angular_radius: r0, .. },
        Light::Distant { direction, irradiance, angular_radius },
    ) = (sun(&before), sun(&scene))
    else {
        unreachable!()
    };
    assert_eq!((direction, angular_radius), (d0, r0));
    let omega = (std::f64::consts::TAU * (1.0 - (0.5 * 0.5358f64).to_radians().cos())) as f32;
    let mitsuba = Vec3::new(20755.25, 16636.76, 11582.435) * omega;
    assert!(((irradiance - mitsuba) / mitsuba).abs().max_element() < 2e-3, "{irradiance} vs {mitsuba}");
    let env = scene.environment.as_ref().expect("the sky");
    assert!(env.eval(Vec3::Y).min_element() > 0.0 && env.eval(-Vec3::Y) == Vec3::ZERO);
}

/// Counts what the loop reports, and stops it after `stop_after` iterations if given.
#[derive(Default)]
struct Counting {
    iterated: u32,
    synced: Vec<u32>,
    stop_after: Option<u32>,
}

impl Observer for Counting {
    fn iterated(&mut self, _done: u32) {
        self.iterated += 1;
    }
    fn synced(&mut self, done: u32) -> std::ops::ControlFlow<()> {
        self.synced.push(done);
        if self.stop_after.is_some_and(|n| done >= n) {
            return std::ops::ControlFlow::Break(());
        }
        std::ops::ControlFlow::Continue(())
    }
}

/// The loop runs the iterations up to the total (counting those held), syncing every 8 (or
/// every one where they are slow); a set stop flag stops it before the first, an observer's
/// request at a sync.
#[test]
fn the_run_loop_stops_at_the_total_the_flag_or_the_observer() {
    let gpu = Gpu::new(&GpuOptions::default()).expect("tests need a GPU adapter (lavapipe on CI)");
    let options = Options { width: Some(16), height: Some(16), method: Method::Path, ..Options::default() };
    let (mut renderer, gather) = Session::load(&options).unwrap().renderer(&gpu, &options).unwrap();
    assert!(gather.is_none());

    let mut seen = Counting::default();
    let outcome = run(renderer.as_mut(), &Limits::iterations(20), None, &mut seen).unwrap();
    assert_eq!((outcome.stop, outcome.first, outcome.done, seen.iterated), (Stop::Done, 0, 20, 20));
    assert_eq!(renderer.samples(), 20);
    assert!(seen.synced.iter().all(|&n| n <= 20) && seen.synced.windows(2).all(|w| w[0] < w[1]), "{:?}", seen.synced);

    // 20 more: the total counts the 20 held.
    let outcome = run(renderer.as_mut(), &Limits::iterations(40), None, &mut ()).unwrap();
    assert_eq!((outcome.stop, outcome.first, outcome.done), (Stop::Done, 20, 40));

    let flag = AtomicUsize::new(15);
    let outcome = run(renderer.as_mut(), &Limits::iterations(100), Some(&flag), &mut ()).unwrap();
    assert_eq!((outcome.stop, outcome.done), (Stop::Signal(15), 40));

    let mut seen = Counting { stop_after: Some(41), ..Counting::default() };
    let outcome = run(renderer.as_mut(), &Limits::iterations(100), None, &mut seen).unwrap();
    assert_eq!(outcome.stop, Stop::Requested);
    assert_eq!(outcome.done, seen.synced[0]);
    assert!(outcome.done > 40 && outcome.done <= 48, "{outcome:?}");
    assert_eq!(renderer.samples(), outcome.done);
}
