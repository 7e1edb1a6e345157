//! Stanford PLY files (ascii, binary little and big endian), parsed by `ply-rs-bw`, become one
//! [`Mesh`](crate::Mesh) with one grey default material, placed by one identity
//! [`Instance`](crate::Instance).
//!
//! Read from the `vertex` element: `x y z` of any numeric type, `nx ny nz` if all three are
//! present, texture coordinates from `u v`, `s t` or `texture_u texture_v` (v flipped to the
//! model's top-row-is-zero convention). From the `face` element: the `vertex_indices` or
//! `vertex_index` list of any integer type; polygons are fan-triangulated. Every other
//! property and element (Armadillo's `uchar intensity` before the index list, the bunny's
//! `confidence`, edge lists, ...) is read past and ignored.
//!
//! The header is checked against the file size before any payload is read: a 100-byte file
//! claiming 4·10⁹ vertices is rejected on the spot instead of looping or allocating. Elements
//! are streamed one at a time, so memory follows the data actually present. In a binary file
//! the bulk (vertices of scalar properties, index lists, elements read past) is read straight
//! from the bytes by [`binary`]; `ply-rs-bw` reads the header, ascii payloads and whatever the
//! fast path stops at, so errors read the same either way.

use std::io::BufRead;
use std::path::Path;

use glam::{Vec2, Vec3};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    ElementDef, Encoding, Header, PropertyAccess, PropertyAccessResult, PropertyType, ScalarType,
};

use crate::error::{Location, SceneError};
use crate::model::{Material, Scene};
use crate::report::LoadReport;
use crate::validate::{MeshBuilder, Part};

mod binary;

/// Parses the PLY bytes of `file` (its name is the mesh's).
pub(crate) fn parse(bytes: &[u8], file: &Path, report: &mut LoadReport) -> Result<Scene, SceneError> {
    let mut reader = Reader::new(bytes);
    let header = Parser::<Skip>::new().read_header(&mut reader).map_err(|e| {
        SceneError::parse(file, e.line().map_or(Location::File, Location::Line), message_of(&e))
    })?;
    // The reader stands on the first payload line.
    let header_lines = reader.line().saturating_sub(1);
    let mut payload = reader.into_inner();
    check_sizes(&header, payload.len(), file)?;

    let mut positions = Vec::new();
    let mut normals = Vec::new();
    let mut uvs = Vec::new();
    let mut triangles = Vec::new();
    let mut short_faces = 0;
    let mut vertex_lines = None;
    let mut lines_read = 0;
    for def in header.elements.values() {
        let mut stream = ElementStream {
            payload: &mut payload,
            encoding: header.encoding,
            def,
            file,
            first_line: header_lines + lines_read,
            start: 0,
        };
        let big_endian = match header.encoding {
            Encoding::Ascii => None,
            Encoding::BinaryBigEndian => Some(true),
            Encoding::BinaryLittleEndian => Some(false),
        };
        match def.name.as_str() {
            "vertex" => {
                vertex_lines = Some(stream.first_line);
                let layout = VertexLayout::of(def, file)?;
                let fields = big_endian.zip(binary::VertexFields::of(def, layout.normals, layout.uvs));
                if let Some((big_endian, fields)) = fields {
                    stream.start = binary::read_vertices(
                        stream.payload,
                        def.count,
                        &fields,
                        big_endian,
                        &mut positions,
                        &mut normals,
                        &mut uvs,
                    );
                }
                positions.reserve(def.count - stream.start);
                stream.each(|_, v: Vertex| {
                    positions.push(Vec3::from(v.position));
                    if layout.normals {
                        normals.push(Vec3::from(v.normal));
                    }
                    if layout.uvs {
                        uvs.push(Vec2::new(v.uv[0], 1.0 - v.uv[1]));
                    }
                    Ok(())
                })?;
            }
            "face" => {
                if let Some(layout) =
                    big_endian.and_then(|big_endian| binary::ListLayout::face(def, big_endian))
                {
                    stream.start = layout.read_faces(
                        stream.payload,
                        def.count,
                        &mut triangles,
                        &mut short_faces,
                        |index| bad_index(file, index),
                    )?;
                }
                stream.each(|index, face: Face| {
                    let corners = face
                        .indices
                        .iter()
                        .map(|&i| u32::try_from(i))
                        .collect::<Result<Vec<u32>, _>>()
                        .map_err(|_| bad_index(file, index))?;
                    if corners.len() < 3 {
                        short_faces += 1;
                    }
                    for pair in corners.get(1..).unwrap_or_default().windows(2) {
                        triangles.push([corners[0], pair[0], pair[1]]);
                    }
                    Ok(())
                })?;
            }
            _ => {
                if let Some(big_endian) = big_endian {
                    stream.start = binary::ListLayout::other(def, big_endian).skip(stream.payload, def.count);
                }
                stream.each(|_, _: Skip| Ok(()))?;
            }
        }
        if header.encoding == Encoding::Ascii {
            lines_read += def.count;
        }
    }
    let Some(vertex_lines) = vertex_lines else {
        return Err(SceneError::invalid(file, Location::File, "no `vertex` element"));
    };

    let mut builder =
        MeshBuilder::new(file.file_stem().map_or_else(|| "ply".into(), |s| s.to_string_lossy().into_owned()));
    let part = Part {
        positions,
        normals: (!normals.is_empty()).then_some(normals),
        uvs: (!uvs.is_empty()).then_some(uvs),
        triangles,
        material: 0,
    };
    builder.add(part).map_err(|defect| {
        let at = match (header.encoding, defect.vertex()) {
            (Encoding::Ascii, Some(vertex)) => Location::Line(vertex_lines + vertex + 1),
            _ => Location::File,
        };
        SceneError::invalid(file, at, defect.to_string())
    })?;
    let built = builder.finish();
    report.degenerate(file, short_faces + built.degenerate);
    Ok(built.into_scene(vec![Material::default()], file, report))
}

/// The error of a face whose vertex index does not fit a `u32`.
fn bad_index(file: &Path, index: usize) -> SceneError {
    SceneError::invalid(
        file,
        Location::Element { name: "face".into(), index },
        "negative or too large vertex index",
    )
}

/// `ply-rs-bw` messages start with "Line N:" when they know a line; the line goes into the
/// [`Location`] instead.
fn message_of(error: &ply_rs_bw::parser::ParseError) -> String {
    let text = error.to_string();
    match text.split_once(": ") {
        Some((prefix, rest)) if prefix.starts_with("Line ") => rest.to_owned(),
        _ => text,
    }
    .replace("\n\t", "; ")
}

/// Rejects headers whose element counts need more bytes than the file has.
fn check_sizes(header: &Header, available: usize, file: &Path) -> Result<(), SceneError> {
    let mut needed: usize = 0;
    for def in header.elements.values() {
        if def.count > 0 && def.properties.is_empty() {
            return Err(SceneError::invalid(
                file,
                Location::File,
                format!("element `{}` has no properties", def.name),
            ));
        }
        let per_element: usize = def
            .properties
            .values()
            .map(|p| match header.encoding {
                // A value and its separating blank or newline.
                Encoding::Ascii => 2,
                Encoding::BinaryBigEndian | Encoding::BinaryLittleEndian => match &p.data_type {
                    PropertyType::Scalar(t) | PropertyType::List(t, _) => scalar_size(t),
                },
            })
            .sum();
        needed = def
            .count
            .checked_mul(per_element)
            .and_then(|n| n.checked_add(needed))
            .ok_or_else(|| too_big(def, file))?;
        if needed > available {
            return Err(SceneError::invalid(
                file,
                Location::File,
                format!(
                    "the header declares {} `{}` elements, which need at least {needed} bytes, \
                     but only {available} bytes follow the header",
                    def.count, def.name
                ),
            ));
        }
    }
    Ok(())
}

fn too_big(def: &ElementDef, file: &Path) -> SceneError {
    SceneError::invalid(
        file,
        Location::File,
        format!("the header declares an impossible {} `{}` elements", def.count, def.name),
    )
}

fn scalar_size(t: &ScalarType) -> usize {
    match t {
        ScalarType::Char | ScalarType::UChar => 1,
        ScalarType::Short | ScalarType::UShort => 2,
        ScalarType::Int | ScalarType::UInt | ScalarType::Float => 4,
        ScalarType::Double => 8,
    }
}

/// Reads the elements of one element definition one at a time.
struct ElementStream<'a, 'b> {
    payload: &'a mut &'b [u8],
    encoding: Encoding,
    def: &'a ElementDef,
    file: &'a Path,
    /// Lines before this element's first line (ascii only).
    first_line: usize,
    /// The first element to read (those before were read by the binary fast path).
    start: usize,
}

impl ElementStream<'_, '_> {
    fn each<E: PropertyAccess>(
        &mut self,
        mut visit: impl FnMut(usize, E) -> Result<(), SceneError>,
    ) -> Result<(), SceneError> {
        let parser = Parser::<E>::new();
        let mut line = String::new();
        for index in self.start..self.def.count {
            let at = || match self.encoding {
                Encoding::Ascii => Location::Line(self.first_line + index + 1),
                _ => Location::Element { name: self.def.name.clone(), index },
            };
            let element = match self.encoding {
                Encoding::Ascii => {
                    line.clear();
                    let read = self
                        .payload
                        .read_line(&mut line)
                        .map_err(|e| SceneError::parse(self.file, at(), e.to_string()))?;
                    if read == 0 {
                        return Err(self.truncated(index));
                    }
                    parser.read_ascii_element(&line, self.def)
                }
                Encoding::BinaryBigEndian => parser.read_big_endian_element(self.payload, self.def),
                Encoding::BinaryLittleEndian => parser.read_little_endian_element(self.payload, self.def),
            };
            let element = element.map_err(|e| {
                if e.kind() == std::io::ErrorKind::UnexpectedEof {
                    self.truncated(index)
                } else {
                    SceneError::parse(self.file, at(), message_of(&e))
                }
            })?;
            visit(index, element)?;
        }
        Ok(())
    }

    fn truncated(&self, index: usize) -> SceneError {
        SceneError::parse(
            self.file,
            Location::Element { name: self.def.name.clone(), index },
            format!("file ends early: the header declares {} `{}` elements", self.def.count, self.def.name),
        )
    }
}

/// Which optional vertex attributes the header declares.
struct VertexLayout {
    normals: bool,
    uvs: bool,
}

impl VertexLayout {
    fn of(def: &ElementDef, file: &Path) -> Result<Self, SceneError> {
        let has = |name: &str| {
            def.properties.get(name).is_some_and(|p| matches!(p.data_type, PropertyType::Scalar(_)))
        };
        if !(has("x") && has("y") && has("z")) {
            return Err(SceneError::invalid(
                file,
                Location::File,
                "the `vertex` element lacks one of the scalar properties x, y, z",
            ));
        }
        Ok(Self {
            normals: has("nx") && has("ny") && has("nz"),
            uvs: (has("u") && has("v")) || (has("s") && has("t")) || (has("texture_u") && has("texture_v")),
        })
    }
}

/// One `vertex` element: every numeric type is accepted and converted to `f32`.
#[derive(Default)]
struct Vertex {
    position: [f32; 3],
    normal: [f32; 3],
    uv: [f32; 2],
}

impl Vertex {
    fn set(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        let slot = match name {
            "x" => &mut self.position[0],
            "y" => &mut self.position[1],
            "z" => &mut self.position[2],
            "nx" => &mut self.normal[0],
            "ny" => &mut self.normal[1],
            "nz" => &mut self.normal[2],
            "u" | "s" | "texture_u" => &mut self.uv[0],
            "v" | "t" | "texture_v" => &mut self.uv[1],
            _ => return PropertyAccessResult::Ignored,
        };
        *slot = value;
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Self::default()
    }
    fn set_char(&mut self, name: &str, value: i8) -> PropertyAccessResult {
        self.set(name, f32::from(value))
    }
    fn set_uchar(&mut self, name: &str, value: u8) -> PropertyAccessResult {
        self.set(name, f32::from(value))
    }
    fn set_short(&mut self, name: &str, value: i16) -> PropertyAccessResult {
        self.set(name, f32::from(value))
    }
    fn set_ushort(&mut self, name: &str, value: u16) -> PropertyAccessResult {
        self.set(name, f32::from(value))
    }
    fn set_int(&mut self, name: &str, value: i32) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
    fn set_uint(&mut self, name: &str, value: u32) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
    fn set_float(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        self.set(name, value)
    }
    fn set_double(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
}

/// One `face` element: its vertex index list, of whatever integer type the header declares.
#[derive(Default)]
struct Face {
    indices: Vec<i64>,
}

impl Face {
    fn set<T: Into<i64>>(&mut self, name: &str, values: Vec<T>) -> PropertyAccessResult {
        if matches!(name, "vertex_indices" | "vertex_index") {
            self.indices = values.into_iter().map(Into::into).collect();
            PropertyAccessResult::Set
        } else {
            PropertyAccessResult::Ignored
        }
    }

    fn reject_float(name: &str) -> PropertyAccessResult {
        if matches!(name, "vertex_indices" | "vertex_index") {
            PropertyAccessResult::UnsupportedType
        } else {
            PropertyAccessResult::Ignored
        }
    }
}

impl PropertyAccess for Face {
    fn new() -> Self {
        Self::default()
    }
    fn set_list_char(&mut self, name: &str, values: Vec<i8>) -> PropertyAccessResult {
        self.set(name, values)
    }
    fn set_list_uchar(&mut self, name: &str, values: Vec<u8>) -> PropertyAccessResult {
        self.set(name, values)
    }
    fn set_list_short(&mut self, name: &str, values: Vec<i16>) -> PropertyAccessResult {
        self.set(name, values)
    }
    fn set_list_ushort(&mut self, name: &str, values: Vec<u16>) -> PropertyAccessResult {
        self.set(name, values)
    }
    fn set_list_int(&mut self, name: &str, values: Vec<i32>) -> PropertyAccessResult {
        self.set(name, values)
    }
    fn set_list_uint(&mut self, name: &str, values: Vec<u32>) -> PropertyAccessResult {
        self.set(name, values)
    }
    fn set_list_float(&mut self, name: &str, _: Vec<f32>) -> PropertyAccessResult {
        Self::reject_float(name)
    }
    fn set_list_double(&mut self, name: &str, _: Vec<f64>) -> PropertyAccessResult {
        Self::reject_float(name)
    }
}

/// Any other element: read past, nothing kept.
struct Skip;

impl PropertyAccess for Skip {
    fn new() -> Self {
        Skip
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_bytes(bytes: &[u8]) -> Result<(Scene, LoadReport), SceneError> {
        let mut report = LoadReport::default();
        crate::parse_mesh(crate::MeshFormat::Ply, bytes, "t.ply", None, &mut report).map(|s| (s, report))
    }

    const ASCII: &str = "ply\nformat ascii 1.0\ncomment c\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 2\nproperty uchar intensity\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n7 4 0 1 2 3\n7 2 0 1\n";

    #[test]
    fn ascii_polygons_are_fanned_and_extra_properties_skipped() {
        let (scene, report) = parse_bytes(ASCII.as_bytes()).unwrap();
        let mesh = &scene.meshes[0];
        assert_eq!(mesh.indices.len(), 2);
        assert_eq!(report.degenerate_dropped, 1, "the two-vertex face");
        let uvs = mesh.uvs.as_ref().unwrap();
        assert!(uvs.contains(&Vec2::new(0.0, 1.0)) && uvs.contains(&Vec2::new(1.0, 0.0)), "v flipped");
        assert_eq!(scene.materials, vec![Material::default()]);
    }

    fn binary(big_endian: bool) -> Vec<u8> {
        let format = if big_endian { "binary_big_endian" } else { "binary_little_endian" };
        let mut bytes = format!(
            "ply\nformat {format} 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty uchar intensity\nproperty list uchar uint vertex_index\nend_header\n"
        )
        .into_bytes();
        let vertices: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        for v in vertices {
            for c in v {
                bytes.extend(if big_endian { c.to_be_bytes() } else { c.to_le_bytes() });
            }
            for n in [0.0f32, 0.6, 0.8] {
                bytes.extend(if big_endian { n.to_be_bytes() } else { n.to_le_bytes() });
            }
        }
        bytes.extend([9u8, 3]);
        for i in [0u32, 1, 2] {
            bytes.extend(if big_endian { i.to_be_bytes() } else { i.to_le_bytes() });
        }
        bytes
    }

    #[test]
    fn binary_both_endians() {
        for big_endian in [false, true] {
            let (scene, _) = parse_bytes(&binary(big_endian)).unwrap();
            let mesh = &scene.meshes[0];
            assert_eq!(mesh.indices, vec![[0, 1, 2]]);
            assert_eq!(mesh.positions[1], Vec3::X);
            assert_eq!(mesh.normals.as_ref().unwrap()[0], Vec3::new(0.0, 0.6, 0.8));
        }
    }

    /// A value of a property as written in a file: its PLY type and its number.
    type Value = (&'static str, f64);

    /// A file of the given `format` holding `elements` (name, property declarations, and the
    /// values of each element; a list is written as its length followed by its items).
    fn file(format: &str, elements: &[(&str, &str, Vec<Vec<Value>>)]) -> Vec<u8> {
        let mut bytes = format!("ply\nformat {format} 1.0\n").into_bytes();
        for (name, properties, rows) in elements {
            bytes.extend(format!("element {name} {}\n{properties}", rows.len()).bytes());
        }
        bytes.extend(b"end_header\n");
        for row in elements.iter().flat_map(|(_, _, rows)| rows) {
            if format == "ascii" {
                let text: Vec<String> = row.iter().map(|(_, v)| v.to_string()).collect();
                bytes.extend(format!("{}\n", text.join(" ")).bytes());
                continue;
            }
            let big = format == "binary_big_endian";
            for &(ty, v) in row {
                // The value as `$t` in the file's byte order.
                macro_rules! encoded {
                    ($t:ty) => {
                        if big { (v as $t).to_be_bytes().to_vec() } else { (v as $t).to_le_bytes().to_vec() }
                    };
                }
                let raw: Vec<u8> = match ty {
                    "char" => vec![v as i8 as u8],
                    "uchar" => vec![v as u8],
                    "short" => encoded!(i16),
                    "ushort" => encoded!(u16),
                    "int" => encoded!(i32),
                    "uint" => encoded!(u32),
                    "float" => encoded!(f32),
                    _ => encoded!(f64),
                };
                bytes.extend(raw);
            }
        }
        bytes
    }

    /// Every scalar type, lists of every length type, polygons, a short face and an element
    /// read past between the vertices and the faces.
    fn mixed(format: &str) -> Vec<u8> {
        let vertices = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.5], [0.0, 2.0, 0.0], [1.0, 3.0, -1.0]];
        let vertex_rows = vertices
            .iter()
            .enumerate()
            .map(|(i, &[x, y, z])| {
                let k = i as f64;
                vec![
                    ("double", x),
                    ("char", -3.0),
                    ("float", y),
                    ("short", z * 2.0),
                    ("float", 0.25 * k),
                    ("uchar", 1.0),
                    ("float", 0.5),
                    ("ushort", 3.0),
                    ("int", -4.0),
                    ("double", 0.125 * k),
                    ("uint", 7.0),
                ]
            })
            .collect();
        let edges = vec![
            vec![("short", 2.0), ("int", 0.0), ("int", 1.0), ("uchar", 9.0)],
            vec![("short", 0.0), ("uchar", 9.0)],
        ];
        let face = |indices: &[f64], count: &'static str, item: &'static str| {
            let mut row = vec![("float", 0.75), (count, indices.len() as f64)];
            row.extend(indices.iter().map(|&i| (item, i)));
            row.extend([("uint", 2.0), ("float", 0.1), ("float", 0.2)]);
            row
        };
        let faces = vec![
            face(&[0.0, 1.0, 2.0, 3.0], "char", "ushort"),
            face(&[1.0, 2.0, 4.0], "char", "ushort"),
            face(&[0.0, 1.0], "char", "ushort"),
        ];
        file(
            format,
            &[
                (
                    "vertex",
                    "property double x\nproperty char flags\nproperty float y\nproperty short z\nproperty float s\nproperty uchar nx\nproperty float ny\nproperty ushort nz\nproperty int unused\nproperty double t\nproperty uint more\n",
                    vertex_rows,
                ),
                ("edge", "property list short int vertex\nproperty uchar colour\n", edges),
                (
                    "face",
                    "property float quality\nproperty list char ushort vertex_indices\nproperty list uint float texcoord\n",
                    faces,
                ),
            ],
        )
    }

    #[test]
    fn binary_reads_as_ascii() {
        let (ascii, ascii_report) = parse_bytes(&mixed("ascii")).unwrap();
        let mesh = &ascii.meshes[0];
        assert_eq!(mesh.indices.len(), 3);
        assert_eq!(ascii_report.degenerate_dropped, 1, "the two-vertex face");
        assert!(mesh.normals.is_some() && mesh.uvs.is_some());
        for format in ["binary_little_endian", "binary_big_endian"] {
            let (binary, report) = parse_bytes(&mixed(format)).unwrap();
            assert_eq!(binary.digest(), ascii.digest(), "{format}");
            assert_eq!(report.degenerate_dropped, 1, "{format}");
        }
    }

    #[test]
    fn binary_errors_read_as_before() {
        let vertex = "property float x\nproperty float y\nproperty float z\n";
        let vertices: Vec<Vec<Value>> = (0..3)
            .map(|i| vec![("float", f64::from(i)), ("float", f64::from(i * i)), ("float", 1.0)])
            .collect();
        let faces = |indices: Vec<Value>| {
            vec![vec![("uchar", 3.0), ("int", 0.0), ("int", 1.0), ("int", 2.0)], indices]
        };
        let read = |face: &str, rows: Vec<Vec<Value>>| {
            let bytes =
                file("binary_little_endian", &[("vertex", vertex, vertices.clone()), ("face", face, rows)]);
            parse_bytes(&bytes).map(|_| ()).unwrap_err().to_string()
        };
        let list = "property list char int vertex_indices\n";
        assert_eq!(
            read(list, faces(vec![("char", -1.0), ("int", 0.0), ("int", 0.0), ("int", 0.0)])),
            "t.ply: face 1: List length cannot be negative (i8)."
        );
        assert_eq!(
            read(list, faces(vec![("char", 3.0), ("int", 0.0), ("int", -1.0), ("int", 0.0)])),
            "t.ply: face 1: negative or too large vertex index"
        );
        assert_eq!(
            read(list, faces(vec![("char", 3.0), ("int", 0.0), ("int", 1.0), ("int", 7.0)])),
            "t.ply: triangle 1 refers to vertex 7, but there are only 3 vertices"
        );
        let floats = "property list uchar float vertex_indices\n";
        let err = read(floats, faces(vec![("uchar", 3.0), ("float", 0.0), ("float", 1.0), ("float", 2.0)]));
        assert!(err.starts_with("t.ply: face 0: PLY property 'vertex_indices'"), "{err}");
    }

    #[test]
    fn lying_header_is_rejected_before_reading() {
        let bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n\0\0\0\0";
        let err = parse_bytes(bytes).unwrap_err();
        assert!(err.to_string().contains("4000000000 `vertex` elements"), "{err}");
    }

    #[test]
    fn truncation_and_bad_indices_are_errors() {
        let full = binary(false);
        let err = parse_bytes(&full[..full.len() - 2]).unwrap_err();
        assert!(err.to_string().contains("face 0"), "{err}");
        let bad = ASCII.replace("7 4 0 1 2 3", "7 4 0 1 2 9");
        let err = parse_bytes(bad.as_bytes()).unwrap_err();
        assert!(err.to_string().contains("vertex 9"), "{err}");
        let negative = ASCII.replace("7 4 0 1 2 3", "7 4 0 1 -2 3");
        let err = parse_bytes(negative.as_bytes()).unwrap_err();
        assert!(err.to_string().contains("face 0"), "{err}");
        let nan = ASCII.replace("1 1 0 1 1", "1 nan 0 1 1");
        let err = parse_bytes(nan.as_bytes()).unwrap_err();
        assert!(err.to_string().starts_with("t.ply: line 16: "), "{err}");
        let mut nan = binary(true);
        let second_x = nan.len() - 3 * 4 - 2 - 2 * 36;
        nan[second_x..second_x + 8].copy_from_slice(&f64::NAN.to_be_bytes());
        let err = parse_bytes(&nan).unwrap_err();
        assert_eq!(err.to_string(), "t.ply: vertex 1 has a NaN or infinite position");
    }
}
