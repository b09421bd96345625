//! The value arrays of leaf and internal nodes: the per-node byte that says how inactive values
//! were stored, the chunk codecs (blosc, zip, none) and the value encodings (f32, f64, half).

use crate::bytes::Cursor;
use crate::{blosc, VdbError};
use std::io::Read;

/// Per-grid compression flags (OpenVDB's `COMPRESS_*`).
pub(crate) const COMPRESS_ZIP: u32 = 0x1;
pub(crate) const COMPRESS_ACTIVE_MASK: u32 = 0x2;
pub(crate) const COMPRESS_BLOSC: u32 = 0x4;

/// How a node's inactive values were stored (the byte before its values).
const NO_MASK_OR_INACTIVE_VALS: u8 = 0;
#[allow(dead_code)] // the default: inactive values are minus the background
const NO_MASK_AND_MINUS_BG: u8 = 1;
const NO_MASK_AND_ONE_INACTIVE_VAL: u8 = 2;
const MASK_AND_NO_INACTIVE_VALS: u8 = 3;
const MASK_AND_ONE_INACTIVE_VAL: u8 = 4;
const MASK_AND_TWO_INACTIVE_VALS: u8 = 5;
const NO_MASK_AND_ALL_VALS: u8 = 6;

/// How one value is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Encoding {
    F32,
    F64,
    /// IEEE 754 binary16 (grids saved with `saveFloatAsHalf`).
    Half,
}

impl Encoding {
    fn size(self) -> usize {
        match self {
            Encoding::F32 => 4,
            Encoding::F64 => 8,
            Encoding::Half => 2,
        }
    }
}

/// What reading a node's values needs besides the bytes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ValueFormat {
    pub compression: u32,
    /// Encoding of the node arrays (half for half-float grids).
    pub array: Encoding,
    /// Encoding of single values (background, tiles, inactive values): the full type.
    pub single: Encoding,
    pub background: f32,
}

/// Reads one value in `enc`.
pub(crate) fn read_value(c: &mut Cursor, enc: Encoding, what: &str) -> Result<f32, VdbError> {
    let b = c.take(enc.size(), what)?;
    Ok(decode(b, enc))
}

fn decode(b: &[u8], enc: Encoding) -> f32 {
    match enc {
        Encoding::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        Encoding::F64 => {
            f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]) as f32
        }
        Encoding::Half => half_to_f32(u16::from_le_bytes([b[0], b[1]])),
    }
}

/// IEEE 754 binary16 to binary32 (exact).
pub fn half_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = u32::from((h >> 10) & 0x1f);
    let man = u32::from(h & 0x3ff);
    match exp {
        // Zero and subnormals: man * 2^-24.
        0 => sign * man as f32 * f32::from_bits(0x3380_0000),
        31 if man == 0 => sign * f32::INFINITY,
        31 => f32::NAN,
        _ => f32::from_bits((u32::from(h & 0x8000) << 16) | ((exp + 112) << 23) | (man << 13)),
    }
}

/// A node mask of `bits` bits, read as little-endian 64-bit words.
pub(crate) fn read_mask(c: &mut Cursor, bits: usize, what: &str) -> Result<Vec<u64>, VdbError> {
    let raw = c.take(bits / 8, what)?;
    Ok(raw
        .chunks_exact(8)
        .map(|w| u64::from_le_bytes([w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7]]))
        .collect())
}

#[inline]
pub(crate) fn bit(mask: &[u64], i: usize) -> bool {
    mask[i >> 6] >> (i & 63) & 1 != 0
}

/// Reads the `n` values of a node (in OpenVDB's order) whose value mask is `active`, restoring
/// the inactive values OpenVDB left out.
pub(crate) fn read_node_values(
    c: &mut Cursor,
    n: usize,
    active: &[u64],
    f: &ValueFormat,
) -> Result<Vec<f32>, VdbError> {
    let at = c.pos();
    let mode = c.u8("the node's value-storage byte")?;
    if mode > NO_MASK_AND_ALL_VALS {
        return Err(VdbError::Corrupt {
            offset: at,
            message: format!("unknown node value-storage mode {mode} (expected 0 to 6)"),
        });
    }
    let bg = f.background;
    // Inactive values: `inactive[1]` where the selection mask is on, `inactive[0]` elsewhere.
    let mut inactive = [
        if mode == NO_MASK_OR_INACTIVE_VALS {
            bg
        } else {
            -bg
        },
        bg,
    ];
    if matches!(
        mode,
        NO_MASK_AND_ONE_INACTIVE_VAL | MASK_AND_ONE_INACTIVE_VAL | MASK_AND_TWO_INACTIVE_VALS
    ) {
        inactive[0] = read_value(c, f.single, "an inactive value")?;
        if mode == MASK_AND_TWO_INACTIVE_VALS {
            inactive[1] = read_value(c, f.single, "the second inactive value")?;
        }
    }
    let selection = if matches!(
        mode,
        MASK_AND_NO_INACTIVE_VALS | MASK_AND_ONE_INACTIVE_VAL | MASK_AND_TWO_INACTIVE_VALS
    ) {
        Some(read_mask(c, n, "the inactive-value selection mask")?)
    } else {
        None
    };
    let masked = f.compression & COMPRESS_ACTIVE_MASK != 0 && mode != NO_MASK_AND_ALL_VALS;
    let stored = if masked {
        active.iter().map(|w| w.count_ones() as usize).sum()
    } else {
        n
    };
    // Half-float arrays with no values to store are written as nothing at all.
    let bytes = if stored == 0 && f.array == Encoding::Half {
        Vec::new().into()
    } else {
        read_chunk(c, stored * f.array.size(), f.compression)?
    };
    let values = bytes
        .chunks_exact(f.array.size())
        .map(|b| decode(b, f.array));
    if stored == n {
        return Ok(values.collect());
    }
    let mut values = values;
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        if bit(active, i) {
            // `stored` values for `stored` active bits.
            out.push(values.next().unwrap_or(bg));
        } else {
            let on = selection.as_ref().is_some_and(|s| bit(s, i));
            out.push(inactive[usize::from(on)]);
        }
    }
    Ok(out)
}

/// One chunk of `len` bytes as stored with `compression`: blosc and zip chunks start with an
/// i64 byte count (negative or zero: stored uncompressed, that many bytes).
fn read_chunk<'a>(
    c: &mut Cursor<'a>,
    len: usize,
    compression: u32,
) -> Result<std::borrow::Cow<'a, [u8]>, VdbError> {
    if compression & (COMPRESS_BLOSC | COMPRESS_ZIP) == 0 {
        return Ok(c.take(len, "uncompressed node values")?.into());
    }
    let codec = if compression & COMPRESS_BLOSC != 0 {
        "blosc"
    } else {
        "zip"
    };
    let at = c.pos();
    let size = c.i64("a compressed chunk's size")?;
    if size <= 0 {
        let stored = size.unsigned_abs();
        if stored != len as u64 {
            return Err(VdbError::Corrupt {
                offset: at,
                message: format!("expected {len} uncompressed bytes, the chunk has {stored}"),
            });
        }
        return Ok(c.take(len, "uncompressed node values")?.into());
    }
    let size = usize::try_from(size).unwrap_or(usize::MAX);
    let data = c.take(size, &format!("a {codec} chunk"))?;
    let bad = |message: String| VdbError::Corrupt {
        offset: at,
        message: format!("{codec} chunk: {message}"),
    };
    let out = if codec == "blosc" {
        blosc::decompress(data, len).map_err(bad)?
    } else {
        // At most `len + 1` bytes are inflated: enough to tell a chunk that is too long.
        let mut out = Vec::with_capacity(len);
        flate2::read::ZlibDecoder::new(data)
            .take(len as u64 + 1)
            .read_to_end(&mut out)
            .map_err(|e| bad(format!("bad zlib data ({e})")))?;
        if out.len() != len {
            return Err(bad(format!(
                "inflates to {}{} bytes, expected {len}",
                out.len(),
                if out.len() > len { " or more" } else { "" }
            )));
        }
        out
    };
    Ok(out.into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn half_values() {
        assert_eq!(half_to_f32(0x3c00), 1.0);
        assert_eq!(half_to_f32(0xc000), -2.0);
        assert_eq!(half_to_f32(0x7bff), 65504.0);
        assert_eq!(half_to_f32(0x0001), 2f32.powi(-24));
        assert_eq!(half_to_f32(0x83ff), -1023.0 * 2f32.powi(-24));
        assert_eq!(half_to_f32(0x3555), 0.333_251_95);
        assert_eq!(half_to_f32(0x8000).to_bits(), (-0.0f32).to_bits());
        assert_eq!(half_to_f32(0x7c00), f32::INFINITY);
        assert!(half_to_f32(0x7e00).is_nan());
    }

    fn format(compression: u32) -> ValueFormat {
        ValueFormat {
            compression,
            array: Encoding::F32,
            single: Encoding::F32,
            background: 2.0,
        }
    }

    fn bytes(values: &[f32]) -> Vec<u8> {
        values.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    #[test]
    fn every_inactive_value_mode() {
        // 64 values, voxels 0 and 5 active.
        let active = [1u64 | 1 << 5];
        let selection = [1u64 << 1 | 1 << 2];
        let case = |mode: u8, extra: &[f32], sel: bool| {
            let mut b = vec![mode];
            b.extend(bytes(extra));
            if sel {
                b.extend(selection[0].to_le_bytes());
            }
            b.extend(bytes(&[10.0, 15.0]));
            let mut c = Cursor::new(&b);
            let v = read_node_values(&mut c, 64, &active, &format(COMPRESS_ACTIVE_MASK));
            assert_eq!(c.remaining(), 0);
            v.unwrap()
        };
        let v = case(NO_MASK_OR_INACTIVE_VALS, &[], false);
        assert_eq!((v[0], v[1], v[5], v[63]), (10.0, 2.0, 15.0, 2.0));
        let v = case(NO_MASK_AND_MINUS_BG, &[], false);
        assert_eq!((v[0], v[1], v[5], v[63]), (10.0, -2.0, 15.0, -2.0));
        let v = case(NO_MASK_AND_ONE_INACTIVE_VAL, &[7.0], false);
        assert_eq!((v[1], v[2], v[63]), (7.0, 7.0, 7.0));
        let v = case(MASK_AND_NO_INACTIVE_VALS, &[], true);
        assert_eq!((v[1], v[2], v[3], v[5]), (2.0, 2.0, -2.0, 15.0));
        let v = case(MASK_AND_ONE_INACTIVE_VAL, &[7.0], true);
        assert_eq!((v[1], v[2], v[3]), (2.0, 2.0, 7.0));
        let v = case(MASK_AND_TWO_INACTIVE_VALS, &[7.0, 9.0], true);
        assert_eq!((v[1], v[2], v[3]), (9.0, 9.0, 7.0));
        // Mode 6 stores every value.
        let mut b = vec![NO_MASK_AND_ALL_VALS];
        b.extend(bytes(&(0..64).map(|i| i as f32).collect::<Vec<_>>()));
        let v = read_node_values(
            &mut Cursor::new(&b),
            64,
            &active,
            &format(COMPRESS_ACTIVE_MASK),
        )
        .unwrap();
        assert_eq!(v[63], 63.0);
        // Unknown modes are errors.
        let e = read_node_values(&mut Cursor::new(&[7]), 64, &active, &format(0)).unwrap_err();
        assert!(e.to_string().contains("mode 7"), "{e}");
    }

    #[test]
    fn zip_chunks() {
        use std::io::Write;
        let values: Vec<f32> = (0..64).map(|i| (i % 3) as f32).collect();
        let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(&bytes(&values)).unwrap();
        let z = z.finish().unwrap();
        let mut b = vec![NO_MASK_AND_ALL_VALS];
        b.extend((z.len() as i64).to_le_bytes());
        b.extend(&z);
        let got = read_node_values(&mut Cursor::new(&b), 64, &[0], &format(COMPRESS_ZIP)).unwrap();
        assert_eq!(got, values);
        // Too few values for the node.
        let e =
            read_node_values(&mut Cursor::new(&b), 65, &[0, 0], &format(COMPRESS_ZIP)).unwrap_err();
        assert!(e.to_string().contains("expected 260"), "{e}");
        // Stored uncompressed inside a zip grid: a negative size.
        let mut b = vec![NO_MASK_AND_ALL_VALS];
        b.extend((-256i64).to_le_bytes());
        b.extend(bytes(&values));
        let got = read_node_values(&mut Cursor::new(&b), 64, &[0], &format(COMPRESS_ZIP)).unwrap();
        assert_eq!(got, values);
    }
}
