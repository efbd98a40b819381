//! Interactive camera control: the maths behind the viewer's keys and mouse, free of any
//! window so it can be tested alone.
//!
//! The camera is kept as an eye point, a view direction given by yaw and pitch about the
//! world up vector, and a focus distance: the target is `eye + distance · forward`. Two modes
//! share that state and differ only in what a drag keeps fixed:
//!
//! - **Fly**: a drag turns the view about the eye (mouse look); WASD/QE move the eye.
//! - **Orbit**: a drag swings the eye about the target on a sphere of radius `distance`.
//!
//! In both modes WASD/QE translate eye and target together (right/left along the camera's
//! horizontal right vector, forward/back along the view direction, up/down along world up),
//! a pan slides them across the view plane, and a zoom moves the eye toward the target
//! (the distance shrinks geometrically, the target stays). Switching modes never moves the
//! camera. Pitch stays within ±[`MAX_PITCH_DEG`] so the view never lines up with world up.
//!
//! Every operation returns whether the camera changed: the caller restarts the accumulation
//! exactly then (and the photon map is kept).

use glam::Vec3;

use crate::scene::{Aabb, Camera};

/// Largest |pitch|, in degrees, of the view direction above or below the horizon.
pub const MAX_PITCH_DEG: f32 = 89.0;
/// Factor by which one zoom step (one scroll notch) scales the distance to the target.
pub const ZOOM_STEP: f32 = 0.85;
/// Speed multiplier while the speed modifier (Shift) is held.
pub const FAST_FACTOR: f32 = 4.0;
/// Radians of yaw or pitch per pixel of mouse drag.
pub const DRAG_RADIANS_PER_PIXEL: f32 = 0.005;

/// What a mouse drag does.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mode {
    /// Drag turns the view about the eye.
    #[default]
    Fly,
    /// Drag swings the eye about the target.
    Orbit,
}

impl Mode {
    pub fn name(self) -> &'static str {
        match self {
            Mode::Fly => "fly",
            Mode::Orbit => "orbit",
        }
    }
}

/// Movement keys held down: W/S forward/back, A/D left/right, E/Q up/down, Shift fast.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MoveKeys {
    pub forward: bool,
    pub back: bool,
    pub left: bool,
    pub right: bool,
    pub up: bool,
    pub down: bool,
    pub fast: bool,
}

impl MoveKeys {
    /// The held direction in camera terms (right, up, forward), each -1, 0 or 1.
    fn axes(&self) -> Vec3 {
        let axis = |pos: bool, neg: bool| pos as i32 as f32 - neg as i32 as f32;
        Vec3::new(axis(self.right, self.left), axis(self.up, self.down), axis(self.forward, self.back))
    }

    /// Whether any movement key is held (the speed modifier alone moves nothing).
    pub fn any(&self) -> bool {
        self.axes() != Vec3::ZERO
    }
}

/// The controller's state. See the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraControl {
    pub mode: Mode,
    eye: Vec3,
    /// Radians; 0 looks along `north`, positive turns toward `east` (to the right).
    yaw: f32,
    /// Radians above the horizon.
    pitch: f32,
    /// Distance from the eye to the target (focus / orbit radius), > 0.
    distance: f32,
    /// World up, unit length.
    up: Vec3,
    /// Horizontal unit vectors: the initial view direction projected on the horizon, and
    /// `north × up` (to its right).
    north: Vec3,
    east: Vec3,
    fov_y_deg: f32,
    /// Movement speed in scene units per second (before the fast factor).
    pub speed: f32,
}

impl CameraControl {
    /// Starts from `camera`; movement speed is a quarter of the scene's diagonal per second.
    /// The camera must be valid ([`Camera::validate`]).
    pub fn new(camera: &Camera, bounds: &Aabb) -> CameraControl {
        let up = camera.up.normalize();
        let offset = camera.target - camera.eye;
        let distance = offset.length();
        let forward = offset / distance;
        let north = (forward - forward.dot(up) * up).normalize();
        let east = north.cross(up);
        let pitch = forward.dot(up).clamp(-1.0, 1.0).asin().clamp(-max_pitch(), max_pitch());
        let diagonal = bounds.extent().length();
        let speed = if diagonal.is_finite() && diagonal > 0.0 { 0.25 * diagonal } else { 1.0 };
        CameraControl {
            mode: Mode::Fly,
            eye: camera.eye,
            yaw: 0.0,
            pitch,
            distance,
            up,
            north,
            east,
            fov_y_deg: camera.fov_y_deg,
            speed,
        }
    }

    /// The unit view direction: `cos(pitch)·(cos(yaw)·north + sin(yaw)·east) + sin(pitch)·up`.
    pub fn forward(&self) -> Vec3 {
        let horizontal = self.yaw.cos() * self.north + self.yaw.sin() * self.east;
        (self.pitch.cos() * horizontal + self.pitch.sin() * self.up).normalize()
    }

    /// The horizontal unit vector to the right of the view.
    pub fn right(&self) -> Vec3 {
        -self.yaw.sin() * self.north + self.yaw.cos() * self.east
    }

    pub fn target(&self) -> Vec3 {
        self.eye + self.distance * self.forward()
    }

    pub fn distance(&self) -> f32 {
        self.distance
    }

    pub fn camera(&self) -> Camera {
        Camera { eye: self.eye, target: self.target(), up: self.up, fov_y_deg: self.fov_y_deg }
    }

    /// Switches fly ↔ orbit. The camera does not move (the orbit's centre is the target).
    pub fn toggle_mode(&mut self) {
        self.mode = match self.mode {
            Mode::Fly => Mode::Orbit,
            Mode::Orbit => Mode::Fly,
        };
    }

    /// Moves eye and target by `right` along the right vector, `up` along world up and
    /// `forward` along the view direction (scene units).
    pub fn translate(&mut self, right: f32, up: f32, forward: f32) -> bool {
        let d = right * self.right() + up * self.up + forward * self.forward();
        if d == Vec3::ZERO || !d.is_finite() {
            return false;
        }
        self.eye += d;
        true
    }

    /// Held movement keys for `dt` seconds: a displacement of `speed · dt` (times
    /// [`FAST_FACTOR`] with the speed modifier) along the held directions, normalised so
    /// diagonals are not faster.
    pub fn fly(&mut self, keys: &MoveKeys, dt: f32) -> bool {
        let axes = keys.axes();
        if axes == Vec3::ZERO || dt <= 0.0 {
            return false;
        }
        let step = self.speed * dt * if keys.fast { FAST_FACTOR } else { 1.0 };
        let d = axes.normalize() * step;
        self.translate(d.x, d.y, d.z)
    }

    /// Turns the view direction by `yaw` radians to the right and `pitch` up, keeping the eye.
    pub fn look(&mut self, yaw: f32, pitch: f32) -> bool {
        self.turn(yaw, pitch)
    }

    /// Turns the view direction like [`look`](Self::look) but keeps the target: the eye
    /// swings about it (turning right moves the eye to the left around the target).
    pub fn orbit(&mut self, yaw: f32, pitch: f32) -> bool {
        let target = self.target();
        let changed = self.turn(yaw, pitch);
        self.eye = target - self.distance * self.forward();
        changed
    }

    fn turn(&mut self, yaw: f32, pitch: f32) -> bool {
        if !(yaw.is_finite() && pitch.is_finite()) {
            return false;
        }
        let before = (self.yaw, self.pitch);
        self.yaw = (self.yaw + yaw).rem_euclid(std::f32::consts::TAU);
        self.pitch = (self.pitch + pitch).clamp(-max_pitch(), max_pitch());
        (self.yaw, self.pitch) != before
    }

    /// A mouse drag of `(dx, dy)` pixels (x right, y down): mouse look in fly mode, orbit in
    /// orbit mode. Dragging right turns the view right, dragging down turns it down.
    pub fn drag(&mut self, dx: f32, dy: f32) -> bool {
        let (yaw, pitch) = (dx * DRAG_RADIANS_PER_PIXEL, -dy * DRAG_RADIANS_PER_PIXEL);
        match self.mode {
            Mode::Fly => self.look(yaw, pitch),
            Mode::Orbit => self.orbit(yaw, pitch),
        }
    }

    /// Slides eye and target across the view plane so that the point at the target follows
    /// a drag of `(dx, dy)` pixels in a viewport `viewport_height` pixels tall.
    pub fn pan(&mut self, dx: f32, dy: f32, viewport_height: f32) -> bool {
        if viewport_height <= 0.0 {
            return false;
        }
        // Scene units per pixel at the target's depth.
        let unit = 2.0 * self.distance * (0.5 * self.fov_y_deg.to_radians()).tan() / viewport_height;
        let (right, forward) = (self.right(), self.forward());
        let view_up = right.cross(forward);
        let d = (-dx * right + dy * view_up) * unit;
        if d == Vec3::ZERO || !d.is_finite() {
            return false;
        }
        self.eye += d;
        true
    }

    /// Moves the eye toward the target: the distance is scaled by [`ZOOM_STEP`]^steps
    /// (positive steps zoom in; scroll notches).
    pub fn zoom(&mut self, steps: f32) -> bool {
        let target = self.target();
        let distance = (self.distance * ZOOM_STEP.powf(steps)).max(1e-6);
        if !distance.is_finite() || distance == self.distance {
            return false;
        }
        self.distance = distance;
        self.eye = target - distance * self.forward();
        true
    }
}

fn max_pitch() -> f32 {
    MAX_PITCH_DEG.to_radians()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::passes::frame::view_projection;
    use glam::Vec2;

    fn cornell_camera() -> Camera {
        Camera { eye: Vec3::new(0.0, 0.0, 3.9), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 39.3077 }
    }

    fn unit_box() -> Aabb {
        Aabb { min: Vec3::splat(-1.0), max: Vec3::splat(1.0) }
    }

    fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
        (a - b).length() <= tol
    }

    #[test]
    fn starting_camera_is_reproduced() {
        let tilted = Camera {
            eye: Vec3::new(1.0, 2.0, 3.0),
            target: Vec3::new(-0.5, 0.25, 0.0),
            up: Vec3::new(0.0, 2.0, 0.0),
            fov_y_deg: 50.0,
        };
        for cam in [cornell_camera(), tilted] {
            let c = CameraControl::new(&cam, &unit_box()).camera();
            assert!(close(c.eye, cam.eye, 1e-6) && close(c.target, cam.target, 1e-5), "{c:?} vs {cam:?}");
            assert!(close(c.up, cam.up.normalize(), 1e-6) && c.fov_y_deg == cam.fov_y_deg);
        }
    }

    #[test]
    fn switching_modes_never_moves_the_camera() {
        let mut c = CameraControl::new(&cornell_camera(), &unit_box());
        c.orbit(0.3, 0.2);
        let before = c.camera();
        c.toggle_mode();
        assert_eq!((c.mode, c.camera()), (Mode::Orbit, before));
        c.toggle_mode();
        assert_eq!((c.mode, c.camera()), (Mode::Fly, before));
    }

    #[test]
    fn flying_moves_eye_and_target_at_the_set_speed_and_faster_with_shift() {
        let mut c = CameraControl::new(&cornell_camera(), &unit_box());
        c.speed = 2.0;
        let start = c.camera();
        assert!(c.fly(&MoveKeys { forward: true, ..Default::default() }, 0.5));
        // Forward is -z: one scene unit in half a second at 2 units/s.
        let moved = c.camera();
        assert!(close(moved.eye, start.eye - Vec3::Z, 1e-5) && close(moved.target, start.target - Vec3::Z, 1e-5));
        assert!(c.fly(&MoveKeys { right: true, up: true, fast: true, ..Default::default() }, 0.5));
        // Diagonal at 4× speed: 4 units along (x + y)/√2.
        let d = c.camera().eye - moved.eye;
        assert!(close(d, Vec3::new(1.0, 1.0, 0.0).normalize() * 4.0, 1e-4), "{d}");
    }

    #[test]
    fn opposite_keys_or_the_modifier_alone_do_not_move_and_report_no_change() {
        let mut c = CameraControl::new(&cornell_camera(), &unit_box());
        let before = c.clone();
        let keys = MoveKeys { forward: true, back: true, left: true, right: true, fast: true, ..Default::default() };
        assert!(!keys.any() && !c.fly(&keys, 1.0));
        assert!(!c.fly(&MoveKeys { fast: true, ..Default::default() }, 1.0));
        assert!(!c.fly(&MoveKeys { forward: true, ..Default::default() }, 0.0));
        assert!(!c.look(0.0, 0.0) && !c.zoom(0.0) && !c.pan(0.0, 0.0, 64.0) && !c.translate(0.0, 0.0, 0.0));
        assert_eq!(c, before);
    }

    #[test]
    fn looking_right_keeps_the_eye_and_turns_toward_plus_x() {
        let mut c = CameraControl::new(&cornell_camera(), &unit_box());
        assert!(c.look(90f32.to_radians(), 0.0));
        let cam = c.camera();
        assert!(close(cam.eye, Vec3::new(0.0, 0.0, 3.9), 1e-6));
        assert!(close(c.forward(), Vec3::X, 1e-6), "{}", c.forward());
        // Dragging right in fly mode is the same turn.
        let mut d = CameraControl::new(&cornell_camera(), &unit_box());
        assert!(d.drag(90f32.to_radians() / DRAG_RADIANS_PER_PIXEL, 0.0));
        assert!(close(d.forward(), Vec3::X, 1e-5));
    }

    #[test]
    fn orbiting_keeps_target_and_distance_and_a_full_turn_returns() {
        let mut c = CameraControl::new(&cornell_camera(), &unit_box());
        c.toggle_mode();
        let start = c.camera();
        assert!(c.drag(90f32.to_radians() / DRAG_RADIANS_PER_PIXEL, 0.0));
        let cam = c.camera();
        // Turning the view right swings the eye to the left of the target (-x).
        assert!(close(cam.target, start.target, 1e-5) && close(cam.eye, Vec3::new(-3.9, 0.0, 0.0), 1e-5), "{cam:?}");
        assert!(((cam.eye - cam.target).length() - 3.9).abs() < 1e-5);
        for _ in 0..3 {
            c.orbit(90f32.to_radians(), 0.0);
        }
        assert!(close(c.camera().eye, start.eye, 1e-4) && close(c.camera().target, start.target, 1e-5));
        // Dragging down turns the view down: the eye rises above the target.
        c.drag(0.0, 100.0);
        assert!(c.camera().eye.y > 0.0 && c.forward().y < 0.0);
    }

    #[test]
    fn pitch_stops_short_of_the_poles_so_the_camera_stays_valid() {
        let mut c = CameraControl::new(&cornell_camera(), &unit_box());
        assert!(c.look(0.0, 3.0));
        assert!((c.forward().dot(Vec3::Y).asin().to_degrees() - MAX_PITCH_DEG).abs() < 1e-3);
        assert!(!c.look(0.0, 1.0), "already at the limit: nothing changes");
        c.camera().validate().unwrap();
        c.toggle_mode();
        c.orbit(0.0, -10.0);
        assert!((c.forward().dot(Vec3::Y).asin().to_degrees() + MAX_PITCH_DEG).abs() < 1e-3);
        c.camera().validate().unwrap();
    }

    #[test]
    fn zoom_keeps_the_target_and_scales_the_distance_geometrically() {
        let mut c = CameraControl::new(&cornell_camera(), &unit_box());
        let start = c.camera();
        assert!(c.zoom(2.0));
        assert!((c.distance() - 3.9 * ZOOM_STEP * ZOOM_STEP).abs() < 1e-5);
        assert!(close(c.camera().target, start.target, 1e-5) && c.camera().eye.z < start.eye.z);
        assert!(c.zoom(-2.0));
        assert!(close(c.camera().eye, start.eye, 1e-5));
    }

    #[test]
    fn panning_makes_the_target_follow_the_cursor() {
        let (w, h) = (64u32, 48u32);
        let mut c = CameraControl::new(&cornell_camera(), &unit_box());
        c.look(0.4, -0.2);
        let point = c.target();
        let pixel = |cam: &Camera| {
            let ndc = view_projection(cam, w, h, 0.01, Vec2::ZERO).project_point3(point);
            Vec2::new((ndc.x + 1.0) * 0.5 * w as f32, (1.0 - ndc.y) * 0.5 * h as f32)
        };
        let before = pixel(&c.camera());
        assert!(c.pan(5.0, -3.0, h as f32));
        let after = pixel(&c.camera());
        assert!((after - before - Vec2::new(5.0, -3.0)).length() < 1e-3, "{before} → {after}");
        // The view direction did not change.
        assert!(close((c.target() - c.camera().eye).normalize(), c.forward(), 1e-6));
    }
}
