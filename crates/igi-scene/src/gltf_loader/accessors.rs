//! Accessors checked against their buffers before the `gltf` crate's reader reads them.

use gltf::accessor::{DataType, Dimensions};

/// The accessor type of positions, normals, translations and scales.
pub(super) const VEC3: &[(DataType, Dimensions)] = &[(DataType::F32, Dimensions::Vec3)];

/// Checks that an accessor has one of the `allowed` types and that all of its elements lie
/// inside its buffer view and buffer, so that the `gltf` crate's reader can neither panic nor
/// silently return fewer elements than `count`.
pub(super) fn check_accessor(
    accessor: &gltf::Accessor,
    allowed: &[(DataType, Dimensions)],
    buffers: &[Vec<u8>],
) -> Result<(), String> {
    let kind = (accessor.data_type(), accessor.dimensions());
    if !allowed.contains(&kind) {
        return Err(format!(
            "accessor {}: type {:?} {:?} is not supported here",
            accessor.index(),
            kind.0,
            kind.1
        ));
    }
    let count = accessor.count();
    if count == 0 {
        return Err(format!("accessor {}: count is 0", accessor.index()));
    }
    let element = accessor.size();
    let fits = |view: gltf::buffer::View, offset: usize, count: usize, element: usize| {
        let stride = view.stride().unwrap_or(element);
        let end = stride
            .checked_mul(count - 1)
            .and_then(|n| n.checked_add(offset))
            .and_then(|n| n.checked_add(element));
        let view_end = view.offset().checked_add(view.length());
        let buffer_len = buffers.get(view.buffer().index()).map_or(0, Vec::len);
        stride >= element
            && end.is_some_and(|end| end <= view.length())
            && view_end.is_some_and(|end| end <= buffer_len)
    };
    if let Some(view) = accessor.view() {
        if !fits(view, accessor.offset(), count, element) {
            return Err(format!("accessor {}: data extends past its buffer view", accessor.index()));
        }
    }
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        let indices = sparse.indices();
        let values = sparse.values();
        if n == 0
            || n > count
            || !fits(indices.view(), indices.offset(), n, indices.index_type().size())
            || !fits(values.view(), values.offset(), n, element)
        {
            return Err(format!("accessor {}: sparse data extends past its buffer view", accessor.index()));
        }
    }
    Ok(())
}
