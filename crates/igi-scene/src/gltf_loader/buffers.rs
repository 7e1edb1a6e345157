//! Where the bytes of buffers and images come from: the GLB's BIN chunk, `data:` URIs, or
//! files beside the document (URIs are resolved here, not by the `gltf` crate, which panics on
//! some of them).

use std::path::Path;

use crate::error::{Location, SceneError};
use crate::report::LoadReport;
use crate::resources;

/// Decodes `%XX` escapes of a relative URI.
fn percent_decode(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Where the bytes of a buffer or image come from.
pub(super) enum Uri {
    /// A `data:` URI, decoded.
    Data(Vec<u8>),
    /// A file, relative to the document.
    File(String),
}

pub(super) fn classify_uri(uri: &str) -> Result<Uri, String> {
    if uri.starts_with("data:") {
        let data = gltf::buffer::Data::from_source(gltf::buffer::Source::Uri(uri), None)
            .map_err(|e| format!("bad data URI: {e}"))?;
        Ok(Uri::Data(data.0))
    } else if uri.contains(':') {
        Err(format!("unsupported URI scheme in `{uri}`"))
    } else {
        percent_decode(uri)
            .map(Uri::File)
            .ok_or_else(|| format!("URI `{uri}` is not valid percent-encoded UTF-8"))
    }
}

pub(super) fn load_buffers(
    document: &gltf::Document,
    mut blob: Option<Vec<u8>>,
    file: &Path,
    base_dir: Option<&Path>,
    report: &mut LoadReport,
) -> Result<Vec<Vec<u8>>, SceneError> {
    let mut buffers = Vec::new();
    for buffer in document.buffers() {
        let at = || Location::Json(format!("buffers[{}]", buffer.index()));
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob
                .take()
                .ok_or_else(|| SceneError::invalid(file, at(), "refers to a missing GLB BIN chunk"))?,
            gltf::buffer::Source::Uri(uri) => {
                match classify_uri(uri).map_err(|m| SceneError::invalid(file, at(), m))? {
                    Uri::Data(data) => data,
                    Uri::File(relative) => {
                        let Some(dir) = base_dir else {
                            return Err(SceneError::unsupported(
                                file,
                                at(),
                                format!(
                                    "external buffer `{relative}` cannot be read when parsing from memory"
                                ),
                            ));
                        };
                        let path =
                            resources::resolve(dir, &relative).ok_or_else(|| SceneError::MissingFile {
                                file: file.to_path_buf(),
                                at: at(),
                                missing: dir.join(&relative),
                            })?;
                        resources::read(&path, report)?
                    }
                }
            }
        };
        if data.len() < buffer.length() {
            return Err(SceneError::invalid(
                file,
                at(),
                format!("byteLength is {} but only {} bytes are present", buffer.length(), data.len()),
            ));
        }
        buffers.push(data);
    }
    Ok(buffers)
}
