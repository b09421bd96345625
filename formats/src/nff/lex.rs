//! Lines and numbers: the NFF scanner's two hot loops.
//!
//! A line is split into whitespace-separated tokens (`#` starts a comment that runs to the end
//! of the line); numbers are parsed with Clinger's exact fast path (at most 19 significant
//! digits, a mantissa below 2^53 and a power of ten up to 22: one correctly rounded multiply or
//! divide), which covers everything the SPD programs write, and fall back to the standard
//! library's correctly rounded parser otherwise.

/// Byte classes of the scanner.
const SPACE: u8 = 1;
const NEWLINE: u8 = 2;
const COMMENT: u8 = 3;

static CLASS: [u8; 256] = {
    let mut t = [0u8; 256];
    t[b' ' as usize] = SPACE;
    t[b'\t' as usize] = SPACE;
    t[b'\r' as usize] = SPACE;
    t[0x0b] = SPACE; // vertical tab
    t[0x0c] = SPACE; // form feed
    t[b'\n' as usize] = NEWLINE;
    t[b'#' as usize] = COMMENT;
    t
};

/// A cursor over a chunk of NFF text that hands out one non-blank line at a time.
pub(crate) struct Lines<'a> {
    pub text: &'a [u8],
    pos: usize,
    /// Lines started so far (0-based index of the next line).
    next_line: u32,
    /// The current line: its 0-based index in the chunk and where it starts.
    pub line: u32,
    pub line_start: usize,
    /// Token spans (start, end) of the current line, as offsets into `text`.
    pub toks: Vec<(usize, usize)>,
}

impl<'a> Lines<'a> {
    pub fn new(text: &'a [u8]) -> Lines<'a> {
        Lines {
            text,
            pos: 0,
            next_line: 0,
            line: 0,
            line_start: 0,
            toks: Vec::with_capacity(16),
        }
    }

    /// Moves to the next line that has tokens; false at the end of the text.
    pub fn advance(&mut self) -> bool {
        let text = self.text;
        let n = text.len();
        loop {
            if self.pos >= n {
                return false;
            }
            self.toks.clear();
            self.line = self.next_line;
            self.line_start = self.pos;
            let mut i = self.pos;
            let mut start = usize::MAX;
            while i < n {
                match CLASS[text[i] as usize] {
                    0 => {
                        if start == usize::MAX {
                            start = i;
                        }
                    }
                    SPACE => {
                        if start != usize::MAX {
                            self.toks.push((start, i));
                            start = usize::MAX;
                        }
                    }
                    NEWLINE => break,
                    _ => {
                        // A comment: the rest of the line is not read.
                        if start != usize::MAX {
                            self.toks.push((start, i));
                            start = usize::MAX;
                        }
                        while i < n && text[i] != b'\n' {
                            i += 1;
                        }
                        break;
                    }
                }
                i += 1;
            }
            if start != usize::MAX {
                self.toks.push((start, i));
            }
            if i < n {
                // At a newline.
                self.pos = i + 1;
                self.next_line += 1;
            } else {
                self.pos = n;
            }
            if !self.toks.is_empty() {
                return true;
            }
        }
    }

    /// The hot path for vertex lines: if the next line holds exactly `out.len()` plain numbers
    /// (no comment, nothing else), reads them and moves past the line in one pass. Otherwise
    /// reads nothing and returns false, and the caller takes the general path (`advance`),
    /// which also finds the error if there is one.
    #[inline]
    pub fn numbers_line(&mut self, out: &mut [f64]) -> bool {
        let text = self.text;
        let n = text.len();
        let mut i = self.pos;
        // Numerators and divisors first, the divisions together afterwards: independent
        // divisions overlap instead of each stalling the scan.
        let mut den = [1.0f64; 8];
        for (x, d) in out.iter_mut().zip(den.iter_mut()) {
            while i < n && (text[i] == b' ' || text[i] == b'\t') {
                i += 1;
            }
            let Some((num, div, end)) = number_at(text, i) else {
                return false;
            };
            *x = num;
            *d = div;
            i = end;
        }
        for (x, d) in out.iter_mut().zip(den) {
            *x /= d;
        }
        while i < n && CLASS[text[i] as usize] == SPACE {
            i += 1;
        }
        if i < n && text[i] != b'\n' {
            return false;
        }
        self.line = self.next_line;
        self.line_start = self.pos;
        self.toks.clear();
        if i < n {
            self.next_line += 1;
            self.pos = i + 1;
        } else {
            self.pos = n;
        }
        true
    }

    /// Newlines in the text read so far (all of them once `advance` returned false).
    pub fn newlines(&self) -> u32 {
        self.next_line
    }

    /// Token `k` of the current line.
    pub fn tok(&self, k: usize) -> &'a [u8] {
        let (s, e) = self.toks[k];
        &self.text[s..e]
    }

    /// 1-based column (in characters) of byte offset `at` on the current line.
    pub fn col_of(&self, at: usize) -> u32 {
        column(&self.text[self.line_start..at])
    }

    /// Column of token `k`, or just past the last token when `k` is beyond the line (where a
    /// missing value would go).
    pub fn col(&self, k: usize) -> u32 {
        match self.toks.get(k) {
            Some(&(s, _)) => self.col_of(s),
            None => {
                let end = self.toks.last().map_or(self.line_start, |t| t.1);
                self.col_of(end)
            }
        }
    }

    /// Where the text ends: (0-based line, 1-based column).
    pub fn end_position(&self) -> (u32, u32) {
        let n = self.text.len();
        let start = self
            .text
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |i| i + 1);
        let line = self.text.iter().filter(|&&b| b == b'\n').count() as u32;
        (line, column(&self.text[start..n]))
    }
}

/// 1 + the number of characters in `prefix` (UTF-8 continuation bytes do not count).
pub(crate) fn column(prefix: &[u8]) -> u32 {
    1 + prefix.iter().filter(|&&b| (b & 0xc0) != 0x80).count() as u32
}

/// Why a token is not a usable number.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum NumError {
    NotANumber,
    /// NaN, an infinity, or out of the range of f64.
    NotFinite,
}

const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// A number starting at `text[i]` and ending at a separator (or the end): its value as
/// numerator / divisor (the correctly rounded quotient is the number) and where it ends. `None` when there is no such finite number. One pass over the bytes, eight
/// digits at a time; anything unusual goes to `parse_f64`.
#[inline]
fn number_at(text: &[u8], start: usize) -> Option<(f64, f64, usize)> {
    let n = text.len();
    let mut i = start;
    let neg = i < n && text[i] == b'-';
    if i < n && (neg || text[i] == b'+') {
        i += 1;
    }
    let (mut mant, int_digits) = digits(text, i);
    i += int_digits;
    let mut frac_digits = 0;
    if i < n && text[i] == b'.' {
        i += 1;
        let (f, k) = digits(text, i);
        frac_digits = k;
        mant = mant.wrapping_mul(pow10_u64(k)).wrapping_add(f);
        i += k;
    }
    let total = int_digits + frac_digits;
    let plain = total > 0
        && total <= 19
        && mant <= (1 << 53)
        && frac_digits <= 22
        && (i == n || CLASS[text[i] as usize] != 0);
    if plain {
        let m = mant as f64;
        return Some((if neg { -m } else { m }, POW10[frac_digits], i));
    }
    // Exponents, long mantissas, bad tokens: the general parser on the whole token.
    let mut end = i;
    while end < n && CLASS[text[end] as usize] == 0 {
        end += 1;
    }
    parse_f64(&text[start..end]).ok().map(|v| (v, 1.0, end))
}

#[inline]
fn pow10_u64(k: usize) -> u64 {
    const P: [u64; 20] = {
        let mut p = [1u64; 20];
        let mut i = 1;
        while i < 20 {
            p[i] = p[i - 1] * 10;
            i += 1;
        }
        p
    };
    P[k.min(19)]
}

/// The run of decimal digits at `text[i..]`: its value (meaningful for up to 19 digits) and
/// length. Eight bytes at a time while they are in the text.
#[inline]
fn digits(text: &[u8], mut i: usize) -> (u64, usize) {
    let start = i;
    let mut value: u64 = 0;
    while i + 8 <= text.len() {
        let x = u64::from_le_bytes(text[i..i + 8].try_into().unwrap());
        // Digit values in each byte; a byte is a digit iff its high nibble is 0 and its low
        // nibble is below 10 (no carries cross bytes in these sums).
        let t = x ^ 0x3030_3030_3030_3030;
        let high = t & 0xf0f0_f0f0_f0f0_f0f0;
        let big = ((t & 0x0f0f_0f0f_0f0f_0f0f) + 0x0606_0606_0606_0606) & 0xf0f0_f0f0_f0f0_f0f0;
        let other = high | big;
        let flags = (((other & 0x7f7f_7f7f_7f7f_7f7f) + 0x7f7f_7f7f_7f7f_7f7f) | other)
            & 0x8080_8080_8080_8080;
        let k = if flags == 0 {
            8
        } else {
            (flags.trailing_zeros() / 8) as usize
        };
        if k > 0 {
            // The k digits, most significant first in memory: shift them to the top bytes.
            let d = t << (8 * (8 - k));
            value = value
                .wrapping_mul(pow10_u64(k))
                .wrapping_add(eight_digits(d));
            i += k;
        }
        if k < 8 {
            return (value, i - start);
        }
    }
    while i < text.len() && text[i].is_ascii_digit() {
        value = value.wrapping_mul(10).wrapping_add((text[i] - b'0') as u64);
        i += 1;
    }
    (value, i - start)
}

/// Eight digit values (0..=9, first digit in the lowest byte) as a number.
#[inline]
fn eight_digits(mut v: u64) -> u64 {
    const MASK: u64 = 0x0000_00ff_0000_00ff;
    const MUL1: u64 = 0x000f_4240_0000_0064; // 100 + (1000000 << 32)
    const MUL2: u64 = 0x0000_2710_0000_0001; // 1 + (10000 << 32)
    v = v.wrapping_mul(10).wrapping_add(v >> 8);
    (((v & MASK).wrapping_mul(MUL1)).wrapping_add(((v >> 16) & MASK).wrapping_mul(MUL2))) >> 32
}

/// Parses a whole token as a finite f64.
#[inline]
pub(crate) fn parse_f64(s: &[u8]) -> Result<f64, NumError> {
    match fast_f64(s) {
        Some(v) => Ok(v),
        None => slow_f64(s),
    }
}

/// Clinger's fast path; `None` when the token is not a plain decimal it can parse exactly.
#[inline]
fn fast_f64(s: &[u8]) -> Option<f64> {
    let n = s.len();
    // Longer tokens may hold more than 19 digits: the slow path takes them.
    if n == 0 || n > 24 {
        return None;
    }
    let mut i = 0;
    let neg = s[0] == b'-';
    if neg || s[0] == b'+' {
        i = 1;
    }
    // At most 19 digits (checked below) cannot overflow u64.
    let mut mant: u64 = 0;
    let int_start = i;
    while i < n {
        let d = s[i].wrapping_sub(b'0');
        if d > 9 {
            break;
        }
        mant = mant.wrapping_mul(10).wrapping_add(d as u64);
        i += 1;
    }
    let mut digits = i - int_start;
    let mut exp: i64 = 0;
    if i < n && s[i] == b'.' {
        i += 1;
        let frac_start = i;
        while i < n {
            let d = s[i].wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            mant = mant.wrapping_mul(10).wrapping_add(d as u64);
            i += 1;
        }
        digits += i - frac_start;
        exp = -((i - frac_start) as i64);
    }
    if digits == 0 || digits > 19 {
        return None;
    }
    if i < n && (s[i] | 0x20) == b'e' {
        i += 1;
        let eneg = match s.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let mut e: i64 = 0;
        let start = i;
        while i < n && s[i].is_ascii_digit() {
            e = (e * 10 + (s[i] - b'0') as i64).min(1 << 20);
            i += 1;
        }
        if i == start {
            return None;
        }
        exp += if eneg { -e } else { e };
    }
    if i != n || mant > (1 << 53) || !(-22..=22).contains(&exp) {
        return None;
    }
    let m = mant as f64;
    let v = if exp >= 0 {
        m * POW10[exp as usize]
    } else {
        m / POW10[(-exp) as usize]
    };
    Some(if neg { -v } else { v })
}

#[cold]
fn slow_f64(s: &[u8]) -> Result<f64, NumError> {
    let text = std::str::from_utf8(s).map_err(|_| NumError::NotANumber)?;
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(NumError::NotFinite),
        Err(_) => Err(NumError::NotANumber),
    }
}

/// Parses a whole token as a non-negative integer that fits in u32.
pub(crate) fn parse_u32(s: &[u8]) -> Option<u32> {
    let s = s.strip_prefix(b"+").unwrap_or(s);
    if s.is_empty() || s.len() > 10 || !s.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let v = s.iter().fold(0u64, |a, &d| a * 10 + (d - b'0') as u64);
    u32::try_from(v).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_parse_exactly() {
        for t in [
            "0",
            "1",
            "-1",
            "+2.5",
            "0.272166",
            "-0.5",
            "12",
            "3.0827",
            "100000",
            "1e-05",
            "1E5",
            ".5",
            "5.",
            "-.25e+2",
            "0.0000000000001234",
            "123456789012345678",
            "1234567890123456789012",
            "0.1",
            "2.2250738585072014e-308",
            "1.7976931348623157e308",
            "9007199254740993",
            "4.9e-324",
        ] {
            let want: f64 = t.parse().unwrap();
            assert_eq!(parse_f64(t.as_bytes()), Ok(want), "{t}");
        }
    }

    #[test]
    fn bad_numbers_are_classified() {
        for t in [
            "", "-", ".", "e5", "1e", "1.2.3", "1-2", "0x10", "abc", "1,5",
        ] {
            assert_eq!(parse_f64(t.as_bytes()), Err(NumError::NotANumber), "{t}");
        }
        for t in ["nan", "NaN", "inf", "-inf", "infinity", "1e400", "-1e999"] {
            assert_eq!(parse_f64(t.as_bytes()), Err(NumError::NotFinite), "{t}");
        }
    }

    #[test]
    fn numbers_in_lines() {
        for t in [
            "0",
            "-3.83333",
            "12345678",
            "123456789",
            "0.000000001234567",
            "+7",
            "1e5",
            "-2.5E-3",
            "123456789012345678",
            "12345678901234567890123",
            "3.",
            ".25",
            "0.1",
            "9007199254740993",
            "1.2345678901234567890",
        ] {
            let want: f64 = t.parse().unwrap();
            for tail in ["", " ", "\n", "\t1", " # c"] {
                let text = format!("{t}{tail}");
                let (num, div, end) = number_at(text.as_bytes(), 0).unwrap();
                assert_eq!((num / div, end), (want, t.len()), "{text:?}");
            }
            let text = format!("xx {t} ");
            let (num, div, end) = number_at(text.as_bytes(), 3).unwrap();
            assert_eq!((num / div, end), (want, 3 + t.len()));
        }
        for t in ["", "-", "1x", "1.2.3", "nan", "1e999", "x1", "1-"] {
            assert_eq!(number_at(format!("{t} 5").as_bytes(), 0), None, "{t}");
        }
        for k in 0..=8 {
            let d: String = "98765432".chars().take(k).collect();
            let text = format!("{d}.5 ");
            let (num, div, end) = number_at(text.as_bytes(), 0).unwrap();
            assert_eq!(num / div, text.trim().parse::<f64>().unwrap());
            assert_eq!(end, k + 2);
        }
    }

    #[test]
    fn integers() {
        assert_eq!(parse_u32(b"144"), Some(144));
        assert_eq!(parse_u32(b"+3"), Some(3));
        assert_eq!(parse_u32(b"4294967295"), Some(u32::MAX));
        for t in ["4294967296", "-3", "3.0", "", "x"] {
            assert_eq!(parse_u32(t.as_bytes()), None, "{t}");
        }
    }

    #[test]
    fn lines_skip_blanks_and_comments() {
        let text = b"# head\n\n  s 1 2 3 4 # tail\r\n\t\np 3\n1 2 3";
        let mut l = Lines::new(text);
        assert!(l.advance());
        assert_eq!((l.line, l.toks.len(), l.tok(0)), (2, 5, &b"s"[..]));
        assert_eq!(l.col(0), 3);
        assert_eq!(l.col(4), 11);
        assert_eq!(l.col(5), 12, "just past the last token");
        assert!(l.advance());
        assert_eq!((l.line, l.tok(1)), (4, &b"3"[..]));
        assert!(l.advance());
        assert_eq!((l.line, l.toks.len()), (5, 3));
        assert!(!l.advance());
        assert_eq!(l.newlines(), 5);
        assert_eq!(l.end_position(), (5, 6));
    }

    #[test]
    fn columns_count_characters() {
        assert_eq!(column("été ".as_bytes()), 5);
    }
}
