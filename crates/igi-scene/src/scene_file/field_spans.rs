//! Where a field of a scene file is in its text, both ways: the span of the value at a field
//! path (`light[0].intensity`, `mesh[2].instances[7].scale`), so that an error found after
//! parsing points at the field's own line rather than its table's header; and the field path
//! of a text offset, so that a `toml` error names the field it is in.
//!
//! Both walk the document as `toml` parses it with spans. They run only when an error is
//! reported, so a valid file is parsed once.

use std::ops::Range;

use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// The span of the value at `path` (components separated by `.`, array indices as `[i]`),
/// if the text is a TOML document that has it.
pub(super) fn value_span(text: &str, path: &str) -> Option<Range<usize>> {
    let document = DeTable::parse(text).ok()?;
    let mut table = document.get_ref();
    let mut found: Option<&Spanned<DeValue>> = None;
    for component in path.split('.') {
        if let Some(value) = found {
            let DeValue::Table(inner) = value.get_ref() else { return None };
            table = inner;
        }
        let (key, indices) = split_indices(component)?;
        let mut value = table.iter().find(|(k, _)| k.get_ref() == key)?.1;
        for index in indices {
            let DeValue::Array(items) = value.get_ref() else { return None };
            value = items.get(index)?;
        }
        found = Some(value);
    }
    found.map(Spanned::span)
}

/// `name[1][2]` as `("name", [1, 2])`.
fn split_indices(component: &str) -> Option<(&str, Vec<usize>)> {
    let (key, mut rest) = component.split_once('[').map_or((component, ""), |(k, r)| (k, r));
    let mut indices = Vec::new();
    while !rest.is_empty() {
        let (index, after) = rest.split_once(']')?;
        indices.push(index.parse().ok()?);
        rest = after.strip_prefix('[').unwrap_or(after);
    }
    Some((key, indices))
}

/// The path of the innermost field whose key or value holds `offset` (`mesh[0].instances[1]
/// .translate`), read from the document as far as it parses.
pub(super) fn path_at(text: &str, offset: usize) -> Option<String> {
    let (document, _) = DeTable::parse_recoverable(text);
    field_in_table(document.get_ref(), offset, "")
}

fn field_in_table(table: &DeTable, offset: usize, prefix: &str) -> Option<String> {
    table.iter().find_map(|(key, value)| {
        let path =
            if prefix.is_empty() { key.get_ref().to_string() } else { format!("{prefix}.{}", key.get_ref()) };
        // A table's span is its header only: look inside it whatever its span.
        field_in_value(value, offset, &path).or_else(|| key.span().contains(&offset).then_some(path))
    })
}

fn field_in_value(value: &Spanned<DeValue>, offset: usize, path: &str) -> Option<String> {
    let inner = match value.get_ref() {
        DeValue::Table(table) => field_in_table(table, offset, path),
        // Tables in arrays are fields of their own (`instances[1]`); other items are part of
        // their array's value.
        DeValue::Array(items) => items.iter().enumerate().find_map(|(index, item)| match item.get_ref() {
            DeValue::Table(_) => field_in_value(item, offset, &format!("{path}[{index}]")),
            _ => None,
        }),
        _ => None,
    };
    inner.or_else(|| value.span().contains(&offset).then(|| path.to_owned()))
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "[camera]\nfov = 40\n\n[[mesh]]\nfile = \"a.obj\"\ninstances = [\n  { translate = [0, 0, 0] },\n  { translate = [1, 0, 0], scale = 2 },\n]\n\n[[light]]\ntype = \"point\"\nintensity = [1, 1, 1]\n";

    fn line(offset: usize) -> usize {
        TEXT[..offset].matches('\n').count() + 1
    }

    #[test]
    fn paths_find_their_values_and_values_their_paths() {
        for (path, expected_line) in [
            ("camera.fov", 2),
            ("mesh[0].file", 5),
            ("mesh[0].instances[1].scale", 8),
            ("mesh[0].instances[1]", 8),
            ("light[0].intensity", 13),
        ] {
            let span = value_span(TEXT, path).unwrap_or_else(|| panic!("{path}"));
            assert_eq!(line(span.start), expected_line, "{path}");
            assert_eq!(path_at(TEXT, span.start).as_deref(), Some(path), "{path}");
        }
        assert_eq!(value_span(TEXT, "light[1].intensity"), None);
        assert_eq!(value_span(TEXT, "mesh[0].file.x"), None);
        assert_eq!(split_indices("a[1][22]"), Some(("a", vec![1, 22])));
        assert_eq!(split_indices("a[x]"), None);
    }
}
