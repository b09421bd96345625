//! NFF text as the SPD programs print it: C's `%g` numbers, a cone on one line.

use std::io::{self, Write};

use super::{Fill, Sink, View};

/// Appends `x` formatted like C's `printf("%g", x)`: 6 significant digits, trailing zeros
/// removed, an exponent (`1e-05`, `2.5e+07`) below 1e-4 or from 1e6 on; `-0` for negative zero.
pub fn push_g(out: &mut Vec<u8>, x: f64) {
    if x == 0.0 {
        out.extend_from_slice(if x.is_sign_negative() { b"-0" } else { b"0" });
        return;
    }
    if !x.is_finite() {
        let _ = write!(out, "{x}");
        return;
    }
    // The exponent after rounding to 6 significant digits decides the style, as in C.
    let mut sci = [0u8; 32];
    let len = {
        let mut cursor = io::Cursor::new(&mut sci[..]);
        let _ = write!(cursor, "{x:.5e}");
        cursor.position() as usize
    };
    let sci = &sci[..len];
    let e_at = sci.iter().position(|&c| c == b'e').unwrap_or(len);
    let exp: i32 = std::str::from_utf8(&sci[e_at + 1..])
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    if !(-4..6).contains(&exp) {
        out.extend_from_slice(strip_zeros(&sci[..e_at]));
        out.push(b'e');
        out.push(if exp < 0 { b'-' } else { b'+' });
        let a = exp.unsigned_abs();
        if a < 10 {
            out.push(b'0');
        }
        let _ = write!(out, "{a}");
    } else {
        let start = out.len();
        let _ = write!(out, "{:.*}", (5 - exp) as usize, x);
        let kept = strip_zeros(&out[start..]).len();
        out.truncate(start + kept);
    }
}

/// "1.50000" -> "1.5", "2.00000" -> "2", "120" -> "120".
fn strip_zeros(s: &[u8]) -> &[u8] {
    if !s.contains(&b'.') {
        return s;
    }
    let mut end = s.len();
    while end > 0 && s[end - 1] == b'0' {
        end -= 1;
    }
    if end > 0 && s[end - 1] == b'.' {
        end -= 1;
    }
    &s[..end]
}

/// A [`Sink`] writing NFF text. Lines are assembled in a buffer and written in large blocks;
/// call [`NffWriter::flush`] at the end.
pub struct NffWriter<W: Write> {
    out: W,
    buf: Vec<u8>,
}

const BLOCK: usize = 1 << 16;

impl<W: Write> NffWriter<W> {
    pub fn new(out: W) -> Self {
        NffWriter {
            out,
            buf: Vec::with_capacity(BLOCK + 4096),
        }
    }

    /// Writes what is buffered and flushes the underlying writer.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.write_all(&self.buf)?;
        self.buf.clear();
        self.out.flush()
    }

    fn numbers(&mut self, keyword: &[u8], values: &[f64]) {
        self.buf.extend_from_slice(keyword);
        for (i, &v) in values.iter().enumerate() {
            if i > 0 || !keyword.is_empty() {
                self.buf.push(b' ');
            }
            push_g(&mut self.buf, v);
        }
        self.buf.push(b'\n');
    }

    fn end_entity(&mut self) -> io::Result<()> {
        if self.buf.len() >= BLOCK {
            self.out.write_all(&self.buf)?;
            self.buf.clear();
        }
        Ok(())
    }
}

impl<W: Write> Sink for NffWriter<W> {
    fn background(&mut self, rgb: [f64; 3]) -> io::Result<()> {
        self.numbers(b"b", &rgb);
        self.end_entity()
    }

    fn view(&mut self, v: &View) -> io::Result<()> {
        self.buf.extend_from_slice(b"v\n");
        self.numbers(b"from", &v.from);
        self.numbers(b"at", &v.at);
        self.numbers(b"up", &v.up);
        self.numbers(b"angle", &[v.angle]);
        self.numbers(b"hither", &[v.hither]);
        let _ = writeln!(self.buf, "resolution {} {}", v.resolution.0, v.resolution.1);
        self.end_entity()
    }

    fn light(&mut self, p: [f64; 3]) -> io::Result<()> {
        self.numbers(b"l", &p);
        self.end_entity()
    }

    fn fill(&mut self, f: &Fill) -> io::Result<()> {
        self.numbers(b"f", f);
        self.end_entity()
    }

    fn sphere(&mut self, c: [f64; 3], r: f64) -> io::Result<()> {
        self.numbers(b"s", &[c[0], c[1], c[2], r]);
        self.end_entity()
    }

    fn cone(&mut self, b: [f64; 3], br: f64, a: [f64; 3], ar: f64) -> io::Result<()> {
        self.numbers(b"c", &[b[0], b[1], b[2], br, a[0], a[1], a[2], ar]);
        self.end_entity()
    }

    fn polygon(&mut self, v: &[[f64; 3]]) -> io::Result<()> {
        let _ = writeln!(self.buf, "p {}", v.len());
        for p in v {
            self.numbers(b"", p);
        }
        self.end_entity()
    }

    fn patch(&mut self, v: &[[f64; 3]], n: &[[f64; 3]]) -> io::Result<()> {
        let _ = writeln!(self.buf, "pp {}", v.len());
        for (p, n) in v.iter().zip(n) {
            self.numbers(b"", &[p[0], p[1], p[2], n[0], n[1], n[2]]);
        }
        self.end_entity()
    }
}

#[cfg(test)]
mod tests {
    use super::push_g;

    fn g(x: f64) -> String {
        let mut v = Vec::new();
        push_g(&mut v, x);
        String::from_utf8(v).unwrap()
    }

    #[test]
    fn like_c_percent_g() {
        assert_eq!(g(0.0), "0");
        assert_eq!(g(-0.0), "-0");
        assert_eq!(g(1.0), "1");
        assert_eq!(g(-12.0), "-12");
        assert_eq!(g(0.5), "0.5");
        assert_eq!(g(100000.0), "100000");
        assert_eq!(g(1e6), "1e+06");
        assert_eq!(g(999999.5), "1e+06");
        assert_eq!(g(0.0001), "0.0001");
        assert_eq!(g(0.00001), "1e-05");
        assert_eq!(g(1.0 / 3.0), "0.333333");
        assert_eq!(g(2.0 / 3.0), "0.666667");
        assert_eq!(g(-2.55836e-17), "-2.55836e-17");
        assert_eq!(g(1.11022302e-16), "1.11022e-16");
        assert_eq!(g(0.0103125), "0.0103125");
        assert_eq!(g(9.9999996), "10");
        assert_eq!(g(123456789.0), "1.23457e+08");
        assert_eq!(g(1e100), "1e+100");
    }
}
