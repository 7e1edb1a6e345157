//! The node forest: world transforms, the instances of meshes on nodes, and the
//! [`AnimationNode`]s of nodes that move or sit under one that does.

use glam::{Affine3A, Mat4, Quat, Vec3, Vec4};

use super::channels::NodeTracks;
use super::loader::Loader;
use crate::animation::{AnimatedInstance, AnimationNode, RotationTrack, Track};
use crate::error::{Location, SceneError};
use crate::model::Instance;

/// glTF node transform as a matrix, with the rotation quaternion normalised (exporters write
/// slightly non-unit ones, e.g. the Cameras sample).
fn local_transform(node: &gltf::Node) -> Option<Mat4> {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => Some(Mat4::from_cols_array_2d(&matrix)),
        gltf::scene::Transform::Decomposed { translation, rotation, scale } => {
            let rotation = Quat::from_vec4(Vec4::from(rotation).try_normalize()?);
            Some(Mat4::from_scale_rotation_translation(Vec3::from(scale), rotation, Vec3::from(translation)))
        }
    }
}

impl Loader<'_> {
    /// Visits the scene's node forest depth-first with an explicit stack (a hostile file can
    /// nest nodes deeper than the call stack) and rejects cycles and shared children.
    pub(super) fn walk(&mut self, document: &gltf::Document) -> Result<(), SceneError> {
        let roots: Vec<gltf::Node> = match document.default_scene().or_else(|| document.scenes().next()) {
            Some(scene) => scene.nodes().collect(),
            None => {
                let mut is_child = vec![false; document.nodes().count()];
                for node in document.nodes() {
                    for child in node.children() {
                        is_child[child.index()] = true;
                    }
                }
                document.nodes().filter(|n| !is_child[n.index()]).collect()
            }
        };
        let mut visited = vec![false; document.nodes().count()];
        // (node, its parent's world transform at rest, its parent's animation node if it moves)
        let mut stack: Vec<(gltf::Node, Mat4, Option<u32>)> =
            roots.into_iter().rev().map(|n| (n, Mat4::IDENTITY, None)).collect();
        while let Some((node, parent, parent_node)) = stack.pop() {
            let at = || Location::Json(format!("nodes[{}]", node.index()));
            if std::mem::replace(&mut visited[node.index()], true) {
                return Err(SceneError::invalid(
                    self.file,
                    at(),
                    "node is reached twice (the node hierarchy must be a forest)",
                ));
            }
            let local = local_transform(&node)
                .ok_or_else(|| SceneError::invalid(self.file, at(), "rotation is a zero quaternion"))?;
            let world = parent * local;
            if !world.is_finite() {
                return Err(SceneError::invalid(self.file, at(), "transform is not finite"));
            }
            let moving = self.animation_node(&node, local, parent, parent_node);
            if let Some(mesh) = node.mesh() {
                self.instance(&node, mesh, world, moving)?;
            }
            if let Some(light) = node.light() {
                self.light(&node, light, world, moving);
            }
            if let Some(camera) = node.camera() {
                self.camera(&node, camera, world, moving);
            }
            stack.extend(node.children().collect::<Vec<_>>().into_iter().rev().map(|c| (c, world, moving)));
        }
        Ok(())
    }

    /// The node's index in the scene's [`Animation`](crate::Animation) if it moves: if it has
    /// tracks or its parent moves (`parent_node`). A still node under still nodes has none
    /// and keeps its baked world transform. `local` is the node's transform relative to its
    /// parent, `parent` the parent's world transform at rest.
    fn animation_node(
        &mut self,
        node: &gltf::Node,
        local: Mat4,
        parent: Mat4,
        parent_node: Option<u32>,
    ) -> Option<u32> {
        let animation_node = match self.tracks.remove(&node.index()) {
            Some(tracks) => {
                // The still ancestors of the topmost moving node of a branch become one fixed
                // node above it: the tracks replace parts of the node's own transform only.
                let parent_node = parent_node.or_else(|| {
                    (parent != Mat4::IDENTITY)
                        .then(|| self.push_node(AnimationNode::fixed(None, Affine3A::from_mat4(parent))))
                });
                self.animated_node(node, local, parent_node, tracks)
            }
            None => AnimationNode::fixed(Some(parent_node?), Affine3A::from_mat4(local)),
        };
        Some(self.push_node(animation_node))
    }

    /// The [`AnimationNode`] of a node with tracks: its rest transform is the node's own,
    /// which [`AnimationNode::local`] decomposes into translation, rotation and scale for the
    /// tracks to replace.
    fn animated_node(
        &mut self,
        node: &gltf::Node,
        local: Mat4,
        parent: Option<u32>,
        mut tracks: NodeTracks,
    ) -> AnimationNode {
        let rest = Affine3A::from_mat4(local);
        let (scale, rotation, translation) = match node.transform() {
            gltf::scene::Transform::Decomposed { translation, rotation, scale } => (
                Vec3::from(scale),
                // `local_transform` has checked that it is not zero.
                Quat::from_vec4(Vec4::from(rotation).normalize()),
                Vec3::from(translation),
            ),
            gltf::scene::Transform::Matrix { .. } => {
                self.report.warn(
                    self.file,
                    format!(
                        "nodes[{}]: an animated node must not have a matrix (glTF 3.5.3); it is decomposed \
                         into translation, rotation and scale",
                        node.index()
                    ),
                );
                rest.to_scale_rotation_translation()
            }
        };
        if !(scale.is_finite() && rotation.is_finite()) {
            self.report.warn(
                self.file,
                format!("nodes[{}]: its matrix is singular; its animation is not shown", node.index()),
            );
            return AnimationNode::fixed(parent, rest);
        }
        // Decomposing the rest transform does not give back every TRS: glam moves the sign of
        // a negative scale onto X and the rotation with it, and a zero scale has no rotation.
        // Then a track would be combined with the wrong parts, so the parts without a track
        // are held by one-key tracks of the node's own values instead.
        let (decomposed_scale, decomposed_rotation, _) = rest.to_scale_rotation_translation();
        let tolerance = 1e-5 * scale.abs().max_element().max(1.0);
        if !(decomposed_rotation.is_finite() && decomposed_scale.abs_diff_eq(scale, tolerance)) {
            tracks.translation =
                tracks.translation.or_else(|| Track::step(vec![0.0], vec![translation]).ok());
            tracks.rotation = tracks.rotation.or_else(|| Track::step(vec![0.0], vec![rotation]).ok());
            tracks.scale = tracks.scale.or_else(|| Track::step(vec![0.0], vec![scale]).ok());
        }
        AnimationNode {
            parent,
            rest,
            translation: tracks.translation,
            rotation: tracks.rotation.map(RotationTrack::Quaternion),
            scale: tracks.scale,
        }
    }

    /// Appends a node to the scene's animation and returns its index.
    fn push_node(&mut self, node: AnimationNode) -> u32 {
        self.scene.animation.nodes.push(node);
        (self.scene.animation.nodes.len() - 1) as u32
    }

    /// Places `mesh` at the node's world transform; a node that moves (`moving`) carries it.
    fn instance(
        &mut self,
        node: &gltf::Node,
        mesh: gltf::Mesh,
        world: Mat4,
        moving: Option<u32>,
    ) -> Result<(), SceneError> {
        let index = match self.meshes.get(&mesh.index()) {
            Some(&index) => index,
            None => {
                let index = self.load_mesh(&mesh, node.skin().is_some())?;
                self.meshes.insert(mesh.index(), index);
                index
            }
        };
        let Some(index) = index else { return Ok(()) };
        let transform = Affine3A::from_mat4(world);
        if !(transform.is_finite() && transform.inverse().is_finite()) {
            // Rays are traced in the instance's own space, so its transform must invert in f32.
            let (scale, _, _) = world.to_scale_rotation_translation();
            let why = if scale.cmpeq(glam::Vec3::ZERO).any() {
                "scale is zero".to_owned()
            } else {
                format!("world transform (scale {scale}) cannot be inverted in single precision")
            };
            self.report.warn(self.file, format!("nodes[{}]: {why}; the instance is left out", node.index()));
            return Ok(());
        }
        self.scene.instances.push(Instance { mesh: index, transform });
        // A skinned mesh ignores its node's transform and follows its joints (glTF 3.7.3),
        // which are not animated here: it stays in its bind pose.
        if let (Some(carrier), None) = (moving, node.skin()) {
            let instance = (self.scene.instances.len() - 1) as u32;
            self.scene.animation.instances.push(AnimatedInstance {
                instance,
                node: carrier,
                local: Affine3A::IDENTITY,
            });
        }
        Ok(())
    }
}
