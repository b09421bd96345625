//! `--vary texture_filter`: rewrites the `filter` of every image texture in a scene's RON
//! params text (the `image` plugin's own params and `Image(...)` inputs nested in texture
//! trees), before the scene is built. Text in strings and comments is left alone.

/// `params` with the `filter` of each image texture set to `filter` (inserted where absent),
/// and how many image textures it changed. `top`: the params are an `image` texture's own.
pub fn set_image_filter(params: &str, filter: &str, top: bool) -> (String, usize) {
    let b = params.as_bytes();
    // (position, bytes removed, text inserted), in increasing position.
    let mut edits: Vec<(usize, usize, String)> = Vec::new();
    // Open parentheses: for an image texture's, where a `filter` would go and whether it has
    // one; None for others.
    let mut stack: Vec<Option<(usize, bool)>> = Vec::new();
    let mut seen_first = false;
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
            }
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                i += 2;
                while i + 1 < b.len() && !(b[i] == b'*' && b[i + 1] == b'/') {
                    i += 1;
                }
                i += 2;
            }
            b'(' => {
                let before = params[..i].trim_end();
                let named_image = before.ends_with("Image")
                    && !before[..before.len() - 5]
                        .ends_with(|c: char| c.is_ascii_alphanumeric() || c == '_');
                let image = named_image || (top && !seen_first);
                seen_first = true;
                stack.push(image.then_some((i + 1, false)));
                i += 1;
            }
            b')' => {
                if let Some(Some((pos, false))) = stack.pop() {
                    // No `filter` field: insert one after the `(`.
                    edits.push((pos, 0, format!("filter: {filter}, ")));
                }
                i += 1;
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                let start = i;
                while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                    i += 1;
                }
                let in_image = matches!(stack.last(), Some(Some(_)));
                if in_image && &params[start..i] == "filter" {
                    let rest = &params[i..];
                    let after_colon = rest.trim_start();
                    if let Some(value) = after_colon.strip_prefix(':') {
                        let v_start = i
                            + (rest.len() - value.len())
                            + (value.len() - value.trim_start().len());
                        let v_len = params[v_start..]
                            .bytes()
                            .take_while(|c| c.is_ascii_alphanumeric() || *c == b'_')
                            .count();
                        edits.push((v_start, v_len, filter.to_string()));
                        if let Some(Some((_, found))) = stack.last_mut() {
                            *found = true;
                        }
                        i = v_start + v_len;
                    }
                }
            }
            _ => i += 1,
        }
    }
    let changed = edits.len();
    let mut out = params.to_string();
    edits.sort_by_key(|e| e.0);
    for (pos, len, text) in edits.into_iter().rev() {
        out.replace_range(pos..pos + len, &text);
    }
    (out, changed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_or_inserts_the_filter() {
        let f = |p, top| set_image_filter(p, "nearest", top);
        assert_eq!(
            f(r#"(file: "a.png", filter: mip, wrap: clamp)"#, true),
            (r#"(file: "a.png", filter: nearest, wrap: clamp)"#.into(), 1)
        );
        assert_eq!(
            f(r#"(file: "a.png")"#, true),
            (r#"(filter: nearest, file: "a.png")"#.into(), 1)
        );
        assert_eq!(f("()", true), ("(filter: nearest, )".into(), 1));
        // Nested inputs of a tree; strings and comments are not touched.
        assert_eq!(
            f(
                r#"(even: Image(file: "filter: x(", filter: Bilinear), odd: Image(), scale: 2 /* Image( */)"#,
                false
            ),
            (
                r#"(even: Image(file: "filter: x(", filter: nearest), odd: Image(filter: nearest, ), scale: 2 /* Image( */)"#
                    .into(),
                2
            )
        );
        // Not an image texture: unchanged.
        assert_eq!(f("(scale: 0.5, even: (1, 1, 1))", false).1, 0);
        assert_eq!(f("(odd: MyImage(x: 1))", false).1, 0);
    }
}
