//! What a glTF load will read from its accessors, counted before it reads any.
//!
//! An accessor's `count` comes from the file, and its data need not: an accessor without a
//! buffer view is `count` zeros (glTF 3.6.2.3) with at most a few sparse substitutions, so a
//! file of a few hundred bytes can declare four billion vertices, and thousands of primitives
//! may share one large accessor, each read into a mesh of its own. So the loader first adds up
//! what every primitive and every animation channel will read (each accessor as often as it is
//! read, at the size it is read into) and refuses the file if that exceeds
//! [`GLTF_READ_BUDGET`], before any allocation (issue 35).

use std::path::Path;

use gltf::accessor::Accessor;
use gltf::mesh::Mode;

use crate::error::{Location, SceneError};

/// The bytes a glTF file's meshes and animations may read from its accessors: positions,
/// normals and texture coordinates as 32-bit floats, indices as 32-bit integers (twice: the
/// list and its triangles), key times and values. 4 GiB is about 90 million triangles of
/// vertices, normals, texture coordinates and indices.
pub const GLTF_READ_BUDGET: u64 = 4 << 30;

/// Bytes of the 32-bit floats or integers one element of `accessor` is read into.
fn read_bytes(accessor: &Accessor) -> u64 {
    accessor.count() as u64 * accessor.dimensions().multiplicity() as u64 * 4
}

/// Refuses `document` if its primitives and animation channels would read more than `budget`
/// bytes from their accessors.
pub(super) fn check(document: &gltf::Document, file: &Path, budget: u64) -> Result<(), SceneError> {
    let mut total = 0u64;
    for primitive in document.meshes().flat_map(|m| m.primitives()).filter(|p| p.mode() == Mode::Triangles) {
        let attributes: u64 = primitive.attributes().map(|(_, accessor)| read_bytes(&accessor)).sum();
        let vertices = primitive.get(&gltf::Semantic::Positions).map_or(0, |a| a.count() as u64);
        let indices = primitive.indices().map_or(vertices, |a| a.count() as u64);
        total = total.saturating_add(attributes).saturating_add(indices.saturating_mul(8));
    }
    for channel in document.animations().flat_map(|a| a.channels()) {
        let sampler = channel.sampler();
        total =
            total.saturating_add(read_bytes(&sampler.input())).saturating_add(read_bytes(&sampler.output()));
    }
    if total > budget {
        let gib = |bytes: u64| bytes as f64 / f64::from(1u32 << 30);
        return Err(SceneError::invalid(
            file,
            Location::Json("meshes".into()),
            format!(
                "the accessors' counts add up to {:.1} GiB of geometry and animation to read, more than \
                 the {:.0} GiB a glTF file may",
                gib(total),
                gib(budget)
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A glTF document (JSON) with `primitives` triangle primitives over one accessor of
    /// `count` VEC3 positions given by sparse data alone (no buffer view), as the probe's
    /// 596-byte file does.
    fn document(count: u64, primitives: usize) -> gltf::Document {
        let primitive = r#"{"attributes":{"POSITION":0}}"#;
        let list = vec![primitive; primitives].join(",");
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},
            "buffers":[{{"byteLength":16}}],
            "bufferViews":[{{"buffer":0,"byteLength":4}},{{"buffer":0,"byteOffset":4,"byteLength":12}}],
            "accessors":[{{"type":"VEC3","componentType":5126,"count":{count},"min":[0,0,0],"max":[0,0,0],
              "sparse":{{"count":1,"indices":{{"bufferView":0,"componentType":5125}},
                          "values":{{"bufferView":1}}}}}}],
            "meshes":[{{"primitives":[{list}]}}]}}"#
        );
        gltf::Gltf::from_slice(json.as_bytes()).unwrap().document
    }

    #[test]
    fn a_huge_count_without_data_is_refused_before_reading() {
        let file = Path::new("bomb.gltf");
        let error = check(&document(u64::from(u32::MAX), 1), file, GLTF_READ_BUDGET).unwrap_err().to_string();
        assert!(error.contains("bomb.gltf") && error.contains("GiB"), "{error}");
        assert!(check(&document(1000, 1), file, GLTF_READ_BUDGET).is_ok());
    }

    #[test]
    fn primitives_sharing_an_accessor_count_once_each() {
        // 300k vertices (3.6 MB of positions, 2.4 MB of indices as read) in 1000 primitives
        // is about 6 GB: refused, though the accessor is one.
        let file = Path::new("shared.gltf");
        assert!(check(&document(300_000, 1000), file, GLTF_READ_BUDGET).is_err());
        assert!(check(&document(300_000, 100), file, GLTF_READ_BUDGET).is_ok());
    }
}
