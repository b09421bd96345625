//! ron's errors as `SceneError`s: positioned on the culprit, reworded to say what was expected.

use ron::error::SpannedError;

use crate::error::{printable, suggest, unknown_name, SceneError};
use crate::scanner::{scan, skip_blank, RECURSION_LIMIT};
use crate::spans::SourceMap;

/// ron's error, with "did you mean" for names.
pub(crate) fn ron_error(e: &SpannedError, src: &SourceMap) -> SceneError {
    // ron's span may start on the blank before the culprit; point at the culprit.
    let start = src.byte(e.span.start.line, e.span.start.col);
    let end = src.byte(e.span.end.line, e.span.end.col);
    let to = end.max(start).min(src.text.len());
    let mut at = skip_blank(&src.text[..to], start);
    // These are reported at the closing bracket; the value's start reads better.
    if matches!(
        e.code,
        ron::Error::MissingStructField { .. } | ron::Error::ExpectedDifferentLength { .. }
    ) {
        if let Some(node) = scan(&src.text)
            .ok()
            .as_ref()
            .and_then(|root| root.closed_at(at))
        {
            at = node.start;
        }
    }
    // ron's messages quote what it found: make that safe to print.
    let mut message = printable(&ron_message(&e.code)).into_owned();
    if at >= src.text.len() && !message.starts_with("unexpected end") {
        message = format!("unexpected end of file; {message}");
    }
    SceneError::at(src.origin(at), message)
}

/// What ron found wrong, saying what was expected.
fn ron_message(code: &ron::Error) -> String {
    // A gradient background is read without its name (see `raw::Background`): ron then
    // names the scene around it; its fields say whose they are.
    let within = |outer: &Option<String>, field: &str| match outer.as_deref() {
        Some("Scene") if GRADIENT_FIELDS.contains(&field) => " in `Gradient`".to_string(),
        Some(o) => format!(" in `{o}`"),
        None => String::new(),
    };
    use ron::Error as E;
    match code {
        // The keyed structs of `animation:` list exactly what can be animated.
        E::NoSuchStructField {
            expected,
            found,
            outer: Some(outer),
        } if keyed(outer).is_some() => {
            let whose = keyed(outer).unwrap_or_default();
            let mut message = format!("{whose} `{}` cannot be animated", printable(found));
            if let Some(close) = suggest(found, expected.iter().copied()) {
                message.push_str(&format!("; did you mean `{close}`?"));
            } else {
                message.push(';');
            }
            let list: Vec<String> = expected.iter().map(|e| format!("`{e}`")).collect();
            message.push_str(&format!(" expected one of {}", list.join(", ")));
            message
        }
        E::NoSuchStructField {
            expected,
            found,
            outer,
        } => {
            let whose = within(outer, expected.first().copied().unwrap_or_default());
            unknown_name("field", found, &whose, expected.iter().copied())
        }
        E::NoSuchEnumVariant {
            expected,
            found,
            outer,
        } => unknown_name(
            "variant",
            found,
            &within(outer, ""),
            expected.iter().copied(),
        ),
        E::MissingStructField { field, outer } => {
            format!(
                "missing field `{field}`{}; expected `{field}: ...`",
                within(outer, field)
            )
        }
        E::DuplicateStructField { field, outer } => {
            format!(
                "field `{field}` is given twice{}; expected it once",
                within(outer, field)
            )
        }
        E::ExpectedDifferentStructName { expected, found } => {
            let mut message = format!("found `{found}(`; expected `{expected}(` or just `(`");
            if let Some(close) = suggest(found, [*expected]) {
                message.push_str(&format!(" (did you mean `{close}`?)"));
            }
            message
        }
        E::ExpectedDifferentLength { expected, found } if expected.contains("length 3") => {
            format!("found {found} numbers; expected 3, as in `(x, y, z)`")
        }
        E::InvalidValueForType { expected, found } => format!("found {found}; expected {expected}"),
        E::ExpectedFloat | E::ExpectedInteger => "expected a number".to_string(),
        E::ExpectedString => "expected a string in double quotes".to_string(),
        E::ExpectedBoolean => "expected `true` or `false`".to_string(),
        E::ExpectedStructLike => "expected `(`".to_string(),
        E::ExpectedStructLikeEnd => "expected `,` or `)`".to_string(),
        E::ExpectedArray => "expected a list `[...]`".to_string(),
        E::ExpectedArrayEnd => "expected `,` or `]`".to_string(),
        E::ExpectedMap => "expected a map `{ \"name\": (...), ... }`".to_string(),
        E::ExpectedMapEnd => "expected `,` or `}`".to_string(),
        E::ExpectedMapColon => "expected `:` after the map key".to_string(),
        E::ExpectedComma => "expected `,` between values (or a closing bracket)".to_string(),
        E::Eof => "unexpected end of file; expected more of the scene".to_string(),
        E::ExpectedStringEnd => "unclosed string; expected a closing `\"`".to_string(),
        E::ExpectedIdentifier => "expected a name (a field name or an identifier)".to_string(),
        E::ExceededRecursionLimit => format!(
            "values are nested more than {RECURSION_LIMIT} levels deep; expected at most \
             {RECURSION_LIMIT} levels of brackets"
        ),
        E::TrailingCharacters => {
            "unexpected text after the end of the scene; expected nothing".to_string()
        }
        other => lower_first(&other.to_string()),
    }
}

fn lower_first(s: &str) -> String {
    let mut chars = s.chars();
    match chars.next() {
        Some(c) => c.to_lowercase().chain(chars).collect(),
        None => String::new(),
    }
}

/// The fields of `background: Gradient(...)`, none of them a field of `Scene`.
const GRADIENT_FIELDS: [&str; 6] = ["kind", "up", "top", "bottom", "top_color", "bottom_color"];

/// Whose properties a keyed struct of `animation:` holds, for "… cannot be animated".
fn keyed(outer: &str) -> Option<&'static str> {
    match outer {
        "CameraKeys" => Some("the camera's"),
        "LightKeys" => Some("a light's"),
        "MaterialKeys" => Some("a material's"),
        "ObjectKeys" => Some("an object's"),
        _ => None,
    }
}
