//! A recursive-descent RON scanner: comments, strings (raw too), chars, numbers, identifiers,
//! brackets and `#![...]` attributes. It checks only the shape, which ron has already accepted.

use crate::spans::{Kind, Node};

/// A scan failure at a byte offset.
#[derive(Debug)]
pub(crate) struct ScanError {
    pub at: usize,
    pub message: String,
}

/// Scans a whole RON document (attributes, one value, nothing after it).
pub(crate) fn scan(src: &str) -> Result<Node, ScanError> {
    let mut s = Scanner {
        src,
        pos: 0,
        depth: 0,
    };
    s.skip_ws()?;
    while s.rest().starts_with("#!") {
        s.attribute()?;
        s.skip_ws()?;
    }
    let value = s.value()?;
    s.skip_ws()?;
    if s.pos < src.len() {
        return Err(s.error("unexpected text after the end of the scene; expected nothing"));
    }
    Ok(value)
}

const MAX_DEPTH: usize = 256;
/// How deep ron lets values nest (its default `recursion_limit`, which guards its stack): the
/// limit a scene meets first.
pub(crate) const RECURSION_LIMIT: usize = 128;

struct Scanner<'a> {
    src: &'a str,
    pos: usize,
    depth: usize,
}

impl<'a> Scanner<'a> {
    fn rest(&self) -> &'a str {
        &self.src[self.pos..]
    }

    fn peek(&self) -> Option<char> {
        self.rest().chars().next()
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.peek()?;
        self.pos += c.len_utf8();
        Some(c)
    }

    fn error(&self, message: &str) -> ScanError {
        ScanError {
            at: self.pos,
            message: message.to_string(),
        }
    }

    fn expect(&mut self, c: char, message: &str) -> Result<(), ScanError> {
        if self.peek() == Some(c) {
            self.pos += 1;
            Ok(())
        } else {
            Err(self.error(message))
        }
    }

    fn skip_ws(&mut self) -> Result<(), ScanError> {
        loop {
            let rest = self.rest();
            if let Some(c) = rest.chars().next().filter(|c| c.is_whitespace()) {
                self.pos += c.len_utf8();
            } else if rest.starts_with("//") {
                self.pos += rest.find('\n').unwrap_or(rest.len());
            } else if rest.starts_with("/*") {
                self.block_comment()?;
            } else {
                return Ok(());
            }
        }
    }

    fn block_comment(&mut self) -> Result<(), ScanError> {
        let start = self.pos;
        let mut depth = 0usize;
        loop {
            let rest = self.rest();
            if rest.starts_with("/*") {
                depth += 1;
                self.pos += 2;
            } else if rest.starts_with("*/") {
                depth -= 1;
                self.pos += 2;
                if depth == 0 {
                    return Ok(());
                }
            } else if self.bump().is_none() {
                return Err(ScanError {
                    at: start,
                    message: "unclosed block comment; expected `*/`".into(),
                });
            }
        }
    }

    /// `#![enable(...)]`: skipped, brackets balanced.
    fn attribute(&mut self) -> Result<(), ScanError> {
        self.pos += 2;
        self.expect('[', "expected `[` after `#!`")?;
        let mut depth = 1;
        while depth > 0 {
            match self.bump() {
                Some('[') => depth += 1,
                Some(']') => depth -= 1,
                Some(_) => {}
                None => return Err(self.error("unclosed attribute; expected `]`")),
            }
        }
        Ok(())
    }

    fn value(&mut self) -> Result<Node, ScanError> {
        if self.depth >= MAX_DEPTH {
            return Err(self.error(&format!(
                "values are nested more than {MAX_DEPTH} levels deep; expected at most \
                 {RECURSION_LIMIT} levels of brackets"
            )));
        }
        self.depth += 1;
        let node = self.value_inner();
        self.depth -= 1;
        node
    }

    fn value_inner(&mut self) -> Result<Node, ScanError> {
        let start = self.pos;
        let rest = self.rest();
        let leaf = |s: &mut Self, kind| Node {
            start,
            end: s.pos,
            kind,
        };
        match self.peek() {
            None => Err(self.error("unexpected end of file; expected a value")),
            Some('(') => self.parens(start, None),
            Some('[') => {
                self.pos += 1;
                let items = self.sequence(']')?;
                Ok(leaf(self, Kind::List(items)))
            }
            Some('{') => self.map(start),
            Some('"') => {
                self.string()?;
                Ok(leaf(self, Kind::Str))
            }
            Some('\'') => {
                self.char_literal()?;
                Ok(leaf(self, Kind::Char))
            }
            _ if rest.starts_with("r\"") || rest.starts_with("r#\"") || rest.starts_with("r##") => {
                self.pos += 1;
                self.raw_string()?;
                Ok(leaf(self, Kind::Str))
            }
            _ if rest.starts_with("b\"") => {
                self.pos += 1;
                self.string()?;
                Ok(leaf(self, Kind::Str))
            }
            _ if rest.starts_with("br\"") || rest.starts_with("br#") => {
                self.pos += 2;
                self.raw_string()?;
                Ok(leaf(self, Kind::Str))
            }
            _ if rest.starts_with("b'") => {
                self.pos += 1;
                self.char_literal()?;
                Ok(leaf(self, Kind::Char))
            }
            Some(c) if c.is_ascii_digit() || matches!(c, '+' | '-' | '.') => {
                self.number()?;
                Ok(leaf(self, Kind::Number))
            }
            Some(c) if is_ident_start(c) => {
                let name = self.identifier()?;
                if is_float_word(&name) {
                    return Ok(leaf(self, Kind::Number));
                }
                let after_name = self.pos;
                self.skip_ws()?;
                if self.peek() == Some('(') {
                    self.parens(start, Some(name))
                } else {
                    self.pos = after_name;
                    Ok(leaf(self, Kind::Ident))
                }
            }
            Some(_) => Err(self.error("unexpected character; expected a value")),
        }
    }

    /// `( ... )`: a struct when it starts with `name:`, else a tuple.
    fn parens(&mut self, start: usize, name: Option<String>) -> Result<Node, ScanError> {
        self.pos += 1;
        self.skip_ws()?;
        let kind = if self.starts_field()? {
            Kind::Struct(self.fields()?)
        } else {
            Kind::Tuple(name, self.sequence(')')?)
        };
        Ok(Node {
            start,
            end: self.pos,
            kind,
        })
    }

    fn starts_field(&mut self) -> Result<bool, ScanError> {
        let saved = self.pos;
        let is_field = match self.peek() {
            Some(c) if is_ident_start(c) && !self.rest().starts_with("r\"") => {
                self.identifier().is_ok() && {
                    self.skip_ws()?;
                    self.rest().starts_with(':') && !self.rest().starts_with("::")
                }
            }
            _ => false,
        };
        self.pos = saved;
        Ok(is_field)
    }

    fn fields(&mut self) -> Result<Vec<(String, Node)>, ScanError> {
        let mut fields = Vec::new();
        loop {
            self.skip_ws()?;
            if self.peek() == Some(')') {
                self.pos += 1;
                return Ok(fields);
            }
            let name = self.identifier()?;
            self.skip_ws()?;
            self.expect(':', "expected `:` after the field name")?;
            self.skip_ws()?;
            fields.push((name, self.value()?));
            if !self.separator(')')? {
                return Err(self.error("expected `,` or `)`"));
            }
        }
    }

    /// Comma-separated values up to `close`.
    fn sequence(&mut self, close: char) -> Result<Vec<Node>, ScanError> {
        let mut items = Vec::new();
        loop {
            self.skip_ws()?;
            if self.peek() == Some(close) {
                self.pos += 1;
                return Ok(items);
            }
            items.push(self.value()?);
            if !self.separator(close)? {
                return Err(self.error(&format!("expected `,` or `{close}`")));
            }
        }
    }

    fn map(&mut self, start: usize) -> Result<Node, ScanError> {
        self.pos += 1;
        let mut entries = Vec::new();
        loop {
            self.skip_ws()?;
            if self.peek() == Some('}') {
                self.pos += 1;
                break;
            }
            let key = self.value()?;
            self.skip_ws()?;
            self.expect(':', "expected `:` after the map key")?;
            self.skip_ws()?;
            entries.push((key, self.value()?));
            if !self.separator('}')? {
                return Err(self.error("expected `,` or `}`"));
            }
        }
        Ok(Node {
            start,
            end: self.pos,
            kind: Kind::Map(entries),
        })
    }

    /// After an element: a comma (consumed), or the closing bracket (left for the caller).
    fn separator(&mut self, close: char) -> Result<bool, ScanError> {
        self.skip_ws()?;
        match self.peek() {
            Some(',') => {
                self.pos += 1;
                Ok(true)
            }
            Some(c) => Ok(c == close),
            None => Ok(false),
        }
    }

    fn identifier(&mut self) -> Result<String, ScanError> {
        let start = self.pos;
        if self.rest().starts_with("r#") {
            self.pos += 2;
            let len = self.run_len(|c| c.is_alphanumeric() || "_.+-".contains(c));
            self.pos += len;
            if len == 0 {
                return Err(self.error("expected an identifier after `r#`"));
            }
            return Ok(self.src[start + 2..self.pos].to_string());
        }
        match self.peek() {
            Some(c) if is_ident_start(c) => {
                self.pos += self.run_len(|c| c.is_alphanumeric() || c == '_');
                Ok(self.src[start..self.pos].to_string())
            }
            _ => Err(self.error("expected a field name")),
        }
    }

    fn run_len(&self, accept: impl Fn(char) -> bool) -> usize {
        self.rest()
            .char_indices()
            .find(|&(_, c)| !accept(c))
            .map_or(self.rest().len(), |(i, _)| i)
    }

    /// Sign, then `inf`/`NaN` or digits, letters (hex, suffixes), `_`, `.` and exponent signs.
    fn number(&mut self) -> Result<(), ScanError> {
        if matches!(self.peek(), Some('+' | '-')) {
            self.pos += 1;
            if self.peek().is_some_and(is_ident_start) {
                let word = self.identifier()?;
                return if is_float_word(&word) {
                    Ok(())
                } else {
                    Err(self.error("expected a number after the sign"))
                };
            }
        }
        let start = self.pos;
        let hex = self.rest().starts_with("0x") || self.rest().starts_with("0X");
        let mut prev = ' ';
        while let Some(c) = self.peek() {
            let exponent_sign = matches!(c, '+' | '-') && matches!(prev, 'e' | 'E') && !hex;
            let dot = c == '.' && !self.rest().starts_with("..");
            if !(c.is_ascii_alphanumeric() || c == '_' || dot || exponent_sign) {
                break;
            }
            prev = c;
            self.pos += 1;
        }
        if self.pos == start {
            return Err(self.error("expected a number"));
        }
        Ok(())
    }

    /// A `"..."` string; the cursor is on the opening quote.
    fn string(&mut self) -> Result<(), ScanError> {
        let start = self.pos;
        self.pos += 1;
        loop {
            match self.bump() {
                Some('"') => return Ok(()),
                Some('\\') => {
                    self.bump();
                }
                Some(_) => {}
                None => {
                    return Err(ScanError {
                        at: start,
                        message: "unclosed string; expected a closing `\"`".into(),
                    })
                }
            }
        }
    }

    /// `#..#"..."#..#`; the cursor is just after the `r`.
    fn raw_string(&mut self) -> Result<(), ScanError> {
        let start = self.pos;
        let hashes = self.run_len(|c| c == '#');
        self.pos += hashes;
        self.expect('"', "expected `\"` to open the raw string")?;
        let close = format!("\"{}", "#".repeat(hashes));
        match self.rest().find(&close) {
            Some(i) => {
                self.pos += i + close.len();
                Ok(())
            }
            None => Err(ScanError {
                at: start,
                message: format!("unclosed raw string; expected `{close}`"),
            }),
        }
    }

    /// `'c'` or `'\n'`; the cursor is on the opening quote.
    fn char_literal(&mut self) -> Result<(), ScanError> {
        self.pos += 1;
        if self.bump() == Some('\\') {
            // Escapes run to the closing quote (`\u{1F600}`, `\x41`, `\'`).
            self.bump();
            let len = self.run_len(|c| c != '\'' && c != '\n');
            self.pos += len;
        }
        self.expect('\'', "expected `'` to close the character")
    }
}

fn is_ident_start(c: char) -> bool {
    c.is_alphabetic() || c == '_'
}

/// Float literals that look like identifiers.
fn is_float_word(word: &str) -> bool {
    let base = word
        .strip_suffix("f32")
        .or_else(|| word.strip_suffix("f64"))
        .unwrap_or(word);
    base == "inf" || base == "NaN"
}

/// The first offset from `from` that is not blank or in a comment (`from` if a comment is open).
pub(crate) fn skip_blank(src: &str, from: usize) -> usize {
    let mut s = Scanner {
        src,
        pos: from,
        depth: 0,
    };
    match s.skip_ws() {
        Ok(()) => s.pos,
        Err(_) => from,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn text<'a>(src: &'a str, node: &Node) -> &'a str {
        &src[node.start..node.end]
    }

    #[test]
    fn finds_fields_items_and_entries() {
        let src = r#"#![enable(implicit_some)]
// comment with ( and "
Scene( /* nested /* block */ comment */
    objects: [ (plugin: "sphere", params: Foo(a: [1, 2], b: {"x": -1e-3}), m: Some("r")) ],
    materials: { "a\"b": (c: 'x'), r"raw": (c: '\n') },
    n: -inf, h: 0x1F, t: true,
)"#;
        let root = scan(src).unwrap();
        let object = root.field("objects").unwrap().item(0).unwrap();
        assert!(text(src, object).starts_with("(plugin"));
        assert_eq!(text(src, object.field("plugin").unwrap()), "\"sphere\"");
        assert_eq!(
            text(src, object.raw_field("params").unwrap()),
            r#"Foo(a: [1, 2], b: {"x": -1e-3})"#
        );
        assert_eq!(text(src, object.field("m").unwrap()), "\"r\"");
        let (key, value) = root.field("materials").unwrap().entry(1).unwrap();
        assert_eq!(text(src, key), "r\"raw\"");
        assert_eq!(text(src, value.field("c").unwrap()), "'\\n'");
        let mut numbers = Vec::new();
        root.each_number(&mut |n| {
            numbers.push(text(src, n).to_string());
            Ok::<(), ()>(())
        })
        .unwrap();
        assert_eq!(numbers, ["1", "2", "-1e-3", "-inf", "0x1F"]);
    }

    #[test]
    fn reports_unclosed_things() {
        assert_eq!(scan("(a: \"x)").unwrap_err().at, 4);
        assert_eq!(scan("(a: 1 /* x").unwrap_err().at, 6);
        assert!(scan("(a: 1) x").is_err());
    }

    #[test]
    fn skips_blanks_and_comments() {
        assert_eq!(skip_blank("a  /* x */ // y\n b", 1), 17);
        assert_eq!(skip_blank("a /* open", 1), 1);
    }
}
