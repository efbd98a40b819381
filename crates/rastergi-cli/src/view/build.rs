//! What the viewer builds a renderer from ([`Build`]), a scene opened by a build
//! ([`Opened`]), and how a build turns the loaded scene into the one it renders.

use std::sync::Arc;

use rastergi::scene::Scene;
use rastergi::settings::RenderSettings;

use super::controls::SunAngles;
use crate::args::SceneArgs;
use crate::render::Method;

/// What a renderer is built from besides the scene's geometry: the viewer rebuilds its
/// renderer when the wanted one differs.
#[derive(Clone, Debug, PartialEq)]
pub struct Build {
    pub(super) settings: RenderSettings,
    pub(super) method: Method,
    pub(super) sun: Option<SunAngles>,
    pub(super) env_scale: Option<f32>,
    /// Which scene: counts the scenes opened.
    pub(super) scene: u64,
}

/// A scene opened by a build, with its fitted photon settings.
pub struct Opened {
    pub(super) name: String,
    pub(super) scene: Arc<Scene>,
    pub(super) photons: u32,
    pub(super) grid: u32,
    pub(super) sun: Option<SunAngles>,
    pub(super) env_scale: Option<f32>,
}

/// Whether `a` and `b` differ in the image size alone.
pub(super) fn same_but_size(a: &Build, b: &Build) -> bool {
    let mut a = a.clone();
    (a.settings.width, a.settings.height) = (b.settings.width, b.settings.height);
    a == *b
}

/// The scene as a build wants it: its sun (the last distant light) turned to the wanted
/// angles and its environment map scaled to the wanted `--env-scale` (it was loaded at
/// `loaded_scale`).
pub(super) fn prepare(mut scene: Scene, wanted: &Build, loaded_scale: f32) -> Scene {
    if let Some(sun) = wanted.sun {
        scene.turn_sun(sun);
    }
    if let (Some(scale), Some(env)) = (wanted.env_scale, &scene.environment)
        && scale != loaded_scale
        && loaded_scale > 0.0
    {
        scene.environment = Some(Arc::new(env.scaled(scale / loaded_scale)));
    }
    scene
}

/// The environment scale the panel can change: `--env-scale` where the scene has an
/// environment map that is not black.
pub(super) fn env_scale(a: &SceneArgs, scene: &Scene) -> Option<f32> {
    scene.environment.as_ref().filter(|e| !e.is_dark() && a.env_scale > 0.0).map(|_| a.env_scale)
}
