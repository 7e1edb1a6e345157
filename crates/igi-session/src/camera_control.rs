//! [`CameraController`]: the viewers' camera, flown with WASD/QE and mouse look or orbited
//! around a target by dragging, with +Y up (the convention of igi-scene's `Camera`).
//!
//! The view direction is kept as yaw (about +Y, 0 looking down −Z) and pitch (above the
//! horizon), so a drag turns the view by an angle proportional to its length and the horizon
//! stays level. Pitch stops short of the poles, where yaw is undefined.
//!
//! Drag rates are tied to the image, not to a constant per pixel: looking around (fly), the
//! scene moves under the pointer as far as the pointer moved (one pixel at the image centre
//! spans 2·tan(fov/2)/height radians); orbiting, a drag over the image's height turns once
//! around the target, the rate of three.js' OrbitControls and, on a 900-pixel viewport, of
//! Blender's default 0.4° per pixel.

use crate::input::{Button, CameraMode, Input, Key};
use glam::Vec3;
use igi_scene::Camera;

/// Radians an orbit turns per drag over the image's height: once around.
const ORBIT_PER_HEIGHT: f32 = std::f32::consts::TAU;
/// Largest pitch, just short of straight up or down.
const MAX_PITCH: f32 = 89.0 * std::f32::consts::PI / 180.0;
/// Factor of fly speed or orbit distance per scroll notch.
const SCROLL_FACTOR: f32 = 1.1;

/// The camera state of a viewer.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraController {
    mode: CameraMode,
    position: Vec3,
    yaw: f32,
    pitch: f32,
    /// Orbit target distance along the view direction (also kept while flying, so switching
    /// to orbit turns about what was in front of the eye).
    distance: f32,
    /// Fly speed in scene units per second.
    speed: f32,
    fov_y_deg: f32,
    held: [bool; 6],
}

fn forward_of(yaw: f32, pitch: f32) -> Vec3 {
    Vec3::new(pitch.cos() * yaw.sin(), pitch.sin(), -pitch.cos() * yaw.cos())
}

impl CameraController {
    /// Starts at `camera`, in fly mode, with a fly speed of `speed` units per second (a tenth
    /// of the scene's size per second is a good start).
    pub fn new(camera: &Camera, speed: f32) -> Self {
        let view = camera.target - camera.position;
        let forward = view.try_normalize().unwrap_or(Vec3::NEG_Z);
        Self {
            mode: CameraMode::Fly,
            position: camera.position,
            yaw: forward.x.atan2(-forward.z),
            pitch: forward.y.clamp(-1.0, 1.0).asin().clamp(-MAX_PITCH, MAX_PITCH),
            distance: view.length().max(1e-3),
            speed: if speed.is_finite() && speed > 0.0 { speed } else { 1.0 },
            fov_y_deg: camera.fov_y_deg,
            held: [false; 6],
        }
    }

    /// The current mode.
    pub fn mode(&self) -> CameraMode {
        self.mode
    }

    /// Fly speed in units per second.
    pub fn speed(&self) -> f32 {
        self.speed
    }

    /// The unit view direction.
    pub fn forward(&self) -> Vec3 {
        forward_of(self.yaw, self.pitch)
    }

    /// The orbit target (a point `distance` ahead of the eye).
    pub fn target(&self) -> Vec3 {
        self.position + self.distance * self.forward()
    }

    /// The camera to render.
    pub fn camera(&self) -> Camera {
        Camera { position: self.position, target: self.target(), up: Vec3::Y, fov_y_deg: self.fov_y_deg }
    }

    /// True while a movement key is held (the camera moves every frame).
    pub fn is_moving(&self) -> bool {
        self.mode == CameraMode::Fly && self.held.iter().any(|&h| h)
    }

    /// Radians a drag of one pixel turns the view in an image `height` pixels high.
    fn turn_per_pixel(&self, height: u32) -> f32 {
        let height = height.max(1) as f32;
        match self.mode {
            CameraMode::Fly => 2.0 * (0.5 * self.fov_y_deg.to_radians()).tan() / height,
            CameraMode::Orbit => ORBIT_PER_HEIGHT / height,
        }
    }

    /// Applies an input to the view of an image `height` pixels high (drags are in its
    /// pixels); returns true if the view changed at once. Keys only change what is held
    /// ([`CameraController::advance`] moves the eye).
    pub fn handle(&mut self, input: &Input, height: u32) -> bool {
        match *input {
            Input::Key { key, down } => {
                self.held[key as usize] = down;
                false
            }
            Input::Drag { dx, dy, button: Button::Primary } => {
                if !(dx.is_finite() && dy.is_finite()) || (dx == 0.0 && dy == 0.0) {
                    return false;
                }
                let target = self.target();
                let turn = self.turn_per_pixel(height);
                self.yaw += dx * turn;
                self.pitch = (self.pitch - dy * turn).clamp(-MAX_PITCH, MAX_PITCH);
                if self.mode == CameraMode::Orbit {
                    // The eye moves on the sphere about the target.
                    self.position = target - self.distance * self.forward();
                }
                true
            }
            Input::Scroll { delta } if delta.is_finite() && delta != 0.0 => {
                let factor = SCROLL_FACTOR.powf(delta.clamp(-50.0, 50.0));
                match self.mode {
                    CameraMode::Fly => {
                        self.speed = (self.speed * factor).clamp(1e-6, 1e9);
                        false
                    }
                    CameraMode::Orbit => {
                        let target = self.target();
                        self.distance = (self.distance / factor).clamp(1e-4, 1e9);
                        self.position = target - self.distance * self.forward();
                        true
                    }
                }
            }
            Input::Mode { mode } => {
                self.mode = mode;
                false
            }
            _ => false,
        }
    }

    /// Moves the eye by the held keys over `dt` seconds; returns true if it moved.
    pub fn advance(&mut self, dt: f32) -> bool {
        if !(self.is_moving() && dt.is_finite() && dt > 0.0) {
            return false;
        }
        let forward = self.forward();
        let right = forward.cross(Vec3::Y).normalize_or(Vec3::X);
        let axis = |plus: Key, minus: Key| {
            f32::from(self.held[plus as usize]) - f32::from(self.held[minus as usize])
        };
        let step =
            forward * axis(Key::W, Key::S) + right * axis(Key::D, Key::A) + Vec3::Y * axis(Key::E, Key::Q);
        if step == Vec3::ZERO {
            return false;
        }
        self.position += step.normalize() * self.speed * dt;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn start() -> CameraController {
        let camera = Camera {
            position: Vec3::new(0.0, 1.0, 3.0),
            target: Vec3::new(0.0, 1.0, 0.0),
            up: Vec3::Y,
            fov_y_deg: 40.0,
        };
        CameraController::new(&camera, 2.0)
    }

    /// Image height of the tests' drags.
    const H: u32 = 480;

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-4
    }

    #[test]
    fn starts_at_the_scene_camera() {
        let c = start();
        let camera = c.camera();
        assert!(close(camera.position, Vec3::new(0.0, 1.0, 3.0)));
        assert!(close(camera.target, Vec3::new(0.0, 1.0, 0.0)));
    }

    #[test]
    fn wasd_moves_along_the_view_at_the_fly_speed() {
        let mut c = start();
        c.handle(&Input::Key { key: Key::W, down: true }, H);
        assert!(c.advance(0.5));
        assert!(close(c.camera().position, Vec3::new(0.0, 1.0, 2.0)), "{:?}", c.camera());
        c.handle(&Input::Key { key: Key::W, down: false }, H);
        c.handle(&Input::Key { key: Key::D, down: true }, H);
        c.advance(1.0);
        assert!(close(c.camera().position, Vec3::new(2.0, 1.0, 2.0)), "right is +X looking down −Z");
        c.handle(&Input::Key { key: Key::D, down: false }, H);
        c.handle(&Input::Key { key: Key::E, down: true }, H);
        c.advance(0.25);
        assert!(close(c.camera().position, Vec3::new(2.0, 1.5, 2.0)));
        c.handle(&Input::Key { key: Key::E, down: false }, H);
        assert!(!c.advance(1.0), "nothing held, nothing moves");
        // Scrolling doubles the speed after log(2)/log(1.1) notches.
        c.handle(&Input::Scroll { delta: 2f32.ln() / 1.1f32.ln() }, H);
        assert!((c.speed() - 4.0).abs() < 1e-4);
    }

    #[test]
    fn mouse_look_turns_about_the_eye_and_keeps_the_horizon() {
        let mut c = start();
        let quarter = std::f32::consts::FRAC_PI_2 / c.turn_per_pixel(H);
        assert!(c.handle(&Input::Drag { dx: quarter, dy: 0.0, button: Button::Primary }, H));
        assert!(close(c.forward(), Vec3::X), "dragging right turns right: {}", c.forward());
        assert!(close(c.camera().position, Vec3::new(0.0, 1.0, 3.0)));
        c.handle(&Input::Drag { dx: 0.0, dy: -100_000.0, button: Button::Primary }, H);
        assert!(c.forward().y < 1.0 && c.forward().y > 0.99, "pitch stops short of the pole");
    }

    /// Where `point` projects in a 640 x [`H`] image of `camera`, in pixels.
    fn project(camera: &Camera, point: Vec3) -> glam::Vec2 {
        let forward = (camera.target - camera.position).normalize();
        let right = forward.cross(camera.up).normalize();
        let up = right.cross(forward);
        let v = point - camera.position;
        let focal = 0.5 * H as f32 / (0.5 * camera.fov_y_deg.to_radians()).tan();
        let (x, y, z) = (v.dot(right), v.dot(up), v.dot(forward));
        glam::Vec2::new(320.0 + focal * x / z, 0.5 * H as f32 - focal * y / z)
    }

    #[test]
    fn looking_around_moves_the_scene_as_far_as_the_pointer() {
        // The measure: a 72-pixel drag turned the view about 280 pixels. Now the
        // point at the image centre moves 72 pixels (to the left: the view turns right).
        for (dx, dy) in [(72.0, 0.0), (0.0, 72.0), (-20.0, 30.0)] {
            let mut c = start();
            let centre = c.target();
            c.handle(&Input::Drag { dx, dy, button: Button::Primary }, H);
            let moved = project(&c.camera(), centre) - glam::Vec2::new(320.0, 0.5 * H as f32);
            assert!((moved + glam::Vec2::new(dx, dy)).length() < 1.5, "drag ({dx}, {dy}) moved it {moved}");
        }
    }

    #[test]
    fn orbit_keeps_the_target_and_scroll_changes_the_distance() {
        let mut c = start();
        c.handle(&Input::Mode { mode: CameraMode::Orbit }, H);
        let target = c.target();
        // A quarter of the image's height is a quarter turn.
        c.handle(&Input::Drag { dx: 0.25 * H as f32, dy: 0.0, button: Button::Primary }, H);
        assert!(close(c.target(), target));
        assert!(close(c.camera().position, Vec3::new(-3.0, 1.0, 0.0)), "{}", c.camera().position);
        c.handle(&Input::Drag { dx: 0.0, dy: 80.0, button: Button::Primary }, H);
        assert!(close(c.target(), target));
        assert!(((c.camera().position - target).length() - 3.0).abs() < 1e-4);
        c.handle(&Input::Scroll { delta: 1.0 }, H);
        assert!(((c.camera().position - target).length() - 3.0 / 1.1).abs() < 1e-4);
        assert!(close(c.target(), target));
        // Keys do not move an orbiting camera.
        c.handle(&Input::Key { key: Key::W, down: true }, H);
        assert!(!c.advance(1.0));
    }

    #[test]
    fn bad_numbers_change_nothing() {
        let mut c = start();
        let before = c.clone();
        assert!(!c.handle(&Input::Drag { dx: f32::NAN, dy: 1.0, button: Button::Primary }, H));
        assert!(!c.handle(&Input::Scroll { delta: f32::INFINITY }, H));
        assert_eq!(c, before);
    }
}
