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
    if !fast_g(out, x) {
        slow_g(out, x);
    }
}

/// Powers of ten 10^0 ..= 10^10.
const POW10: [f64; 11] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10];

/// `%g` for 1e-4 <= |x| < 999999.5 by scaling to six digits in floating point; declines
/// (returns false) near a rounding tie, where only exact decimal arithmetic decides.
fn fast_g(out: &mut Vec<u8>, x: f64) -> bool {
    let a = x.abs();
    if !(1e-4..999_999.0).contains(&a) {
        return false;
    }
    // e = floor(log10(a)), in -4..=5.
    let mut e: i32 = 5;
    while e > -4 && a < POW10[(e + 4) as usize] * 1e-4 {
        e -= 1;
    }
    let scaled = a * POW10[(5 - e) as usize];
    let floor = scaled.floor();
    if (scaled - floor - 0.5).abs() < 1e-6 {
        return false;
    }
    let mut digits = scaled.round() as u64;
    if digits >= 1_000_000 {
        digits /= 10;
        e += 1;
        if e >= 6 {
            return false;
        }
    }
    if x < 0.0 {
        out.push(b'-');
    }
    let mut d = [0u8; 6];
    for k in (0..6).rev() {
        d[k] = b'0' + (digits % 10) as u8;
        digits /= 10;
    }
    let last = d.iter().rposition(|&c| c != b'0').unwrap_or(0);
    if e >= 0 {
        let int = (e + 1) as usize;
        out.extend_from_slice(&d[..int]);
        if last >= int {
            out.push(b'.');
            out.extend_from_slice(&d[int..=last]);
        }
    } else {
        out.extend_from_slice(b"0.");
        for _ in 0..(-e - 1) {
            out.push(b'0');
        }
        out.extend_from_slice(&d[..=last]);
    }
    true
}

/// `%g` through Rust's exact decimal formatting.
fn slow_g(out: &mut Vec<u8>, x: f64) {
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
    fn fast_path_agrees_with_exact_formatting() {
        let mut state = 0x1234_5678_9abc_def0u64;
        for _ in 0..200_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let mantissa = (state >> 11) as f64 / (1u64 << 53) as f64;
            let x = (mantissa - 0.5) * 10f64.powi((state % 13) as i32 - 5);
            let (mut fast, mut slow) = (Vec::new(), Vec::new());
            if super::fast_g(&mut fast, x) {
                super::slow_g(&mut slow, x);
                assert_eq!(fast, slow, "{x:e}");
            }
        }
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
