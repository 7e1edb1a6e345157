//! `igi info`: what a scene contains (geometry, materials, textures, lights, bounds, camera)
//! and what its loading cost and repaired; the camera renders start with (the scene's, or the
//! default one, as a scene-file snippet) and the default light they add, if any.

use anyhow::{Context, Result};
use clap::Args;
use glam::Vec3;
use igi_render::{PreparedScene, add_default_light, start_camera};
use igi_scene::{Environment, Light, Scene};
use std::time::Instant;

/// Arguments of `igi info`.
#[derive(Debug, Args)]
#[command(after_help = crate::cli::scenes_help())]
pub struct InfoArgs {
    /// Built-in scene (listed below) or scene file (.obj, .ply, .gltf, .glb, .toml).
    pub scene: String,
}

fn v(p: Vec3) -> String {
    format!("({}, {}, {})", p.x, p.y, p.z)
}

/// Emissive triangles of all instances and their total world-space area.
fn emissive(scene: &Scene) -> (usize, f32) {
    let (mut count, mut area) = (0, 0.0);
    for inst in &scene.instances {
        let Some(mesh) = scene.meshes.get(inst.mesh as usize) else { continue };
        for (tri, &m) in mesh.indices.iter().zip(&mesh.material_ids) {
            if scene.materials.get(m as usize).is_some_and(|m| m.is_emissive()) {
                let [a, b, c] = tri.map(|i| inst.transform.transform_point3(mesh.positions[i as usize]));
                count += 1;
                area += 0.5 * (b - a).cross(c - a).length();
            }
        }
    }
    (count, area)
}

/// Runs `igi info`.
pub fn run(args: &InfoArgs) -> Result<()> {
    let t = Instant::now();
    let (scene, report) = igi_scene::load_named_with_report(&args.scene).context("cannot load scene")?;
    let load = t.elapsed();

    let instanced = scene.triangle_count();
    let stored: usize = scene.meshes.iter().map(|m| m.indices.len()).sum();
    let with_normals = scene.meshes.iter().filter(|m| m.normals.is_some()).count();
    let with_uvs = scene.meshes.iter().filter(|m| m.uvs.is_some()).count();
    let (mut point, mut spot, mut directional) = (0, 0, 0);
    for light in &scene.lights {
        match light {
            Light::Point { .. } => point += 1,
            Light::Spot { .. } => spot += 1,
            Light::Directional { .. } => directional += 1,
        }
    }
    let (emissive_tris, emissive_area) = emissive(&scene);
    let textured = scene.materials.iter().filter(|m| m.diffuse_texture.is_some()).count();
    let bounds = scene.bounds();

    outln!("scene        {}", args.scene);
    outln!("triangles    {instanced} ({stored} stored in meshes)");
    outln!(
        "meshes       {} ({with_normals} with normals, {with_uvs} with texture coordinates)",
        scene.meshes.len()
    );
    outln!("instances    {}", scene.instances.len());
    let procedural = scene.materials.iter().filter(|m| m.shader.is_some()).count();
    let bumped =
        scene.materials.iter().filter(|m| m.bump_texture.is_some() || m.normal_texture.is_some()).count();
    outln!(
        "materials    {} ({textured} with a diffuse texture, {bumped} with a bump or normal map, \
         {procedural} procedural)",
        scene.materials.len()
    );
    outln!(
        "textures     {} ({:.1} MiB of texels, about a third more with mipmaps)",
        scene.textures.len(),
        scene.texel_bytes() as f64 / f64::from(1 << 20)
    );
    outln!(
        "lights       {point} point, {spot} spot, {directional} directional; \
         {emissive_tris} emissive triangles (area {emissive_area})"
    );
    match &scene.environment {
        Some(Environment::Constant { radiance }) => outln!("environment  constant sky {}", v(*radiance)),
        Some(Environment::Map { texture, intensity, rotation_deg }) => outln!(
            "environment  {} × {intensity}, turned {rotation_deg} deg",
            scene.textures.get(*texture as usize).map_or("(missing image)", |t| t.name.as_str())
        ),
        None => outln!("environment  none (rays leaving the scene see black)"),
    }
    let animation = &scene.animation;
    if animation.is_empty() {
        outln!("animation    none");
    } else {
        outln!(
            "animation    {} instances and {} lights move, {} nodes, longest cycle {:.3} s",
            animation.instances.len(),
            animation.lights.len(),
            animation.nodes.len(),
            animation.duration()
        );
    }
    if bounds.is_empty() {
        outln!("bounds       empty");
    } else {
        outln!("bounds       {} .. {} (diagonal {})", v(bounds.min), v(bounds.max), bounds.diagonal());
    }
    outln!("load time    {:.3} s", load.as_secs_f64());
    outln!("degenerate   {} triangles dropped", report.degenerate_dropped);
    outln!("warnings     {}", report.warnings.len());
    for w in &report.warnings {
        outln!("  {w}");
    }
    let own_camera = scene.camera.is_some();
    let t = Instant::now();
    let mut prepared = PreparedScene::new(scene);
    let build = t.elapsed();
    let g = prepared.geometry_bytes();
    let per = |bytes: usize| bytes as f64 / g.stored_triangles.max(1) as f64;
    outln!(
        "geometry     prepared in {:.3} s (BVH build included); {:.1} MiB, per stored triangle \
         {:.1} B: {:.1} B vertices and indices, {:.1} B BVH, {:.1} B normals, texture \
         coordinates and materials",
        build.as_secs_f64(),
        g.total() as f64 / f64::from(1 << 20),
        per(g.total()),
        per(g.triangles),
        per(g.bvh),
        per(g.shading)
    );
    let default_light = add_default_light(&mut prepared, true, None);
    let c = start_camera(&prepared);
    if own_camera {
        outln!("camera       the scene's:");
    } else {
        outln!("camera       none in the scene; renders start here (paste into a scene file to keep it):");
    }
    for line in c.scene_file_snippet().lines() {
        outln!("  {line}");
    }
    let names: Vec<String> = prepared.views().iter().map(|view| format!("{:?}", view.name)).collect();
    outln!(
        "views        {}",
        if names.is_empty() { "none ([[view]] in a scene file)".into() } else { names.join(", ") }
    );
    outln!("default light {}", default_light.as_deref().unwrap_or("none (the scene's own lights show it)"));
    Ok(())
}
