//! glTF animation channels (glTF 2.0 section 3.11, Appendix C) read into [`Track`]s, per node.
//!
//! All animations of a file play at once on the scene clock, and every track of one glTF
//! animation repeats with that animation's period: its largest key time. So channels of
//! different lengths stay in step, as a glTF viewer playing the animation in a loop shows
//! them (a short channel holds its last value until the animation starts over).
//!
//! What is not animated, with a warning: `weights` channels (morph targets are loaded in
//! their base shape) and channels that move skin joints (skinned meshes are loaded in their
//! bind pose). A channel whose sampler is unusable (wrong accessor type, data outside its
//! buffer, a value count that does not match the key times, times that are negative or do not
//! increase, non-finite values) is skipped with a warning naming the sampler and the channel;
//! the rest of the file still loads.

use std::collections::HashMap;
use std::path::Path;

use glam::{Quat, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::animation::util::ReadOutputs;
use gltf::animation::{Interpolation, Property};
use gltf::json::validation::Checked;

use super::accessors::{VEC3, check_accessor};
use crate::animation::{Finite, Keyable, Track};
use crate::report::LoadReport;

/// The tracks that the file's animations put on one node.
#[derive(Debug, Default)]
pub(super) struct NodeTracks {
    /// Translation keys.
    pub translation: Option<Track<Vec3>>,
    /// Rotation keys (unit quaternions).
    pub rotation: Option<Track<Quat>>,
    /// Scale keys.
    pub scale: Option<Track<Vec3>>,
}

/// One channel's track, by the property it animates.
enum Channel {
    Translation(Track<Vec3>),
    Rotation(Track<Quat>),
    Scale(Track<Vec3>),
}

impl Channel {
    fn looping(self, period: f32) -> Self {
        match self {
            Self::Translation(track) => Self::Translation(track.looping(period)),
            Self::Rotation(track) => Self::Rotation(track.looping(period)),
            Self::Scale(track) => Self::Scale(track.looping(period)),
        }
    }
}

const TIMES: &[(DataType, Dimensions)] = &[(DataType::F32, Dimensions::Scalar)];
/// Rotation outputs may also be normalized integers (glTF 3.11, "Animation samplers").
const ROTATIONS: &[(DataType, Dimensions)] = &[
    (DataType::F32, Dimensions::Vec4),
    (DataType::I8, Dimensions::Vec4),
    (DataType::U8, Dimensions::Vec4),
    (DataType::I16, Dimensions::Vec4),
    (DataType::U16, Dimensions::Vec4),
];

/// Reads the node channels of every animation: glTF node index → its tracks.
pub(super) fn read(
    document: &gltf::Document,
    buffers: &[Vec<u8>],
    file: &Path,
    report: &mut LoadReport,
) -> HashMap<usize, NodeTracks> {
    let node_count = document.nodes().len();
    let mut joint = vec![false; node_count];
    for skin in document.skins() {
        for node in skin.joints() {
            joint[node.index()] = true;
        }
    }
    let mut tracks: HashMap<usize, NodeTracks> = HashMap::new();
    for (animation, json) in document.animations().zip(&document.as_json().animations) {
        let i = animation.index();
        let mut period = 0.0f32;
        let mut read = Vec::new();
        // (count, first channel) of the channels that move skin joints.
        let mut joint_channels = (0usize, 0usize);
        // The `gltf` crate's validation does not look at channel targets, and its accessors
        // unwrap them, so the target is read from the JSON and checked here.
        for (channel, json) in animation.channels().zip(&json.channels) {
            let at = format!("animations[{i}].channels[{}]", channel.index());
            let node = json.target.node.value();
            let Checked::Valid(property) = json.target.path else {
                report.warn(file, format!("{at}: unknown target path; skipped"));
                continue;
            };
            if node >= node_count {
                report.warn(file, format!("{at}: target node {node} does not exist; skipped"));
                continue;
            }
            let sampler = channel.sampler();
            let reader = channel.reader(|buffer| buffers.get(buffer.index()).map(Vec::as_slice));
            let times = read_times(&sampler, &reader, buffers);
            // Every channel with usable times counts toward the period, including those not
            // shown, so the shown ones loop when a viewer playing the whole animation would.
            if let Some(last) = times.as_ref().ok().and_then(|times| last_key(times)) {
                period = period.max(last);
            }
            if property == Property::MorphTargetWeights {
                report.warn(file, format!("{at}: morph-target weights are not animated; shown at rest"));
                continue;
            }
            if joint[node] {
                if joint_channels.0 == 0 {
                    joint_channels.1 = channel.index();
                }
                joint_channels.0 += 1;
                continue;
            }
            match times.and_then(|times| read_channel(property, times, &sampler, &reader, buffers)) {
                Ok(track) => read.push((node, property, track, at)),
                Err(message) => report.warn(
                    file,
                    format!("animations[{i}].samplers[{}]: {message}; {at} skipped", sampler.index()),
                ),
            }
        }
        if let (count @ 1.., first) = joint_channels {
            report.warn(
                file,
                format!(
                    "animations[{i}]: {count} channel(s) move skin joints (the first is \
                     animations[{i}].channels[{first}]); skinned meshes are not animated and stay in \
                     their bind pose"
                ),
            );
        }
        for (node, property, track, at) in read {
            let node_tracks = tracks.entry(node).or_default();
            let slot_taken = match track.looping(period) {
                Channel::Translation(track) => fill(&mut node_tracks.translation, track),
                Channel::Rotation(track) => fill(&mut node_tracks.rotation, track),
                Channel::Scale(track) => fill(&mut node_tracks.scale, track),
            };
            // glTF 3.11 forbids two channels of one animation with the same target; between
            // animations it is allowed, but as they all play at once only one can be shown.
            if slot_taken {
                report.warn(
                    file,
                    format!(
                        "{at}: nodes[{node}].{} is already animated by another channel; skipped",
                        name(property)
                    ),
                );
            }
        }
    }
    tracks
}

/// Puts `track` into an empty `slot`; returns true (and drops the track) if it is taken.
fn fill<T: Keyable>(slot: &mut Option<Track<T>>, track: Track<T>) -> bool {
    if slot.is_some() {
        return true;
    }
    *slot = Some(track);
    false
}

/// The JSON name of a channel's target path.
fn name(property: Property) -> &'static str {
    match property {
        Property::Translation => "translation",
        Property::Rotation => "rotation",
        Property::Scale => "scale",
        Property::MorphTargetWeights => "weights",
    }
}

/// The last key time of usable key times (finite, ≥ 0, increasing), or `None`.
fn last_key(times: &[f32]) -> Option<f32> {
    let usable = times.first().is_some_and(|&t| t >= 0.0)
        && times.iter().all(|t| t.is_finite())
        && times.windows(2).all(|w| w[0] < w[1]);
    times.last().copied().filter(|_| usable)
}

type Reader<'a, 's, F> = gltf::animation::util::Reader<'a, 's, F>;

/// A sampler's key times (the input accessor), unchecked for order.
fn read_times<'a, 's, F>(
    sampler: &gltf::animation::Sampler,
    reader: &Reader<'a, 's, F>,
    buffers: &[Vec<u8>],
) -> Result<Vec<f32>, String>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let input = sampler.input();
    check_accessor(&input, TIMES, buffers)?;
    // An accessor without a buffer view is zeros except for its sparse values, so more than
    // one key beyond those would repeat time 0. Rejecting that first also keeps a count that
    // no bytes back from sizing the vector below.
    if input.view().is_none() && input.count() > input.sparse().map_or(0, |s| s.count()) + 1 {
        return Err(format!("accessor {}: key times do not increase", input.index()));
    }
    Ok(reader.read_inputs().ok_or("key time data is missing")?.collect())
}

/// The track of one channel: its output values checked against the key times and the
/// interpolation, then keyed.
fn read_channel<'a, 's, F>(
    property: Property,
    times: Vec<f32>,
    sampler: &gltf::animation::Sampler,
    reader: &Reader<'a, 's, F>,
    buffers: &[Vec<u8>],
) -> Result<Channel, String>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let output = sampler.output();
    check_accessor(&output, if property == Property::Rotation { ROTATIONS } else { VEC3 }, buffers)?;
    let interpolation = sampler.interpolation();
    // Appendix C: a CUBICSPLINE key stores an in-tangent, the value and an out-tangent.
    let per_key = if interpolation == Interpolation::CubicSpline { 3 } else { 1 };
    // Checked before reading, so the output count (which a sparse accessor need not back with
    // bytes) is bounded by the key times, which are backed.
    if Some(output.count()) != times.len().checked_mul(per_key) {
        return Err(format!(
            "{} output values for {} key times{}",
            output.count(),
            times.len(),
            if per_key == 3 { " (CUBICSPLINE needs 3 per key)" } else { "" }
        ));
    }
    let track = match reader.read_outputs().ok_or("output data is missing")? {
        ReadOutputs::Translations(values) => {
            keyed(times, values.map(Vec3::from).collect(), interpolation).map(Channel::Translation)
        }
        ReadOutputs::Scales(values) => {
            keyed(times, values.map(Vec3::from).collect(), interpolation).map(Channel::Scale)
        }
        ReadOutputs::Rotations(values) => {
            let mut values: Vec<Quat> = values.into_f32().map(Quat::from_array).collect();
            // Appendix C normalises after cubic interpolation; the keys of the other modes
            // are used as they are, so exporters' slightly non-unit ones are normalised here.
            if interpolation != Interpolation::CubicSpline {
                for (k, q) in values.iter_mut().enumerate() {
                    let unit = Vec4::from(*q).try_normalize();
                    *q = Quat::from_vec4(unit.ok_or(format!("rotation key {k} is zero or not finite"))?);
                }
            }
            keyed(times, values, interpolation).map(Channel::Rotation)
        }
        ReadOutputs::MorphTargetWeights(_) => return Err("weights are not a node transform".into()),
    };
    track.map_err(|e| e.to_string())
}

/// A track of `values` at `times` with glTF's `interpolation`.
fn keyed<T: Keyable + Finite>(
    times: Vec<f32>,
    values: Vec<T>,
    interpolation: Interpolation,
) -> Result<Track<T>, crate::animation::TrackError> {
    match interpolation {
        Interpolation::Step => Track::step(times, values),
        Interpolation::Linear => Track::linear(times, values),
        Interpolation::CubicSpline => {
            // (in-tangent a_k, value v_k, out-tangent b_k) per key. glTF's Hermite multiplies
            // the tangents by the key interval (Appendix C), so they are in value units per
            // second, as `Track::cubic` takes them.
            let (values, tangents) = values.chunks_exact(3).map(|key| (key[1], (key[0], key[2]))).unzip();
            Track::cubic(times, values, tangents)
        }
    }
}
