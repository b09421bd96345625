//! A bounds-checked little-endian cursor over the file's bytes: every read checks the length
//! against what remains, so that no length field of a corrupt file causes a large allocation
//! or a panic.

use crate::VdbError;

pub(crate) struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Cursor { bytes, pos: 0 }
    }

    pub fn pos(&self) -> usize {
        self.pos
    }

    pub fn remaining(&self) -> usize {
        self.bytes.len() - self.pos
    }

    /// Moves to an absolute offset (an offset recorded in the file, so checked).
    pub fn seek(&mut self, offset: i64, what: &str) -> Result<(), VdbError> {
        match usize::try_from(offset) {
            Ok(o) if o <= self.bytes.len() => {
                self.pos = o;
                Ok(())
            }
            _ => Err(VdbError::Corrupt {
                offset: self.pos,
                message: format!(
                    "{what} points to byte {offset}, outside the file's {} bytes",
                    self.bytes.len()
                ),
            }),
        }
    }

    pub fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], VdbError> {
        if n > self.remaining() {
            return Err(VdbError::Truncated {
                offset: self.pos,
                what: what.to_string(),
                needed: n,
                remaining: self.remaining(),
            });
        }
        let s = &self.bytes[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    pub fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], VdbError> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.take(N, what)?);
        Ok(a)
    }

    pub fn u8(&mut self, what: &str) -> Result<u8, VdbError> {
        Ok(self.array::<1>(what)?[0])
    }

    pub fn u32(&mut self, what: &str) -> Result<u32, VdbError> {
        Ok(u32::from_le_bytes(self.array(what)?))
    }

    pub fn i32(&mut self, what: &str) -> Result<i32, VdbError> {
        Ok(i32::from_le_bytes(self.array(what)?))
    }

    pub fn i64(&mut self, what: &str) -> Result<i64, VdbError> {
        Ok(i64::from_le_bytes(self.array(what)?))
    }

    pub fn f64(&mut self, what: &str) -> Result<f64, VdbError> {
        Ok(f64::from_le_bytes(self.array(what)?))
    }

    /// A count stored as i32 of items taking at least `min_bytes` each: negative counts and
    /// counts the remaining bytes cannot hold are errors (so the count bounds allocations).
    pub fn count(&mut self, min_bytes: usize, what: &str) -> Result<usize, VdbError> {
        let at = self.pos;
        let n = self.i32(what)?;
        let n = usize::try_from(n).map_err(|_| VdbError::Corrupt {
            offset: at,
            message: format!("{what} is negative ({n})"),
        })?;
        if n.saturating_mul(min_bytes) > self.remaining() {
            return Err(VdbError::Corrupt {
                offset: at,
                message: format!(
                    "{what} is {n}, more than the remaining {} bytes can hold",
                    self.remaining()
                ),
            });
        }
        Ok(n)
    }

    /// A string: u32 length, then that many bytes (UTF-8 expected, replaced where invalid).
    pub fn string(&mut self, what: &str) -> Result<String, VdbError> {
        let n = self.u32(what)? as usize;
        let s = self.take(n, what)?;
        Ok(String::from_utf8_lossy(s).into_owned())
    }

    pub fn corrupt(&self, message: impl Into<String>) -> VdbError {
        VdbError::Corrupt {
            offset: self.pos,
            message: message.into(),
        }
    }
}
