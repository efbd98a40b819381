//! Scripts for `rastergi view --script FILE`: timed actions that drive the viewer, for demos
//! and automated runs (the tests use one).
//!
//! One action per line, optionally preceded by a condition; `#` starts a comment, blank lines
//! are ignored:
//!
//! ```text
//! # render 16 iterations, turn the camera, render 16 more, save, quit
//! after 16 iterations: orbit 20,0
//! after 16 iterations: screenshot
//! quit
//! ```
//!
//! Conditions (a line without one runs right after the line before it):
//!
//! - `after N iterations:` — once the image has accumulated N iterations since its last
//!   restart (a camera move restarts it). The viewer stops at exactly N, so a screenshot then
//!   holds N iterations.
//! - `after T s:` — T seconds (a decimal number) after the previous line ran.
//!
//! Actions (angles in degrees, distances in scene units):
//!
//! | action | effect |
//! |---|---|
//! | `move R,U,F` | moves the camera R to the right, U up (world up), F forward, like WASD/QE |
//! | `look Y,P` | turns the view Y right and P up, keeping the eye (a fly-mode drag) |
//! | `orbit Y,P` | turns the view Y right and P up, keeping the target (the eye swings about it) |
//! | `pan X,Y` | slides the view like a right-button drag of X,Y pixels (x right, y down) |
//! | `zoom S` | S scroll notches toward the target (negative: away) |
//! | `mode fly` / `mode orbit` | the mouse-drag mode |
//! | `show full\|direct\|indirect\|photon-map` | what the image shows (no restart) |
//! | `exposure EV` | sets the display exposure in stops |
//! | `denoise on\|off` | shows the denoised full image, as the N key (photon map only; the first time restarts the image) |
//! | `photons N` / `grid N` | re-traces the photon map with N photons / N grid cells |
//! | `passes N` | photon passes (0: no limit; 1: one fixed map), re-traces |
//! | `sun AZIMUTH,ELEVATION` | puts the scene's sun (its last distant light) there, re-traces |
//! | `env-scale S` | scales the environment map's radiance (as `--env-scale`), re-traces |
//! | `method gather\|path` | the photon map + final gather, or the reference path tracer |
//! | `gather auto\|raster\|lists\|trace` | the final gather's implementation |
//! | `gather-directions per-pixel\|shared` | whose directions the traced gather casts |
//! | `directions N` | gather directions per iteration (1 to 16) |
//! | `speed S` | the camera's flying speed, scene units per second |
//! | `home` | back to the starting camera |
//! | `open SCENE` | opens another scene (built in or a file), as the panel's Open does |
//! | `panel on\|off` | shows or hides the control panel (as H) |
//! | `resize W,H` | asks for a W×H window; waits until the image has that size |
//! | `screenshot` | saves `rastergi-NNNN.png` and `.exr` as the P key does |
//! | `quit` | closes the viewer |
//!
//! The control panel acts through the same actions: every setting it changes is one of them,
//! so a script reproduces what a click does.
//!
//! A script that ends without `quit` leaves the viewer running. Every error names the file
//! and line.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use rastergi::gather::{GatherDirections, GatherMethod};
use rastergi::passes::film::Show;

use crate::args::{GatherArg, GatherDirectionsArg, ShowArg};
use crate::render::Method;

/// When a step runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum When {
    /// Right after the previous step.
    Now,
    /// Once the image holds at least this many iterations since its last restart.
    Iterations(u32),
    /// This long after the previous step ran.
    Elapsed(Duration),
}

/// Something done to the viewer: by a script line, or by the control panel.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    Move {
        right: f32,
        up: f32,
        forward: f32,
    },
    Look {
        yaw_deg: f32,
        pitch_deg: f32,
    },
    Orbit {
        yaw_deg: f32,
        pitch_deg: f32,
    },
    Pan {
        dx: f32,
        dy: f32,
    },
    Zoom {
        steps: f32,
    },
    Mode {
        orbit: bool,
    },
    Show(Show),
    Exposure(f32),
    /// Shows the denoised image (on) or the raw one.
    Denoise(bool),
    Photons(u32),
    Grid(u32),
    /// Puts the scene's sun at (azimuth, elevation) degrees.
    Sun {
        azimuth: f32,
        elevation: f32,
    },
    /// Photon passes (0: no limit).
    PhotonPasses(u32),
    /// The environment's radiance scale (as `--env-scale`).
    EnvScale(f32),
    Method(Method),
    Gather(GatherMethod),
    GatherDirections(GatherDirections),
    /// Gather directions per iteration.
    Directions(u32),
    /// How long photon passes last (`balanced` or `fitted`).
    PhotonBudget(rastergi::settings::PhotonBudget),
    /// Photons guided to where the map is read (on) or not.
    PhotonGuiding(bool),
    /// The traced gather guided by what its rays found (on) or not.
    GatherGuiding(bool),
    SkyGuiding(bool),
    LightBalance(bool),
    /// The emission at emitters' edges supersampled (on: the default rays) or not.
    EmitterEdges(bool),
    /// Camera speed in scene units per second.
    Speed(f32),
    Home,
    /// Opens a scene: a built-in name or a file.
    Open(String),
    /// Shows or hides the control panel.
    Panel(bool),
    Resize {
        width: u32,
        height: u32,
    },
    Screenshot,
    Quit,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    pub when: When,
    pub action: Action,
    /// 1-based line in the file, for messages.
    pub line: usize,
}

/// Reads and parses a script file; errors name the file and line.
pub fn load(path: &Path) -> Result<Vec<Step>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}: cannot read the script", path.display()))?;
    parse(&text).with_context(|| format!("{}", path.display()))
}

/// Parses a script's text; an error says which line and why.
pub fn parse(text: &str) -> Result<Vec<Step>> {
    let mut steps = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let step = parse_line(line).with_context(|| format!("line {}: '{line}'", i + 1))?;
        steps.push(Step { when: step.0, action: step.1, line: i + 1 });
    }
    Ok(steps)
}

fn parse_line(line: &str) -> Result<(When, Action)> {
    let (when, action) = match line.strip_prefix("after ") {
        Some(rest) => {
            let Some((condition, action)) = rest.split_once(':') else {
                bail!("a condition ends with ':', as in 'after 16 iterations: screenshot'");
            };
            (parse_when(condition.trim())?, action.trim())
        }
        None => (When::Now, line),
    };
    Ok((when, parse_action(action)?))
}

fn parse_when(condition: &str) -> Result<When> {
    let mut words = condition.split_whitespace();
    let (Some(number), Some(unit), None) = (words.next(), words.next(), words.next()) else {
        bail!("expected 'after N iterations:' or 'after T s:'");
    };
    match unit {
        "iteration" | "iterations" => {
            let n = number.parse().map_err(|_| anyhow::anyhow!("'{number}' is not a whole number of iterations"))?;
            Ok(When::Iterations(n))
        }
        "s" | "second" | "seconds" => {
            let t: f64 = number.parse().map_err(|_| anyhow::anyhow!("'{number}' is not a number of seconds"))?;
            if !(t.is_finite() && t >= 0.0) {
                bail!("'{number}' is not a non-negative number of seconds");
            }
            Ok(When::Elapsed(Duration::from_secs_f64(t)))
        }
        other => bail!("unknown unit '{other}': use 'iterations' or 's'"),
    }
}

const ACTIONS: &str = "move, look, orbit, pan, zoom, mode, show, exposure, denoise, photons, grid, passes, sun, env-scale, \
                       method, gather, gather-directions, directions, speed, home, open, panel, resize, screenshot, quit";

fn parse_action(action: &str) -> Result<Action> {
    let (name, args) = match action.split_once(char::is_whitespace) {
        Some((name, args)) => (name, args.trim()),
        None => (action, ""),
    };
    let none =
        |a: Action| -> Result<Action> { if args.is_empty() { Ok(a) } else { bail!("'{name}' takes no arguments") } };
    Ok(match name {
        "move" => {
            let [right, up, forward] = numbers::<3>(args, "R,U,F")?;
            Action::Move { right, up, forward }
        }
        "look" => {
            let [yaw_deg, pitch_deg] = numbers::<2>(args, "YAW,PITCH")?;
            Action::Look { yaw_deg, pitch_deg }
        }
        "orbit" => {
            let [yaw_deg, pitch_deg] = numbers::<2>(args, "YAW,PITCH")?;
            Action::Orbit { yaw_deg, pitch_deg }
        }
        "pan" => {
            let [dx, dy] = numbers::<2>(args, "X,Y")?;
            Action::Pan { dx, dy }
        }
        "zoom" => Action::Zoom { steps: numbers::<1>(args, "STEPS")?[0] },
        "exposure" => Action::Exposure(numbers::<1>(args, "EV")?[0]),
        "mode" => match args {
            "fly" => Action::Mode { orbit: false },
            "orbit" => Action::Mode { orbit: true },
            _ => bail!("'mode' takes 'fly' or 'orbit'"),
        },
        "show" => Action::Show(choice::<ShowArg>(name, args)?.show()),
        "denoise" => Action::Denoise(on_off(name, args)?),
        "photons" => Action::Photons(count(args, "photons", 1, u32::MAX)?),
        "grid" => Action::Grid(count(args, "grid", 1, 1024)?),
        "sun" => {
            let [azimuth, elevation] = numbers::<2>(args, "AZIMUTH,ELEVATION")?;
            Action::Sun { azimuth, elevation }
        }
        "passes" => Action::PhotonPasses(count(args, "passes", 0, u32::MAX)?),
        "env-scale" => match numbers::<1>(args, "SCALE")?[0] {
            s if s >= 0.0 => Action::EnvScale(s),
            _ => bail!("'env-scale' takes a number ≥ 0"),
        },
        "method" => Action::Method(choice(name, args)?),
        "gather" => Action::Gather(choice::<GatherArg>(name, args)?.method()),
        "gather-directions" => Action::GatherDirections(choice::<GatherDirectionsArg>(name, args)?.directions()),
        "directions" => Action::Directions(count(args, "directions", 1, rastergi::gather::MAX_DIRECTIONS)?),
        "photon-budget" => {
            Action::PhotonBudget(choice::<rastergi::session::args::PhotonBudgetArg>(name, args)?.budget())
        }
        "photon-guiding" => Action::PhotonGuiding(on_off(name, args)?),
        "gather-guiding" => Action::GatherGuiding(on_off(name, args)?),
        "sky-guiding" => Action::SkyGuiding(on_off(name, args)?),
        "light-balance" => Action::LightBalance(on_off(name, args)?),
        "emitter-edges" => Action::EmitterEdges(on_off(name, args)?),
        "speed" => match numbers::<1>(args, "SPEED")?[0] {
            s if s > 0.0 => Action::Speed(s),
            _ => bail!("'speed' takes a positive number of scene units per second"),
        },
        "home" => none(Action::Home)?,
        "open" if args.is_empty() => bail!("'open' takes a scene: a built-in name or a file"),
        "open" => Action::Open(args.to_owned()),
        "panel" => Action::Panel(on_off(name, args)?),
        "resize" => {
            let [width, height] = numbers::<2>(args, "W,H")?;
            let side = |v: f32| (1.0..=16384.0).contains(&v) && v.fract() == 0.0;
            if !(side(width) && side(height)) {
                bail!("'resize' takes a whole width and height between 1 and 16384");
            }
            Action::Resize { width: width as u32, height: height as u32 }
        }
        "screenshot" => none(Action::Screenshot)?,
        "quit" => none(Action::Quit)?,
        other => bail!("unknown action '{other}' (expected one of: {ACTIONS})"),
    })
}

/// One of the values the command line's option of that kind takes (`--show`, `--method`,
/// `--gather`, `--gather-directions`), spelled as there.
fn choice<T: ValueEnum>(name: &str, args: &str) -> Result<T> {
    if let Ok(v) = T::from_str(args, false) {
        return Ok(v);
    }
    let names: Vec<String> =
        T::value_variants().iter().filter_map(|v| v.to_possible_value()).map(|v| v.get_name().to_owned()).collect();
    match names.as_slice() {
        [a, b] => bail!("'{name}' takes '{a}' or '{b}'"),
        [first @ .., last] => bail!("'{name}' takes {} or {last}", first.join(", ")),
        [] => unreachable!("a value enum has values"),
    }
}

/// `on` or `off`.
fn on_off(name: &str, args: &str) -> Result<bool> {
    match args {
        "on" => Ok(true),
        "off" => Ok(false),
        _ => bail!("'{name}' takes 'on' or 'off'"),
    }
}

/// `N` comma-separated finite numbers.
fn numbers<const N: usize>(args: &str, shape: &str) -> Result<[f32; N]> {
    let parts: Vec<&str> = args.split(',').map(str::trim).collect();
    if args.is_empty() || parts.len() != N {
        bail!("expected {shape}");
    }
    let mut out = [0.0f32; N];
    for (o, p) in out.iter_mut().zip(&parts) {
        *o = p.parse().ok().filter(|v: &f32| v.is_finite()).ok_or_else(|| anyhow::anyhow!("'{p}' is not a number"))?;
    }
    Ok(out)
}

fn count(args: &str, name: &str, min: u32, max: u32) -> Result<u32> {
    match args.parse::<u32>() {
        Ok(n) if (min..=max).contains(&n) => Ok(n),
        _ => bail!("'{name}' takes a whole number from {min} to {max}"),
    }
}

/// The script's progress.
pub(super) struct ScriptRun {
    pub(super) steps: Vec<Step>,
    pub(super) next: usize,
    /// When the previous step ran.
    pub(super) last: Instant,
    /// A `resize` waiting for the image to take that size, and since when.
    pub(super) resizing: Option<((u32, u32), Instant)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conditions_actions_and_comments_parse() {
        let steps = parse(
            "# a demo\n\nafter 16 iterations: orbit 20,-5\n  move 0.1, 0, -2   # strafe\nafter 1.5 s: show photon-map\n\
             after 0 iterations: screenshot\nresize 64,48\nphotons 4096\ngrid 32\nmode orbit\nzoom -1\npan 3,4\nlook 1,2\n\
             exposure -1.5\nquit\n",
        )
        .unwrap();
        let got: Vec<(When, Action, usize)> = steps.iter().map(|s| (s.when, s.action.clone(), s.line)).collect();
        assert_eq!(
            got[..5],
            [
                (When::Iterations(16), Action::Orbit { yaw_deg: 20.0, pitch_deg: -5.0 }, 3),
                (When::Now, Action::Move { right: 0.1, up: 0.0, forward: -2.0 }, 4),
                (When::Elapsed(Duration::from_millis(1500)), Action::Show(Show::PhotonMap), 5),
                (When::Iterations(0), Action::Screenshot, 6),
                (When::Now, Action::Resize { width: 64, height: 48 }, 7),
            ]
        );
        assert_eq!(
            steps[5..].iter().map(|s| s.action.clone()).collect::<Vec<_>>(),
            [
                Action::Photons(4096),
                Action::Grid(32),
                Action::Mode { orbit: true },
                Action::Zoom { steps: -1.0 },
                Action::Pan { dx: 3.0, dy: 4.0 },
                Action::Look { yaw_deg: 1.0, pitch_deg: 2.0 },
                Action::Exposure(-1.5),
                Action::Quit
            ]
        );
    }

    #[test]
    fn the_panels_actions_parse() {
        let steps = parse(
            "method path\nmethod gather\ngather trace\ngather-directions shared\ndirections 2\npasses 0\n\
             env-scale 0.5\nspeed 2\nhome\nopen scenes/my room.obj\npanel off\ndenoise on\ndenoise off\n",
        )
        .unwrap();
        assert_eq!(
            steps.into_iter().map(|s| s.action).collect::<Vec<_>>(),
            [
                Action::Method(Method::Path),
                Action::Method(Method::Gather),
                Action::Gather(GatherMethod::Trace),
                Action::GatherDirections(GatherDirections::Shared),
                Action::Directions(2),
                Action::PhotonPasses(0),
                Action::EnvScale(0.5),
                Action::Speed(2.0),
                Action::Home,
                Action::Open("scenes/my room.obj".into()),
                Action::Panel(false),
                Action::Denoise(true),
                Action::Denoise(false),
            ]
        );
    }

    #[test]
    fn errors_name_the_line_and_the_problem() {
        let cases = [
            ("quit\njump 1\n", "line 2", "unknown action 'jump'"),
            ("after 3 iterations screenshot", "line 1", "ends with ':'"),
            ("after three iterations: quit", "line 1", "not a whole number"),
            ("after 2 minutes: quit", "line 1", "unknown unit 'minutes'"),
            ("\n\nmove 1,2", "line 3", "expected R,U,F"),
            ("orbit 1,x", "line 1", "'x' is not a number"),
            ("show everything", "line 1", "full, direct, indirect or photon-map"),
            ("screenshot now", "line 1", "takes no arguments"),
            ("grid 0", "line 1", "from 1 to 1024"),
            ("resize 0,10", "line 1", "between 1 and 16384"),
            ("method raytrace", "line 1", "'gather' or 'path'"),
            ("gather fast", "line 1", "auto, raster, lists or trace"),
            ("directions 17", "line 1", "from 1 to 16"),
            ("speed 0", "line 1", "positive"),
            ("env-scale -1", "line 1", "≥ 0"),
            ("open", "line 1", "takes a scene"),
            ("panel hidden", "line 1", "'on' or 'off'"),
            ("denoise yes", "line 1", "'denoise' takes 'on' or 'off'"),
        ];
        for (text, line, message) in cases {
            let e = format!("{:#}", parse(text).unwrap_err());
            assert!(e.contains(line) && e.contains(message), "{text:?}: {e}");
            assert_eq!(e.lines().count(), 1, "{e}");
        }
    }
}
