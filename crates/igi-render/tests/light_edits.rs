//! A viewer's light edits (`ScenePose::lights`): a prepared scene posed with an edit renders
//! exactly the frame of a fresh build of the scene changed by hand (the light moved, its
//! power scaled, the lamp's material brighter and redder), and posing it without the edits
//! gives the unedited frame back.

use glam::{Affine3A, Vec3};
use igi_render::{FrameRenderer, FrameSettings, FrameState, LightEdit, LightId, PreparedScene, ScenePose};
use igi_scene::{Light, Scene, builtin};

/// The still animated room (its animation dropped, so a fresh build stands the same).
fn room() -> Scene {
    Scene { animation: Default::default(), ..builtin("animated-room").unwrap() }
}

fn frame(scene: &mut PreparedScene, pose: ScenePose) -> Vec<Vec3> {
    let settings =
        FrameSettings { width: 64, height: 48, aa: 1, clamp: 0.1, seed: 5, ..FrameSettings::default() };
    let camera = *scene.camera().unwrap();
    let frame = FrameState { pose, ..FrameState::new(camera, settings) };
    let out = FrameRenderer::new(2).render(scene, &frame, &|_, _| {}).unwrap();
    out.image.film().unwrap().pixels().to_vec()
}

#[test]
fn edited_lights_render_as_a_scene_changed_by_hand() {
    let mut edited = PreparedScene::new(room());
    let sources = edited.light_sources();
    let names: Vec<&str> = sources.iter().map(|(_, n)| n.as_str()).collect();
    assert_eq!(names, ["point light 0", "lamp"], "the orbiting point light and the lamp's material");
    let LightId::Emissive(lamp) = sources[1].0 else { panic!("{sources:?}") };

    let offset = Vec3::new(-0.5, 0.3, 0.2);
    let edits = vec![
        LightEdit {
            light: LightId::Punctual(0),
            power: Vec3::new(2.0, 1.0, 0.5),
            transform: Affine3A::from_translation(offset),
        },
        LightEdit { power: Vec3::new(1.5, 0.5, 0.5), ..LightEdit::none(LightId::Emissive(lamp)) },
    ];
    let pose = ScenePose { lights: edits, ..ScenePose::default() };

    let mut by_hand = room();
    let Light::Point { position, intensity } = by_hand.lights[0] else { panic!() };
    by_hand.lights[0] =
        Light::Point { position: position + offset, intensity: intensity * Vec3::new(2.0, 1.0, 0.5) };
    by_hand.materials[lamp as usize].emission *= Vec3::new(1.5, 0.5, 0.5);
    let mut fresh = PreparedScene::new(by_hand);

    let original = frame(&mut edited, ScenePose::default());
    let with_edits = frame(&mut edited, pose.clone());
    assert_eq!(
        with_edits,
        frame(&mut fresh, ScenePose::default()),
        "the edited frame is the changed scene's"
    );
    assert_ne!(with_edits, original);
    assert_eq!(edited.lights(), fresh.lights());
    assert_eq!(frame(&mut edited, ScenePose::default()), original, "without the edits, as before");
}

#[test]
fn a_light_turned_off_leaves_the_rest_and_all_off_is_black() {
    let mut scene = PreparedScene::new(room());
    let off: Vec<LightEdit> = scene
        .light_sources()
        .into_iter()
        .map(|(id, _)| LightEdit { power: Vec3::ZERO, ..LightEdit::none(id) })
        .collect();
    let dark = frame(&mut scene, ScenePose { lights: off.clone(), ..ScenePose::default() });
    assert!(dark.iter().all(|p| *p == Vec3::ZERO), "every light off: black");
    let lamp_only = frame(&mut scene, ScenePose { lights: off[..1].to_vec(), ..ScenePose::default() });
    let both = frame(&mut scene, ScenePose::default());
    let sum = |f: &[Vec3]| f.iter().map(|p| f64::from(p.element_sum())).sum::<f64>();
    assert!(sum(&lamp_only) > 0.0 && sum(&lamp_only) < sum(&both));
}
