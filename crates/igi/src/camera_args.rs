//! [`CameraArgs`]: the camera options `render` and `bench` share (each replaces one field of the
//! scene's camera), and the `x,y,z` vectors they and other options take.

use anyhow::Result;
use glam::Vec3;
use igi_render::{PreparedScene, start_camera};
use igi_scene::Camera;

/// Parses `x,y,z` into a vector (for `--camera-position` and friends).
pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!("{s:?} is not three comma-separated numbers x,y,z"));
    };
    let num = |v: &str| v.parse::<f32>().ok().filter(|f| f.is_finite());
    match (num(x), num(y), num(z)) {
        (Some(x), Some(y), Some(z)) => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("{s:?} is not three finite numbers x,y,z")),
    }
}

/// `x,y,z`, as [`parse_vec3`] reads it.
fn vec3_text(v: Vec3) -> String {
    format!("{},{},{}", v.x, v.y, v.z)
}

/// The camera options shared by `render` and `bench`: each replaces one field of the scene's
/// camera (or of a default camera framing the scene).
#[derive(Debug, Default, clap::Args)]
pub struct CameraArgs {
    /// Start from the scene's view NAME (a scene file's [[view]], a glTF camera; `igi info`
    /// lists them); the options below replace its fields.
    #[arg(long, value_name = "NAME")]
    pub view: Option<String>,
    /// Camera position x,y,z (default: the scene's camera, else inside an interior at eye
    /// height, or a view of an object from a little above its front).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub camera_position: Option<Vec3>,
    /// Camera target x,y,z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub camera_target: Option<Vec3>,
    /// Camera up vector x,y,z.
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    pub camera_up: Option<Vec3>,
    /// Vertical field of view in degrees.
    #[arg(long)]
    pub fov: Option<f32>,
}

impl CameraArgs {
    /// True if any of these options is given: the camera differs from the scene's start.
    pub fn asks(&self) -> bool {
        self.view.is_some()
            || self.camera_position.is_some()
            || self.camera_target.is_some()
            || self.camera_up.is_some()
            || self.fov.is_some()
    }

    /// The camera these options ask for ([`CameraArgs::resolve`]), `None` if they ask for
    /// none (the scene's start camera) or for one that frames no image.
    pub fn requested(&self, scene: &PreparedScene) -> Option<Camera> {
        self.asks().then(|| self.resolve(scene).ok()).flatten()
    }

    /// The camera of `--view`, else the one the scene starts with ([`start_camera`]: its own,
    /// else where a person would stand), with the given fields replaced; an error naming the
    /// flag for an unknown view or a camera that frames no image ([`Camera::check`], the
    /// scene files' check).
    pub fn resolve(&self, scene: &PreparedScene) -> Result<Camera> {
        let mut camera = match &self.view {
            None => start_camera(scene),
            Some(name) => match scene.views().iter().find(|v| &v.name == name) {
                Some(view) => view.camera,
                None if scene.views().is_empty() => anyhow::bail!(
                    "--view {name:?}: the scene has no views (a scene file names them in [[view]] tables)"
                ),
                None => {
                    let names: Vec<String> = scene.views().iter().map(|v| format!("{:?}", v.name)).collect();
                    anyhow::bail!("--view {name:?}: the scene has no such view; it has {}", names.join(", "))
                }
            },
        };
        camera.position = self.camera_position.unwrap_or(camera.position);
        camera.target = self.camera_target.unwrap_or(camera.target);
        camera.up = self.camera_up.unwrap_or(camera.up);
        camera.fov_y_deg = self.fov.unwrap_or(camera.fov_y_deg);
        camera.check().map_err(|defect| {
            let (flag, value) = match defect.field {
                "position" => ("--camera-position", vec3_text(camera.position)),
                "target" => ("--camera-target", vec3_text(camera.target)),
                "up" => ("--camera-up", vec3_text(camera.up)),
                _ => ("--fov", camera.fov_y_deg.to_string()),
            };
            anyhow::anyhow!("{flag} {value}: {}", defect.problem)
        })?;
        Ok(camera)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    /// The camera options alone, as a command line would give them.
    #[derive(Debug, Parser)]
    struct Line {
        #[command(flatten)]
        camera: CameraArgs,
    }

    #[test]
    fn vec3_arguments() {
        assert_eq!(parse_vec3("1,-2.5, 3e1"), Ok(Vec3::new(1.0, -2.5, 30.0)));
        assert!(parse_vec3("1,2").is_err());
        assert!(parse_vec3("1,2,x").is_err());
        assert!(parse_vec3("1,2,inf").is_err());
    }

    fn camera_error(flags: &[&str]) -> String {
        let line = Line::try_parse_from(std::iter::once("igi").chain(flags.iter().copied()));
        let scene = PreparedScene::new(igi_scene::load_named("cornell-box").unwrap());
        line.expect("valid command line").camera.resolve(&scene).unwrap_err().to_string()
    }

    #[test]
    fn cameras_that_frame_no_image_are_refused_naming_the_flag() {
        assert_eq!(camera_error(&["--camera-up", "0,0,0"]), "--camera-up 0,0,0: must not be zero");
        // The Cornell box's camera looks along -z.
        assert_eq!(
            camera_error(&["--camera-up", "0,0,-2"]),
            "--camera-up 0,0,-2: must not be parallel to the view direction"
        );
        let err = camera_error(&["--camera-position", "1,2,3", "--camera-target", "1,2,3"]);
        assert!(err.starts_with("--camera-target 1,2,3: must lie a finite, non-zero distance"), "{err}");
        let err = camera_error(&["--camera-position", "3e38,0,0", "--camera-target", "-3e38,0,0"]);
        assert!(err.starts_with("--camera-target -300000000000000000000000000000000000000,0,0"), "{err}");
        assert!(camera_error(&["--fov", "180"]).starts_with("--fov 180: "));
        assert!(camera_error(&["--fov", "NaN"]).starts_with("--fov NaN: "));
    }
}
