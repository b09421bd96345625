//! Words of a Tachyon scene file, with their line and column, and numbers read the way
//! Tachyon's `fscanf` reads them.
//!
//! A word is a run of characters between whitespace (C's `isspace`: space, tab, newline,
//! carriage return, vertical tab, form feed), as `%s` reads it. Keywords compare without regard
//! to case ([`is`]); names and paths keep their case. Comments are the parser's business: `#`
//! is one only as a whole word where a statement may start, and then [`Lexer::skip_line`]
//! drops the rest of its line.

use std::path::PathBuf;
use std::sync::Arc;

use crate::origin::Origin;

/// A word and where it starts (1-based line and column, in characters).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Word<'a> {
    pub text: &'a str,
    pub line: u32,
    pub col: u32,
}

/// A cursor over one file's text.
pub(super) struct Lexer<'a> {
    text: &'a str,
    pos: usize,
    line: u32,
    col: u32,
    file: Arc<PathBuf>,
}

fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c)
}

impl<'a> Lexer<'a> {
    pub fn new(text: &'a str, file: Arc<PathBuf>) -> Lexer<'a> {
        Lexer {
            text,
            pos: 0,
            line: 1,
            col: 1,
            file,
        }
    }

    /// Moves over one byte, keeping line and column (continuation bytes of a UTF-8 character
    /// do not count as columns).
    fn bump(&mut self, b: u8) {
        self.pos += 1;
        if b == b'\n' {
            self.line += 1;
            self.col = 1;
        } else if b & 0xc0 != 0x80 {
            self.col += 1;
        }
    }

    fn skip_space(&mut self) {
        let bytes = self.text.as_bytes();
        while let Some(&b) = bytes.get(self.pos) {
            if !is_space(b) {
                break;
            }
            self.bump(b);
        }
    }

    /// The next word, or `None` at the end of the text.
    pub fn next_word(&mut self) -> Option<Word<'a>> {
        self.skip_space();
        let bytes = self.text.as_bytes();
        if self.pos >= bytes.len() {
            return None;
        }
        let (start, line, col) = (self.pos, self.line, self.col);
        while let Some(&b) = bytes.get(self.pos) {
            if is_space(b) {
                break;
            }
            self.bump(b);
        }
        Some(Word {
            text: &self.text[start..self.pos],
            line,
            col,
        })
    }

    /// The next word without moving past it.
    pub fn peek(&mut self) -> Option<Word<'a>> {
        let (pos, line, col) = (self.pos, self.line, self.col);
        let word = self.next_word();
        (self.pos, self.line, self.col) = (pos, line, col);
        word
    }

    /// Drops the rest of the current line (after a `#` comment word).
    pub fn skip_line(&mut self) {
        let bytes = self.text.as_bytes();
        while let Some(&b) = bytes.get(self.pos) {
            self.bump(b);
            if b == b'\n' {
                break;
            }
        }
    }

    /// Where `word` is.
    pub fn origin(&self, word: &Word) -> Origin {
        Origin {
            file: self.file.clone(),
            line: word.line,
            col: word.col,
        }
    }

    /// Where the text ends (after any trailing whitespace).
    pub fn end(&mut self) -> Origin {
        self.skip_space();
        Origin {
            file: self.file.clone(),
            line: self.line,
            col: self.col,
        }
    }
}

/// Whether `word` is the keyword `keyword` (upper case), in any case.
pub(super) fn is(word: &str, keyword: &str) -> bool {
    word.eq_ignore_ascii_case(keyword)
}

/// Why a word is not the number wanted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum NumberError {
    /// Not a number at all.
    NotANumber,
    /// NaN, an infinity, or a value too large for a double.
    NotFinite,
    /// A number with a fraction or an exponent where `%d` reads a whole number.
    NotWhole,
    /// A whole number outside C's `int`.
    TooLarge,
}

/// A decimal floating-point number as `%f` reads one (sign, digits, point, exponent). NaN and
/// infinities (which C accepts as `nan` and `inf`) and hexadecimal floats are refused.
pub(super) fn float(text: &str) -> Result<f64, NumberError> {
    let plausible = text.bytes().any(|b| b.is_ascii_digit())
        && text
            .bytes()
            .all(|b| b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'e' | b'E'));
    if !plausible {
        return Err(NumberError::NotANumber);
    }
    match text.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(NumberError::NotFinite),
        Err(_) => Err(NumberError::NotANumber),
    }
}

/// A whole number as `%d` reads one: an optional sign and digits, within C's `int`. `1.0`
/// (which `%d` would read as 1, leaving `.0` for the next field) is refused.
pub(super) fn int(text: &str) -> Result<i64, NumberError> {
    let digits = text.strip_prefix(['+', '-']).unwrap_or(text);
    if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
        return match text.parse::<i64>() {
            Ok(n) if i32::try_from(n).is_ok() => Ok(n),
            _ => Err(NumberError::TooLarge),
        };
    }
    match float(text) {
        Ok(_) | Err(NumberError::NotFinite) => Err(NumberError::NotWhole),
        Err(e) => Err(e),
    }
}

/// A word as messages show it: control characters escaped, at most 40 characters.
pub(super) fn show(text: &str) -> String {
    let mut out = String::new();
    for (i, c) in text.chars().enumerate() {
        if i == 40 {
            out.push_str("...");
            break;
        }
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(text: &str) -> Vec<(String, u32, u32)> {
        let mut lex = Lexer::new(text, Arc::new(PathBuf::from("t.dat")));
        std::iter::from_fn(|| lex.next_word())
            .map(|w| (w.text.to_string(), w.line, w.col))
            .collect()
    }

    #[test]
    fn words_carry_line_and_column() {
        assert_eq!(
            words("BEGIN_SCENE\n  RESOLUTION\t64 32\r\n\x0c\u{e9}t\u{e9} x"),
            vec![
                ("BEGIN_SCENE".into(), 1, 1),
                ("RESOLUTION".into(), 2, 3),
                ("64".into(), 2, 14),
                ("32".into(), 2, 17),
                ("\u{e9}t\u{e9}".into(), 3, 2),
                ("x".into(), 3, 6),
            ]
        );
    }

    #[test]
    fn skip_line_drops_the_rest_of_the_line_only() {
        let mut lex = Lexer::new("# a b\nc # d\ne", Arc::new(PathBuf::from("t")));
        assert_eq!(lex.next_word().unwrap().text, "#");
        lex.skip_line();
        assert_eq!(lex.peek().unwrap().text, "c");
        assert_eq!(lex.next_word().unwrap().text, "c");
        assert_eq!(lex.next_word().unwrap().text, "#");
        lex.skip_line();
        let e = lex.next_word().unwrap();
        assert_eq!((e.text, e.line, e.col), ("e", 3, 1));
        assert!(lex.next_word().is_none());
        assert_eq!(lex.end().line, 3);
    }

    #[test]
    fn floats_as_percent_f_reads_them() {
        for (text, x) in [
            ("1", 1.0),
            ("-2.5", -2.5),
            ("0.", 0.0),
            (".5", 0.5),
            ("+1e2", 100.0),
        ] {
            assert_eq!(float(text), Ok(x), "{text}");
        }
        for text in ["x", "-", ".", "1.0f", "e5", "0x10", "1,5"] {
            assert_eq!(float(text), Err(NumberError::NotANumber), "{text}");
        }
        for text in ["nan", "inf", "-infinity"] {
            assert_eq!(float(text), Err(NumberError::NotANumber), "{text}");
        }
        assert_eq!(float("1e999"), Err(NumberError::NotFinite));
    }

    #[test]
    fn integers_as_percent_d_reads_them() {
        assert_eq!(int("42"), Ok(42));
        assert_eq!(int("-7"), Ok(-7));
        assert_eq!(int("+007"), Ok(7));
        assert_eq!(int("1.0"), Err(NumberError::NotWhole));
        assert_eq!(int("1e3"), Err(NumberError::NotWhole));
        assert_eq!(int("1e999"), Err(NumberError::NotWhole));
        assert_eq!(int("2147483648"), Err(NumberError::TooLarge));
        assert_eq!(int("RES"), Err(NumberError::NotANumber));
    }

    #[test]
    fn shown_words_escape_control_characters() {
        assert_eq!(show("a\u{1}b\tc"), "a\\u{1}b\\tc");
        assert_eq!(show(&"x".repeat(50)), format!("{}...", "x".repeat(40)));
    }
}
