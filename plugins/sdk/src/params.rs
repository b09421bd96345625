//! Errors that point at a parameter: where each top-level field of a params text is, what a
//! type error found there and what the plugin's parameter table says was expected.

use crate::Error;

/// One top-level `name: value` of a params text (byte offsets into it).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Field<'a> {
    pub name: &'a str,
    /// Where the name starts.
    pub at: usize,
    /// The value's text, trimmed.
    pub value: &'a str,
    pub value_at: usize,
}

/// The `name: value` fields directly inside the outermost brackets of `text`, in order. Strings,
/// comments and nested brackets are skipped; anything that does not look like a field is
/// ignored (the RON parser reports it).
pub(crate) fn fields(text: &str) -> Vec<Field<'_>> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut depth = 0usize;
    // The field being read: its name, where that starts, and where its value starts.
    let mut open: Option<(usize, usize, usize)> = None;
    let mut item_start: Option<usize> = None;
    let mut close = |open: &mut Option<(usize, usize, usize)>, end: usize| {
        if let Some((at, name_end, value_at)) = open.take() {
            let raw = &text[value_at..end];
            let lead = raw.len() - raw.trim_start().len();
            out.push(Field {
                name: &text[at..name_end],
                at,
                value: raw.trim(),
                value_at: value_at + lead,
            });
        }
    };
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        match c {
            b'"' => i = skip_string(bytes, i),
            b'/' if matches!(bytes.get(i + 1), Some(b'/' | b'*')) => {
                i = skip_comment(text, i);
                // A comment before a field's name is not part of it.
                if depth == 1 && open.is_none() && item_start.is_some() {
                    item_start = Some(i);
                }
                continue;
            }
            b'(' | b'[' | b'{' => {
                depth += 1;
                if depth == 1 {
                    item_start = Some(i + 1);
                }
            }
            b')' | b']' | b'}' => {
                if depth == 1 {
                    close(&mut open, i);
                    item_start = None;
                }
                depth = depth.saturating_sub(1);
            }
            b',' if depth == 1 => {
                close(&mut open, i);
                item_start = Some(i + 1);
            }
            b':' if depth == 1 && open.is_none() => {
                if let Some(start) = item_start.take() {
                    let key = text[start..i].trim();
                    if is_identifier(key) {
                        let at = start + text[start..i].find(key).unwrap_or(0);
                        open = Some((at, at + key.len(), i + 1));
                    }
                }
            }
            _ => {}
        }
        i += 1;
    }
    out
}

/// The index of the byte after the comment starting at `i` (`//` or `/*`).
fn skip_comment(text: &str, i: usize) -> usize {
    if text[i..].starts_with("//") {
        text[i..].find('\n').map_or(text.len(), |k| i + k)
    } else {
        text[i + 2..]
            .find("*/")
            .map_or(text.len(), |k| i + 2 + k + 2)
    }
}

/// The index of the first byte from `i` on that is neither white space nor in a comment.
fn skip_blank(text: &str, mut i: usize) -> usize {
    loop {
        let rest = &text[i..];
        let trimmed = rest.trim_start();
        i += rest.len() - trimmed.len();
        if trimmed.starts_with("//") || trimmed.starts_with("/*") {
            i = skip_comment(text, i);
        } else {
            return i;
        }
    }
}

/// The index of the closing `"` of the string starting at `i` (a `"`), escapes skipped.
fn skip_string(bytes: &[u8], mut i: usize) -> usize {
    i += 1;
    while i < bytes.len() {
        match bytes[i] {
            b'\\' => i += 2,
            b'"' => return i,
            _ => i += 1,
        }
    }
    i
}

fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// 1-based line and column (in characters) of byte `offset` of `text`.
pub(crate) fn line_col(text: &str, offset: usize) -> (u32, u32) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().unwrap_or("").chars().count() + 1;
    (line as u32, col as u32)
}

/// The byte offset of 1-based `line`:`col` (in characters) in `text`, if it is inside it.
fn offset_of(text: &str, line: usize, col: usize) -> Option<usize> {
    let mut start = 0;
    for _ in 1..line {
        start += text[start..].find('\n')? + 1;
    }
    let rest = &text[start..];
    match rest.char_indices().nth(col.checked_sub(1)?) {
        Some((k, _)) => Some(start + k),
        None => (col - 1 == rest.chars().count()).then_some(text.len()),
    }
}

/// How a parameter table line (`name: type = default  meaning`) writes `name`'s type.
fn documented_type<'a>(doc: &'a str, name: &str) -> Option<&'a str> {
    doc.lines().find_map(|line| {
        let rest = line.trim_start().strip_prefix(name)?.strip_prefix(':')?;
        let ty = rest.split("  ").next()?.split(" = ").next()?.trim();
        (!ty.is_empty()).then_some(ty)
    })
}

/// A documented type in words: `f64 > 0` is "a number > 0", `x|y|z` is "one of `x`, `y`, `z`".
fn in_words(ty: &str) -> String {
    let words: Vec<&str> = ty.split('|').collect();
    if words.len() > 1 && words.iter().all(|w| is_identifier(w)) {
        return one_of(words.iter().copied());
    }
    for (rust, said) in [
        ("f64", "a number"),
        ("f32", "a number"),
        ("u64", "a whole number"),
        ("u32", "a whole number"),
        ("usize", "a whole number"),
        ("i64", "a whole number"),
        ("i32", "a whole number"),
        ("bool", "`true` or `false`"),
        ("path", "a path in double quotes"),
        ("string", "text in double quotes"),
    ] {
        if let Some(rest) = ty.strip_prefix(rust) {
            if rest.is_empty() || rest.starts_with(' ') {
                return format!("{said}{rest}");
            }
        }
    }
    ty.to_string()
}

fn one_of<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let names: Vec<String> = names.map(|n| format!("`{n}`")).collect();
    format!("one of {}", names.join(", "))
}

/// What RON expected, in words, for the errors that are about a value's type.
fn expected_by_ron(code: &ron::Error) -> Option<String> {
    use ron::Error as E;
    Some(match code {
        E::ExpectedFloat => "a number".into(),
        E::ExpectedInteger | E::IntegerOutOfBounds | E::InvalidIntegerDigit { .. } => {
            "a whole number".into()
        }
        E::ExpectedBoolean => "`true` or `false`".into(),
        E::ExpectedString | E::ExpectedStringEnd => "text in double quotes".into(),
        E::ExpectedIdentifier => "a name without quotes".into(),
        E::ExpectedChar => "a character in single quotes".into(),
        E::ExpectedArray | E::ExpectedArrayEnd => "a list `[...]`".into(),
        E::ExpectedStructLike | E::ExpectedStructLikeEnd | E::ExpectedNamedStructLike(_) => {
            "a value in brackets `(...)`".into()
        }
        E::ExpectedUnit => "`()`".into(),
        E::ExpectedMap | E::ExpectedMapEnd => "a map `{...}`".into(),
        E::ExpectedOption | E::ExpectedOptionEnd => "`Some(...)` or `None`".into(),
        E::InvalidValueForType { expected, .. } => expected.clone(),
        E::ExpectedDifferentLength { expected, .. } => expected.clone(),
        E::NoSuchEnumVariant { expected, .. } => one_of(expected.iter().copied()),
        _ => return None,
    })
}

/// `s`, cut to about 40 characters.
fn shorten(s: &str) -> String {
    let s = s.split_whitespace().collect::<Vec<_>>().join(" ");
    if s.chars().count() <= 40 {
        s
    } else {
        format!("{}...", s.chars().take(37).collect::<String>())
    }
}

/// `at`, or the opening quote of the string it is in (reading from `from`, outside any string).
fn string_start(text: &str, from: usize, at: usize) -> usize {
    let bytes = text.as_bytes();
    let mut i = from;
    while i < at {
        if bytes[i] == b'"' {
            let end = skip_string(bytes, i);
            if at <= end {
                return i;
            }
            i = end;
        }
        i += 1;
    }
    at
}

/// Where the bracketed group closed at byte `end` (a `)` or `]`) opens; `end` for anything else.
fn group_start(text: &str, end: usize) -> usize {
    let bytes = text.as_bytes();
    if !matches!(bytes.get(end), Some(b')' | b']')) {
        return end;
    }
    let mut depth = 0usize;
    for i in (0..=end).rev() {
        match bytes[i] {
            b')' | b']' => depth += 1,
            b'(' | b'[' => {
                depth -= 1;
                if depth == 0 {
                    return i;
                }
            }
            _ => {}
        }
    }
    end
}

/// The value starting at byte `at`: a string, a bracketed group or a single token.
fn value_at(text: &str, at: usize) -> &str {
    let rest = &text[at..];
    let bytes = rest.as_bytes();
    let end = match bytes.first() {
        None => 0,
        Some(b'"') => (skip_string(bytes, 0) + 1).min(bytes.len()),
        Some(b'(' | b'[' | b'{') => {
            let mut depth = 0usize;
            let mut i = 0;
            loop {
                match bytes.get(i) {
                    None => break i,
                    Some(b'"') => i = skip_string(bytes, i),
                    Some(b'(' | b'[' | b'{') => depth += 1,
                    Some(b')' | b']' | b'}') => {
                        depth -= 1;
                        if depth == 0 {
                            break i + 1;
                        }
                    }
                    _ => {}
                }
                i += 1;
            }
        }
        Some(_) => rest
            .find(|c: char| c.is_whitespace() || ",)]}".contains(c))
            .unwrap_or(rest.len()),
    };
    &rest[..end]
}

/// An error of RON at `line`:`col` of `text` inside the value of a top-level parameter, in
/// words naming it: for a type error "parameter `color`: expected (r, g, b), found `"red"`"
/// (`doc` is the plugin's parameter table: a parameter's type as written there is what was
/// expected), for any other "parameter `even`: " and RON's words. Also where the value found
/// starts (RON's position may be the blank before it, or inside a string). `None` when the
/// error is not inside one parameter's value (an unknown or missing parameter).
pub(crate) fn type_error(
    text: &str,
    doc: &str,
    code: &ron::Error,
    line: usize,
    col: usize,
) -> Option<(String, (u32, u32))> {
    let mut offset = skip_blank(text, offset_of(text, line, col)?);
    if matches!(code, ron::Error::ExpectedDifferentLength { .. }) {
        // RON stops at the closing bracket of a tuple of the wrong length: point at its start.
        offset = group_start(text, offset);
    }
    let field = fields(text)
        .into_iter()
        .rfind(|f| f.value_at <= offset && offset < f.value_at + f.value.len())?;
    offset = string_start(text, field.value_at, offset);
    let Some(by_ron) = expected_by_ron(code) else {
        if matches!(
            code,
            ron::Error::MissingStructField { .. } | ron::Error::ExceededRecursionLimit
        ) {
            return None;
        }
        let message = format!(
            "parameter `{}`: {}",
            field.name,
            crate::describe_ron_error(code)
        );
        return Some((message, line_col(text, offset)));
    };
    let expected = match (code, documented_type(doc, field.name)) {
        // The variants RON lists are exact; a documented type may say more (`f64 > 0`).
        (ron::Error::NoSuchEnumVariant { .. }, _) | (_, None) => by_ron,
        (_, Some(ty)) => in_words(ty),
    };
    let found = match code {
        ron::Error::ExpectedDifferentLength { found, .. } => {
            format!("{found} value(s) `{}`", shorten(value_at(text, offset)))
        }
        ron::Error::NoSuchEnumVariant { found, .. } => format!("`{found}`"),
        _ => {
            let token = value_at(text, offset);
            let token = if token.is_empty() { field.value } else { token };
            format!("`{}`", shorten(token))
        }
    };
    let unquote = if found.starts_with("`\"") && expected.starts_with("one of") {
        " (written without quotes)"
    } else {
        ""
    };
    let message = format!(
        "parameter `{}`: expected {expected}{unquote}, found {found}",
        field.name
    );
    Some((message, line_col(text, offset)))
}

/// The top-level parameter an error's message names first (`parameter `name`...`), if any:
/// `radii` for "parameter `radii[2]`", `size` for "parameter `size.0 (width)`".
fn named_parameter(message: &str) -> Option<&str> {
    let rest = message.strip_prefix("parameter `")?;
    let name = &rest[..rest.find('`')?];
    Some(name.split(['[', '.', ' ', '(']).next().unwrap_or(name))
}

/// An error from a plugin's own code, placed at the parameter its message names when it has no
/// position yet: `Error::invalid_at("width", ...)` points at `width:` in `text`. A parameter
/// the text does not give (it took its default) leaves the error at the start of the params.
pub(crate) fn place(mut e: Error, text: &str) -> Error {
    if e.line == 0 {
        if let Some(name) = named_parameter(&e.message) {
            if let Some(f) = fields(text).into_iter().find(|f| f.name == name) {
                (e.line, e.col) = line_col(text, f.at);
            }
        }
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_found_at_the_top_level_only() {
        let text = "(\n  a: (1, 2), // b: 3\n  c: \"x, y: z\" /* d: 4 */,\n  e: [(f: 1)],\n)";
        let f = fields(text);
        let names: Vec<&str> = f.iter().map(|f| f.name).collect();
        assert_eq!(names, ["a", "c", "e"]);
        assert_eq!(f[0].value, "(1, 2)");
        assert_eq!(line_col(text, f[1].at), (3, 3));
        assert_eq!(f[1].value, "\"x, y: z\" /* d: 4 */");
        assert_eq!(f[2].value, "[(f: 1)]");
        assert_eq!(&text[f[2].value_at..f[2].value_at + 1], "[");
        assert!(fields("").is_empty());
        assert!(fields("()").is_empty());
    }

    #[test]
    fn positions_convert_both_ways() {
        let text = "(a: 1,\n é: 2)";
        let at = text.find('2').unwrap();
        assert_eq!(line_col(text, at), (2, 5));
        assert_eq!(offset_of(text, 2, 5), Some(at));
        assert_eq!(offset_of(text, 3, 1), None);
    }

    #[test]
    fn documented_types_are_put_in_words() {
        let doc = "color: (r, g, b) = (1, 1, 1)  the colour\nradius: f64 > 0  radius\n\
                   mapping: uv|planar = uv  how\ncaps: bool = true  ends";
        let words = |n| documented_type(doc, n).map(in_words);
        assert_eq!(words("color").as_deref(), Some("(r, g, b)"));
        assert_eq!(words("radius").as_deref(), Some("a number > 0"));
        assert_eq!(words("mapping").as_deref(), Some("one of `uv`, `planar`"));
        assert_eq!(words("caps").as_deref(), Some("`true` or `false`"));
        assert_eq!(words("colour"), None);
    }

    #[test]
    fn values_are_cut_at_their_end() {
        assert_eq!(value_at("\"a, b\" x", 0), "\"a, b\"");
        assert_eq!(value_at("(1, (2)), 3", 0), "(1, (2))");
        assert_eq!(value_at("big, 3", 0), "big");
        assert_eq!(shorten(&"x".repeat(50)), format!("{}...", "x".repeat(37)));
    }

    #[test]
    fn errors_naming_a_parameter_are_placed_at_it() {
        let text = "(\n  height: 2,\n  width: -1,\n)";
        let e = place(Error::invalid_at("width", "must be > 0, found -1"), text);
        assert_eq!(e.message, "parameter `width`: must be > 0, found -1");
        assert_eq!((e.line, e.col), (3, 3));
        // Not in the text (its default was used): no position, so the host uses the params'.
        let e = place(Error::invalid_at("depth", "must be > 0"), text);
        assert_eq!((e.line, e.col), (0, 0));
        // A position the plugin gave is kept.
        let mut given = Error::invalid_at("width", "bad");
        (given.line, given.col) = (2, 3);
        assert_eq!((place(given, text).line), 2);
    }

    #[derive(serde::Deserialize, Debug)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Stripes {
        #[serde(default)]
        width: f64,
        #[serde(default)]
        color: [f64; 3],
        #[serde(default)]
        axis: Axis,
        #[serde(default)]
        points: Vec<[f64; 3]>,
    }

    #[derive(serde::Deserialize, Debug, Default)]
    #[serde(rename_all = "lowercase")]
    enum Axis {
        #[default]
        X,
        Y,
        Z,
    }

    #[derive(serde::Deserialize, Debug)]
    #[allow(dead_code)]
    struct P2 {
        a: f64,
        b: f64,
    }

    #[derive(serde::Deserialize, Debug)]
    #[allow(dead_code)]
    struct P3 {
        a: f64,
        #[serde(deserialize_with = "odd")]
        b: f64,
    }

    fn odd<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        let s = <String as serde::Deserialize>::deserialize(d)?;
        Err(serde::de::Error::custom(format!(
            "expected an odd number, found {s:?}"
        )))
    }

    const DOC: &str = "width: f64 > 0 = 1  stripe width\ncolor: (r, g, b) = (1, 1, 1)  colour\n\
                       axis: x|y|z = x  across which axis\npoints: [(x, y, z), ...]  points";

    fn error(text: &str) -> (String, u32, u32) {
        let e = crate::parse_documented_params::<Stripes>(text, DOC).unwrap_err();
        (e.message, e.line, e.col)
    }

    #[test]
    fn type_errors_name_the_parameter_what_was_expected_and_what_was_found() {
        assert_eq!(
            error("(width: \"wide\")"),
            (
                "parameter `width`: expected a number > 0, found `\"wide\"`".into(),
                1,
                9
            )
        );
        assert_eq!(
            error("(\n  color: \"red\",\n)"),
            (
                "parameter `color`: expected (r, g, b), found `\"red\"`".into(),
                2,
                10
            )
        );
        assert_eq!(
            error("(axis: \"y\")"),
            (
                "parameter `axis`: expected one of `x`, `y`, `z` (written without quotes), \
                 found `\"y\"`"
                    .into(),
                1,
                8
            )
        );
        assert_eq!(
            error("(axis: w)").0,
            "parameter `axis`: expected one of `x`, `y`, `z`, found `w`"
        );
        assert_eq!(
            error("(color: (1, 0))"),
            (
                "parameter `color`: expected (r, g, b), found 2 value(s) `(1, 0)`".into(),
                1,
                9
            )
        );
        // In a list, the element of the wrong length.
        assert_eq!(
            error("(points: [(0, 0, 0), (1, 2)])"),
            (
                "parameter `points`: expected [(x, y, z), ...], found 2 value(s) `(1, 2)`".into(),
                1,
                22
            )
        );
        // Inside a list: the position and the value found are the element's.
        let (m, _, col) = error("(points: [(0, 0, 0), (1, true, 2)])");
        assert_eq!(
            m,
            "parameter `points`: expected [(x, y, z), ...], found `true`"
        );
        assert_eq!(col, 26);
        // Any other error inside a parameter's value names the parameter too.
        let e = crate::parse_params::<P3>("(a: 1, b: \"7\")").unwrap_err();
        assert_eq!(
            (e.message.as_str(), e.line, e.col),
            ("parameter `b`: expected an odd number, found \"7\"", 1, 11)
        );
        // A missing parameter is not blamed on the last one given.
        assert_eq!(
            crate::parse_params::<P2>("(a: 1)").unwrap_err().message,
            "missing parameter `b`"
        );
        // Without a table, RON's expectation in words.
        let e = crate::parse_params::<Stripes>("(width: (1))").unwrap_err();
        assert_eq!(
            e.message,
            "parameter `width`: expected a number, found `(1)`"
        );
    }
}
