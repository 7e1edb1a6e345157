//! Wavefront text (OBJ and MTL) as statements: one per line, its `#` comment cut, split into
//! its keyword and the rest. Both formats are read this way before `tobj` sees them.

/// One line of a Wavefront text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Statement<'a> {
    /// 1-based line number.
    pub line: usize,
    /// The line without its comment, trimmed.
    pub text: &'a str,
    /// Its first word (empty for an empty line).
    pub keyword: &'a str,
    /// The trimmed rest after the keyword.
    pub rest: &'a str,
}

/// The statements of `text`, one per line, empty lines included.
pub(crate) fn statements(text: &str) -> impl Iterator<Item = Statement<'_>> {
    text.lines().enumerate().map(|(index, raw)| {
        let line = strip_comment(raw).trim();
        let (keyword, rest) = split_keyword(line);
        Statement { line: index + 1, text: line, keyword, rest }
    })
}

/// Cuts a `#` comment: at the start of the line or after white space, so that a `#` inside a
/// file name (`wall#2.png`) survives.
fn strip_comment(line: &str) -> &str {
    let bytes = line.as_bytes();
    match (0..bytes.len()).find(|&i| bytes[i] == b'#' && (i == 0 || bytes[i - 1].is_ascii_whitespace())) {
        Some(i) => &line[..i],
        None => line,
    }
}

/// Splits a trimmed line into its first word and the trimmed rest.
fn split_keyword(line: &str) -> (&str, &str) {
    match line.split_once(|c: char| c.is_whitespace()) {
        Some((keyword, rest)) => (keyword, rest.trim()),
        None => (line, ""),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_are_stripped() {
        assert_eq!(strip_comment("map_Kd a#1.png # old"), "map_Kd a#1.png ");
        assert_eq!(strip_comment("#Ke 1 1 1"), "");
    }
}
