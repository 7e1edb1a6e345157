//! The hot loops of a binary payload, read straight from the bytes: the `vertex` element when
//! all its properties are scalars (a fixed stride, read in parallel), and the index lists of
//! the `face` element (and elements read past) without the `Vec` per element that
//! `ply-rs-bw`'s element interface allocates.
//!
//! Each loop reads the elements it can and stops at the first it cannot: one cut short by the
//! end of the file, a negative or non-integer list length, a float index list. The caller reads
//! on from there with `ply-rs-bw`, which reports the problem as it does for every encoding.

use glam::{Vec2, Vec3};
use ply_rs_bw::ply::{ElementDef, PropertyType, ScalarType};
use rayon::prelude::*;

use super::scalar_size;

/// One scalar in a binary element.
#[derive(Clone)]
struct Field {
    /// Bytes from the start of the element.
    offset: usize,
    ty: ScalarType,
}

/// Where the wanted values lie in a `vertex` element whose properties are all scalars.
pub(super) struct VertexFields {
    stride: usize,
    position: [Field; 3],
    normal: Option<[Field; 3]>,
    uv: Option<[Field; 2]>,
}

impl VertexFields {
    /// The fields of `def`, with normals and uvs if wanted, or `None` if some property is a
    /// list (the stride is not fixed) or x, y or z is missing.
    pub fn of(def: &ElementDef, normals: bool, uvs: bool) -> Option<Self> {
        let mut stride = 0;
        let mut slots: [Option<Field>; 8] = Default::default();
        for (name, property) in &def.properties {
            let PropertyType::Scalar(ty) = &property.data_type else { return None };
            // A later property of the same meaning wins, as in `Vertex::set`.
            let slot = match name.as_str() {
                "x" => Some(0),
                "y" => Some(1),
                "z" => Some(2),
                "nx" => Some(3),
                "ny" => Some(4),
                "nz" => Some(5),
                "u" | "s" | "texture_u" => Some(6),
                "v" | "t" | "texture_v" => Some(7),
                _ => None,
            };
            if let Some(slot) = slot {
                slots[slot] = Some(Field { offset: stride, ty: ty.clone() });
            }
            stride += scalar_size(ty);
        }
        let [x, y, z, nx, ny, nz, u, v] = slots;
        Some(Self {
            stride,
            position: [x?, y?, z?],
            normal: if normals { Some([nx?, ny?, nz?]) } else { None },
            uv: if uvs { Some([u?, v?]) } else { None },
        })
    }
}

/// Reads the vertices that `payload` holds in full, at most `count`, into the three arrays
/// (v flipped as in the ascii path), advances `payload` past them and returns how many.
pub(super) fn read_vertices(
    payload: &mut &[u8],
    count: usize,
    fields: &VertexFields,
    big_endian: bool,
    positions: &mut Vec<Vec3>,
    normals: &mut Vec<Vec3>,
    uvs: &mut Vec<Vec2>,
) -> usize {
    let stride = fields.stride;
    // x, y and z make the stride at least 3.
    let complete = payload.len().checked_div(stride).map_or(0, |n| count.min(n));
    let (bytes, rest) = payload.split_at(complete * stride);
    let value = |i: usize, field: &Field| read_f32(bytes, i * stride + field.offset, &field.ty, big_endian);
    let vec3 = |i: usize, [x, y, z]: &[Field; 3]| Vec3::new(value(i, x), value(i, y), value(i, z));
    (0..complete).into_par_iter().map(|i| vec3(i, &fields.position)).collect_into_vec(positions);
    if let Some(normal) = &fields.normal {
        (0..complete).into_par_iter().map(|i| vec3(i, normal)).collect_into_vec(normals);
    }
    if let Some([u, v]) = &fields.uv {
        (0..complete)
            .into_par_iter()
            .map(|i| Vec2::new(value(i, u), 1.0 - value(i, v)))
            .collect_into_vec(uvs);
    }
    *payload = rest;
    complete
}

/// The properties of an element of scalars and lists, and which list holds its face's vertex
/// indices.
pub(super) struct ListLayout {
    properties: Vec<PropertyType>,
    /// The position of the index list in `properties`.
    indices: Option<usize>,
    big_endian: bool,
}

impl ListLayout {
    /// The layout of a `face` element: the last list called `vertex_indices` or `vertex_index`
    /// holds the indices, as in the `Face` of the ascii path; `None` if one of them is a list
    /// of floats (an error `ply-rs-bw` reports).
    pub fn face(def: &ElementDef, big_endian: bool) -> Option<Self> {
        let mut indices = None;
        for (position, (name, property)) in def.properties.iter().enumerate() {
            let is_indices = matches!(name.as_str(), "vertex_indices" | "vertex_index");
            match &property.data_type {
                PropertyType::List(_, ScalarType::Float | ScalarType::Double) if is_indices => return None,
                PropertyType::List(..) if is_indices => indices = Some(position),
                _ => {}
            }
        }
        Some(Self { indices, ..Self::other(def, big_endian) })
    }

    /// The layout of an element read past.
    pub fn other(def: &ElementDef, big_endian: bool) -> Self {
        Self {
            properties: def.properties.values().map(|p| p.data_type.clone()).collect(),
            indices: None,
            big_endian,
        }
    }

    /// The end of the element starting at `start` and its index list (where its values start
    /// and how many), or `None` if the element is incomplete or has a list length that is not
    /// a non-negative integer.
    #[inline]
    fn element(&self, bytes: &[u8], start: usize) -> Option<(usize, Option<(usize, usize)>)> {
        let mut at = start;
        let mut list = None;
        for (position, property) in self.properties.iter().enumerate() {
            match property {
                PropertyType::Scalar(ty) => at += scalar_size(ty),
                PropertyType::List(count_type, item) => {
                    let count = usize::try_from(read_int(bytes, at, count_type, self.big_endian)?).ok()?;
                    at += scalar_size(count_type);
                    if self.indices == Some(position) {
                        list = Some((at, count));
                    }
                    at = at.checked_add(count.checked_mul(scalar_size(item))?)?;
                }
            }
        }
        (at <= bytes.len()).then_some((at, list))
    }

    /// Reads past the elements that `payload` holds in full, at most `count`, and returns how
    /// many.
    pub fn skip(&self, payload: &mut &[u8], count: usize) -> usize {
        let mut at = 0;
        let mut complete = 0;
        while complete < count {
            let Some((end, _)) = self.element(payload, at) else { break };
            at = end;
            complete += 1;
        }
        *payload = &payload[at..];
        complete
    }

    /// Reads the faces that `payload` holds in full, at most `count`, fan-triangulated into
    /// `triangles` (reserved exactly), counts the faces of fewer than three corners in
    /// `short_faces`, advances `payload` past them and returns how many. An index that is
    /// negative or beyond `u32` is an error, made by `bad_index` from the face's number.
    pub fn read_faces<E>(
        &self,
        payload: &mut &[u8],
        count: usize,
        triangles: &mut Vec<[u32; 3]>,
        short_faces: &mut usize,
        bad_index: impl Fn(usize) -> E,
    ) -> Result<usize, E> {
        let index_type = match self.indices.map(|i| &self.properties[i]) {
            Some(PropertyType::List(_, item)) => Some(item),
            _ => None,
        };
        // A first walk finds the complete faces and the triangles they make.
        let (mut at, mut complete, mut triangle_count) = (0, 0, 0);
        while complete < count {
            let Some((end, list)) = self.element(payload, at) else { break };
            triangle_count += list.map_or(0, |(_, corners)| corners.saturating_sub(2));
            at = end;
            complete += 1;
        }
        triangles.reserve_exact(triangle_count);

        let mut at = 0;
        for face in 0..complete {
            let Some((end, list)) = self.element(payload, at) else { break };
            at = end;
            let (Some((start, corners)), Some(ty)) = (list, index_type) else {
                *short_faces += 1;
                continue;
            };
            if corners < 3 {
                *short_faces += 1;
            }
            let size = scalar_size(ty);
            let index = |k: usize| {
                read_int(payload, start + k * size, ty, self.big_endian)
                    .and_then(|i| u32::try_from(i).ok())
                    .ok_or_else(|| bad_index(face))
            };
            // Every index is checked, also those of a face too short to keep.
            let mut first = 0;
            let mut previous = 0;
            for k in 0..corners {
                let corner = index(k)?;
                match k {
                    0 => first = corner,
                    1 => {}
                    _ => triangles.push([first, previous, corner]),
                }
                previous = corner;
            }
        }
        *payload = &payload[at..];
        Ok(complete)
    }
}

/// The `N` bytes at `at`, in little-endian order.
#[inline]
fn bytes_at<const N: usize>(bytes: &[u8], at: usize, big_endian: bool) -> Option<[u8; N]> {
    let mut raw: [u8; N] = bytes.get(at..at.checked_add(N)?)?.try_into().ok()?;
    if big_endian {
        raw.reverse();
    }
    Some(raw)
}

/// The integer of type `ty` at `at`, or `None` past the end or for a float type.
#[inline]
fn read_int(bytes: &[u8], at: usize, ty: &ScalarType, big_endian: bool) -> Option<i64> {
    Some(match ty {
        ScalarType::Char => i8::from_le_bytes(bytes_at(bytes, at, big_endian)?).into(),
        ScalarType::UChar => u8::from_le_bytes(bytes_at(bytes, at, big_endian)?).into(),
        ScalarType::Short => i16::from_le_bytes(bytes_at(bytes, at, big_endian)?).into(),
        ScalarType::UShort => u16::from_le_bytes(bytes_at(bytes, at, big_endian)?).into(),
        ScalarType::Int => i32::from_le_bytes(bytes_at(bytes, at, big_endian)?).into(),
        ScalarType::UInt => u32::from_le_bytes(bytes_at(bytes, at, big_endian)?).into(),
        ScalarType::Float | ScalarType::Double => return None,
    })
}

/// The scalar of type `ty` at `at` (which the caller has checked lies within `bytes`),
/// converted to `f32` as `Vertex` converts it.
#[inline]
fn read_f32(bytes: &[u8], at: usize, ty: &ScalarType, big_endian: bool) -> f32 {
    let value = match ty {
        ScalarType::Float => bytes_at(bytes, at, big_endian).map(f32::from_le_bytes),
        ScalarType::Double => bytes_at(bytes, at, big_endian).map(|b| f64::from_le_bytes(b) as f32),
        _ => read_int(bytes, at, ty, big_endian).map(|i| i as f32),
    };
    value.unwrap_or(f32::NAN)
}
