//! Decoding of blosc (version 1) buffers, the container OpenVDB's blosc compression writes:
//! a 16-byte header, a table of block offsets, and per block one or `typesize` LZ4 streams,
//! byte-shuffled when the header says so. Only what OpenVDB writes is accepted (LZ4 inside,
//! byte shuffle or none); other codecs and bit shuffle are errors naming them.
//!
//! Header (all little-endian): version u8, codec version u8, flags u8 (bit 0 byte shuffle,
//! bit 1 stored without compression, bit 2 bit shuffle, bit 4 blocks not split into streams,
//! bits 5-7 codec: 0 blosclz, 1 lz4, 2 snappy, 3 zlib, 4 zstd), type size u8, uncompressed
//! bytes u32, block size u32, compressed bytes (header included) u32.

const HEADER: usize = 16;
const MAX_SPLITS: usize = 16;
const MIN_BUFFERSIZE: usize = 128;

const CODECS: [&str; 8] = [
    "blosclz", "lz4", "snappy", "zlib", "zstd", "codec 5", "codec 6", "codec 7",
];

/// Decodes `src` (one whole blosc buffer) into exactly `expected` bytes.
pub(crate) fn decompress(src: &[u8], expected: usize) -> Result<Vec<u8>, String> {
    if src.len() < HEADER {
        return Err(format!(
            "a blosc buffer of {} bytes is shorter than its 16-byte header",
            src.len()
        ));
    }
    let word = |at: usize| u32::from_le_bytes([src[at], src[at + 1], src[at + 2], src[at + 3]]);
    let version = src[0];
    let flags = src[2];
    let typesize = usize::from(src[3]).max(1);
    let nbytes = word(4) as usize;
    let blocksize = word(8) as usize;
    let cbytes = word(12) as usize;
    if version == 0 || version > 2 {
        return Err(format!("unknown blosc format version {version}"));
    }
    if nbytes != expected {
        return Err(format!(
            "the blosc buffer holds {nbytes} bytes, expected {expected}"
        ));
    }
    if cbytes != src.len() {
        return Err(format!(
            "the blosc header says {cbytes} compressed bytes, the chunk has {}",
            src.len()
        ));
    }
    if flags & 0x02 != 0 {
        // Stored as is.
        let data = &src[HEADER..];
        if data.len() != nbytes {
            return Err(format!(
                "a stored blosc buffer of {nbytes} bytes comes with {} bytes",
                data.len()
            ));
        }
        return Ok(data.to_vec());
    }
    let codec = usize::from(flags >> 5);
    if codec != 1 {
        return Err(format!(
            "blosc buffers compressed with {} are not supported (OpenVDB writes lz4)",
            CODECS[codec]
        ));
    }
    if flags & 0x04 != 0 {
        return Err("blosc bit shuffle is not supported (OpenVDB uses byte shuffle)".into());
    }
    if nbytes == 0 {
        return Ok(Vec::new());
    }
    if blocksize == 0 {
        return Err("the blosc block size is 0".into());
    }
    let nblocks = nbytes.div_ceil(blocksize);
    let table_end = nblocks
        .checked_mul(4)
        .and_then(|n| n.checked_add(HEADER))
        .filter(|&n| n <= src.len())
        .ok_or_else(|| format!("the blosc buffer is too short for its {nblocks} blocks"))?;
    let shuffle = flags & 0x01 != 0 && typesize > 1;
    let dont_split = flags & 0x10 != 0;
    // `nbytes` equals the caller's expected size, so this allocation is bounded by it.
    let mut out = vec![0u8; nbytes];
    let mut scratch = vec![0u8; blocksize.min(nbytes)];
    for b in 0..nblocks {
        let start = word(HEADER + 4 * b) as usize;
        if start < table_end || start > src.len() {
            return Err(format!(
                "blosc block {b} starts at byte {start}, outside the buffer"
            ));
        }
        let block_len = blocksize.min(nbytes - b * blocksize);
        let leftover = block_len < blocksize;
        let streams = if !dont_split
            && !leftover
            && typesize <= MAX_SPLITS
            && blocksize / typesize >= MIN_BUFFERSIZE
        {
            typesize
        } else {
            1
        };
        let stream_len = block_len / streams;
        let dest = if shuffle {
            &mut scratch[..block_len]
        } else {
            &mut out[b * blocksize..b * blocksize + block_len]
        };
        let mut at = start;
        for s in 0..streams {
            if at + 4 > src.len() {
                return Err(format!("blosc block {b} is cut short"));
            }
            let clen = i32::from_le_bytes([src[at], src[at + 1], src[at + 2], src[at + 3]]);
            at += 4;
            let clen = usize::try_from(clen)
                .ok()
                .filter(|&c| c <= src.len() - at)
                .ok_or_else(|| format!("blosc block {b} has a stream of {clen} bytes"))?;
            let part = &mut dest[s * stream_len..(s + 1) * stream_len];
            let input = &src[at..at + clen];
            if clen == stream_len {
                part.copy_from_slice(input);
            } else {
                let n = lz4_flex::block::decompress_into(input, part)
                    .map_err(|e| format!("blosc block {b}: bad LZ4 data ({e})"))?;
                if n != stream_len {
                    return Err(format!(
                        "blosc block {b}: LZ4 gave {n} bytes, expected {stream_len}"
                    ));
                }
            }
            at += clen;
        }
        if shuffle {
            unshuffle(
                &scratch[..block_len],
                &mut out[b * blocksize..b * blocksize + block_len],
                typesize,
            );
        }
    }
    Ok(out)
}

/// Undoes the byte shuffle of one block: the shuffled block holds byte 0 of every element, then
/// byte 1 of every element, and so on; bytes past the last whole element are kept in place.
fn unshuffle(src: &[u8], dst: &mut [u8], typesize: usize) {
    let n = src.len() / typesize;
    for (i, element) in dst.chunks_exact_mut(typesize).enumerate() {
        for (j, byte) in element.iter_mut().enumerate() {
            *byte = src[j * n + i];
        }
    }
    let whole = n * typesize;
    dst[whole..].copy_from_slice(&src[whole..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unshuffle_interleaves_bytes_and_keeps_the_tail() {
        let src = [1, 2, 3, 10, 20, 30, 99];
        let mut dst = [0; 7];
        unshuffle(&src, &mut dst, 2);
        assert_eq!(dst, [1, 10, 2, 20, 3, 30, 99]);
    }

    fn header(flags: u8, typesize: u8, nbytes: u32, blocksize: u32, cbytes: u32) -> Vec<u8> {
        let mut h = vec![2, 1, flags, typesize];
        for w in [nbytes, blocksize, cbytes] {
            h.extend(w.to_le_bytes());
        }
        h
    }

    #[test]
    fn stored_buffers_and_header_checks() {
        let mut b = header(0x02, 4, 8, 8, 24);
        b.extend(1..=8u8);
        assert_eq!(decompress(&b, 8).unwrap(), (1..=8).collect::<Vec<u8>>());
        assert!(decompress(&b, 9).unwrap_err().contains("expected 9"));
        assert!(decompress(&b[..20], 8)
            .unwrap_err()
            .contains("compressed bytes"));
        let zstd = header(4 << 5, 4, 8, 8, 16);
        assert!(decompress(&zstd, 8).unwrap_err().contains("zstd"));
        let bits = header((1 << 5) | 0x04, 4, 8, 8, 16);
        assert!(decompress(&bits, 8).unwrap_err().contains("bit shuffle"));
        // A block table larger than the buffer.
        let many = header(1 << 5, 4, 1 << 30, 1, 16);
        assert!(decompress(&many, 1 << 30)
            .unwrap_err()
            .contains("too short"));
    }

    #[test]
    fn lz4_blocks_with_shuffle() {
        // One block, typesize 2, not split: a raw (incompressible-size) stream.
        let data = [5u8, 6, 7, 8];
        let mut b = header((1 << 5) | 0x10 | 0x01, 2, 4, 4, 0);
        b.extend(20u32.to_le_bytes()); // block 0 starts after the table
        b.extend(4i32.to_le_bytes());
        b.extend(data); // stored: length equals the stream length
        let n = b.len() as u32;
        b[12..16].copy_from_slice(&n.to_le_bytes());
        assert_eq!(decompress(&b, 4).unwrap(), [5, 7, 6, 8]);
        // A real LZ4 block: literal 'a', a match of 7 at offset 1, then literals "bcdef".
        let mut b = header((1 << 5) | 0x10, 1, 13, 13, 0);
        b.extend(20u32.to_le_bytes());
        let lz4 = [0x13, b'a', 1, 0, 0x50, b'b', b'c', b'd', b'e', b'f'];
        b.extend((lz4.len() as i32).to_le_bytes());
        b.extend(lz4);
        let n = b.len() as u32;
        b[12..16].copy_from_slice(&n.to_le_bytes());
        assert_eq!(decompress(&b, 13).unwrap(), b"aaaaaaaabcdef");
        assert_eq!(
            decompress(&b, 12).unwrap_err(),
            "the blosc buffer holds 13 bytes, expected 12"
        );
        // Corrupt LZ4 data is an error.
        let at = b.len() - 6;
        b[at] = 0xff;
        assert!(decompress(&b, 13).is_err());
    }
}
