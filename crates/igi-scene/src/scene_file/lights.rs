//! `[[light]]` entries: quad lights become emissive meshes (moved by a node if keyed), point,
//! spot and directional lights become [`Light`]s (with their tracks if keyed).

use std::ops::Range;

use glam::{Affine3A, Vec3};
use toml::Spanned;

use super::checker::Checker;
use super::keyframes::looped;
use super::schema::{AnimationSpec, LightKind, LightSpec};
use crate::animation::{AnimatedInstance, AnimatedLight, AnimationNode, RotationTrack};
use crate::error::SceneError;
use crate::light::Light;
use crate::model::{Instance, Material, Mesh, Scene};

/// Adds `[[light]]` entry `index` to `scene`: a quad light as a mesh, material and instance,
/// any other as a [`Light`], with its animation if it is keyed.
pub(super) fn add_light(
    check: &Checker,
    scene: &mut Scene,
    index: usize,
    entry: &Spanned<LightSpec>,
) -> Result<(), SceneError> {
    let span = entry.span();
    let spec = entry.get_ref();
    let path = |field: &str| format!("light[{index}].{field}");
    check.allowed_fields(&span, &spec.present(), spec.kind.fields(), path, |field| {
        format!("a {} light has no `{field}`", spec.kind.name())
    })?;
    let required = |field: &str, value: Option<[f32; 3]>| {
        value.ok_or_else(|| {
            check.error(&span, path(field), format!("a {} light needs `{field}`", spec.kind.name()))
        })
    };
    let light = match spec.kind {
        LightKind::Quad => {
            let centre = check.vector(&span, path("position"), required("position", spec.position)?)?;
            let u = check.vector(&span, path("u"), required("u", spec.u)?)?;
            let v = check.vector(&span, path("v"), required("v", spec.v)?)?;
            if u.cross(v) == Vec3::ZERO {
                return Err(check.error(&span, path("v"), "u and v must span a quad (u × v is zero)"));
            }
            let radiance = check.colour(&span, path("radiance"), required("radiance", spec.radiance)?)?;
            scene.materials.push(Material {
                name: format!("light[{index}]"),
                diffuse: Vec3::ZERO,
                emission: radiance,
                ..Material::default()
            });
            let material = scene.materials.len() as u32 - 1;
            let mesh = scene.meshes.len() as u32;
            let instance = scene.instances.len() as u32;
            match &spec.animation {
                None => {
                    scene.meshes.push(quad_mesh(format!("light[{index}]"), centre, u, v, material));
                    scene.instances.push(Instance { mesh, transform: Affine3A::IDENTITY });
                }
                Some(animation) => {
                    // A moving quad is built about the origin and placed by its node, whose
                    // translation is the keyed centre and rotation turns it about the centre.
                    let node = quad_node(check, &span, &path(""), centre, animation)?;
                    let transform = node.local(0.0);
                    scene.meshes.push(quad_mesh(format!("light[{index}]"), Vec3::ZERO, u, v, material));
                    scene.instances.push(Instance { mesh, transform });
                    let node_index = scene.animation.nodes.len() as u32;
                    scene.animation.nodes.push(node);
                    scene.animation.instances.push(AnimatedInstance {
                        instance,
                        node: node_index,
                        local: Affine3A::IDENTITY,
                    });
                }
            }
            return Ok(());
        }
        LightKind::Point => Light::Point {
            position: check.vector(&span, path("position"), required("position", spec.position)?)?,
            intensity: check.colour(&span, path("intensity"), required("intensity", spec.intensity)?)?,
        },
        LightKind::Spot => {
            let angle =
                spec.angle.ok_or_else(|| check.error(&span, path("angle"), "a spot light needs `angle`"))?;
            if !(angle > 0.0 && angle <= 180.0) {
                return Err(check.error(
                    &span,
                    path("angle"),
                    "the full cone angle must be in (0, 180] degrees",
                ));
            }
            Light::Spot {
                position: check.vector(&span, path("position"), required("position", spec.position)?)?,
                direction: check.direction(
                    &span,
                    path("direction"),
                    required("direction", spec.direction)?,
                )?,
                angle_deg: angle,
                intensity: check.colour(&span, path("intensity"), required("intensity", spec.intensity)?)?,
            }
        }
        LightKind::Directional => Light::Directional {
            direction: check.direction(&span, path("direction"), required("direction", spec.direction)?)?,
            irradiance: check.colour(&span, path("irradiance"), required("irradiance", spec.irradiance)?)?,
        },
    };
    if let Some(animation) = &spec.animation {
        let animated = light_animation(check, &span, &path(""), spec.kind, &light, animation)?;
        let light_index = scene.lights.len() as u32;
        scene.animation.lights.push(AnimatedLight { light: light_index, ..animated });
    }
    scene.lights.push(light);
    Ok(())
}

/// The node of a keyed quad light: rest at its centre, with `position` and `rotate` tracks.
fn quad_node(
    check: &Checker,
    span: &Range<usize>,
    path: &str,
    centre: Vec3,
    spec: &AnimationSpec,
) -> Result<AnimationNode, SceneError> {
    let path = format!("{path}animation.");
    check.keys(span, &path, spec, LightKind::Quad.keyed_fields(), "a quad light")?;
    let translation = check.vector_track(span, &path, spec, "position", |key| key.position)?;
    let rotation = check.vector_track(span, &path, spec, "rotate", |key| key.rotate)?;
    let [translation, rotation] = looped([translation, rotation], spec);
    Ok(AnimationNode {
        translation,
        rotation: rotation.map(RotationTrack::EulerDegrees),
        ..AnimationNode::fixed(None, Affine3A::from_translation(centre))
    })
}

/// The tracks of a keyed point, spot or directional light (its index is set by the caller).
fn light_animation(
    check: &Checker,
    span: &Range<usize>,
    path: &str,
    kind: LightKind,
    light: &Light,
    spec: &AnimationSpec,
) -> Result<AnimatedLight, SceneError> {
    let path = format!("{path}animation.");
    check.keys(span, &path, spec, kind.keyed_fields(), &format!("a {} light", kind.name()))?;
    let position = check.vector_track(span, &path, spec, "position", |key| key.position)?;
    let direction = check.track(span, &path, spec, "direction", |key, at| {
        key.direction.map(|v| check.direction(span, at, v)).transpose()
    })?;
    let power_field = if matches!(kind, LightKind::Directional) { "irradiance" } else { "intensity" };
    let power = check.track(span, &path, spec, power_field, |key, at| {
        key.intensity.or(key.irradiance).map(|v| check.colour(span, at, v)).transpose()
    })?;
    let [position, direction, power] = looped([position, direction, power], spec);
    Ok(AnimatedLight { light: 0, rest: light.clone(), node: None, position, direction, power })
}

/// Two triangles c−u−v, c+u−v, c+u+v and c−u−v, c+u+v, c−u+v: counter-clockwise seen from
/// the side u × v points to, so that is the side they face and emit to.
fn quad_mesh(name: String, centre: Vec3, u: Vec3, v: Vec3, material: u32) -> Mesh {
    Mesh {
        name,
        positions: vec![centre - u - v, centre + u - v, centre + u + v, centre - u + v],
        normals: None,
        uvs: None,
        indices: vec![[0, 1, 2], [0, 2, 3]],
        material_ids: vec![material; 2],
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::parse_str;
    use super::*;

    #[test]
    fn quad_light_faces_u_cross_v() {
        let scene = parse_str("[[light]]\ntype = \"quad\"\nposition = [0, 2, 0]\nu = [0.5, 0, 0]\nv = [0, 0, 0.25]\nradiance = [10, 10, 10]\n").unwrap();
        let mesh = &scene.meshes[0];
        let normal = mesh.triangle_normal(0);
        let expected = Vec3::X.cross(Vec3::Z);
        assert_eq!(expected, -Vec3::Y);
        for t in 0..2 {
            assert!((mesh.triangle_normal(t) - expected).length() < 1e-6);
        }
        assert!((normal - expected).length() < 1e-6);
        assert_eq!(scene.materials[0].emission, Vec3::splat(10.0));
        assert_eq!(scene.materials[0].diffuse, Vec3::ZERO);
        assert_eq!(scene.emissive_triangle_count(), 2);
    }
}
