//! Progressive photon passes (`photons::passes`): the map is re-traced with fresh photons in
//! cells that shrink on the stated schedule, its energy stays the emitted power's, and a room
//! sealed by a thin wall stays black with every pass.

mod common;

use rastergi::film::Show;
use rastergi::gather::GatherMethod;
use rastergi::photons::passes::pass_resolution;
use rastergi::renderer::{RenderSettings, Renderer};
use rastergi::scene::generate::rooms;

fn settings(passes: u32) -> RenderSettings {
    RenderSettings {
        width: 48,
        height: 36,
        photons: 1 << 16,
        grid_resolution: 16,
        photon_passes: passes,
        pass_iterations: 2,
        ..Default::default()
    }
}

#[test]
fn each_pass_traces_fresh_photons_on_the_schedule_with_the_same_energy() {
    let gpu = common::gpu();
    let scene = rooms(true);
    let mut r = Renderer::new(&gpu, &scene, settings(0)).unwrap();
    let mut last: Option<rastergi::photons::map::PhotonMap> = None;
    let mut totals = Vec::new();
    for pass in 0..8u32 {
        for _ in 0..2 {
            r.iterate().unwrap();
        }
        assert_eq!(r.photon_pass(), pass);
        let map = r.photon_map().unwrap().read(&gpu).unwrap();
        assert_eq!(map.grid().dims.max_element(), pass_resolution(16, pass), "pass {pass}");
        if let Some(previous) = &last
            && previous.grid() == map.grid()
        {
            assert_ne!(previous.flux, map.flux, "pass {pass} traced the same photons again");
        }
        totals.push(map.total_flux()[1]);
        last = Some(map);
    }
    // Every pass deposits the same expected flux: N photons of the same power.
    let mean = totals.iter().sum::<f64>() / totals.len() as f64;
    for (k, t) in totals.iter().enumerate() {
        assert!((t / mean - 1.0).abs() < 0.02, "pass {k}: total {t} against the mean {mean}");
    }
}

#[test]
fn the_sealed_room_stays_exactly_black_with_a_fixed_map_and_with_passes() {
    // The closed rooms: the camera's room receives no light at all (Mitsuba: 0 at every
    // pixel). The map's slots keep the two rooms apart (the wall's faces separate the floor,
    // ceiling and side walls they stand on), so neither the fixed coarse map nor the passes'
    // finer ones put light there; the traced gather reads the map exactly where its rays hit.
    let gpu = common::gpu();
    let scene = rooms(false);
    for passes in [1, 0] {
        let settings = RenderSettings { gather: GatherMethod::Trace, ..settings(passes) };
        let img = common::render(&gpu, &scene, settings, 64, Show::Full);
        let max = img.pixels.iter().map(|p| p[0].max(p[1]).max(p[2])).fold(0.0f32, f32::max);
        assert_eq!(max, 0.0, "photon passes {passes}: light in the sealed room");
    }
    // The doorway's rooms with the same settings are lit (the test would pass vacuously
    // otherwise).
    let open = common::render(
        &gpu,
        &rooms(true),
        RenderSettings { gather: GatherMethod::Trace, ..settings(0) },
        16,
        Show::Indirect,
    );
    let mean = open.pixels.iter().map(|p| p[1] as f64).sum::<f64>() / open.pixels.len() as f64;
    assert!(mean > 1e-3, "the open rooms' indirect light: {mean}");
}
