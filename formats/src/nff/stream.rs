//! Reading NFF text in blocks and parsing each block's chunks in parallel.
//!
//! A reader thread reads (and, for gzip, decompresses) the input in blocks of about
//! `BLOCK` bytes, cut before a line that starts an entity (`s`, `p`, `pp`, `c`, `f`, `l`, `b`,
//! `v`): such a line starts something self-contained, since vertex and cone lines hold only
//! numbers and the view's lines start with `from`, `at`... The main thread cuts each block the
//! same way into chunks, parses them in parallel with rayon and hands the results, in file
//! order, to the assembler. At most three blocks of text are alive at once, so the whole text
//! of a large file is never in memory together with everything parsed from it.

use std::io::{self, Read};
use std::ops::Range;
use std::sync::mpsc::sync_channel;

use rayon::prelude::*;

use super::lex::column;
use super::parse::{parse_chunk, ChunkError, ChunkOut, Next, ENTITIES};

/// Bytes of text read at a time.
pub(crate) const BLOCK: usize = 8 << 20;
/// Bytes of text per parallel task. Fixed, not derived from the thread count, so that the
/// scene (its geometry groups and their order) is the same however many threads parse it.
const CHUNK: usize = 1 << 20;

/// A block of whole entities and what starts the text after it (`None`: the file ends).
pub(crate) struct Block {
    pub text: Vec<u8>,
    pub next: Option<Next>,
}

#[inline]
fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | 0x0b | 0x0c)
}

/// If the line starting at `p` begins with an entity keyword followed by a separator (within
/// `text`), that keyword and its column.
pub(crate) fn entity_at(text: &[u8], p: usize) -> Option<Next> {
    let mut i = p;
    while i < text.len() && (text[i] == b' ' || text[i] == b'\t') {
        i += 1;
    }
    let start = i;
    while i < text.len() && text[i].is_ascii_lowercase() {
        i += 1;
    }
    if i == start || i - start > 2 || i >= text.len() {
        return None;
    }
    let after = text[i];
    if !(is_space(after) || after == b'\n' || after == b'#') {
        return None;
    }
    let word = &text[start..i];
    ENTITIES
        .iter()
        .find(|k| k.as_bytes() == word)
        .map(|k| Next {
            keyword: k,
            col: column(&text[p..start]),
        })
}

/// The last position > 0 in `text` where a line starts an entity.
fn last_boundary(text: &[u8]) -> Option<(usize, Next)> {
    let mut end = text.len();
    while let Some(nl) = text[..end].iter().rposition(|&b| b == b'\n') {
        if let Some(n) = entity_at(text, nl + 1) {
            return Some((nl + 1, n));
        }
        end = nl;
    }
    None
}

/// The first position >= `from` where a line starts an entity.
fn next_boundary(text: &[u8], from: usize) -> Option<(usize, Next)> {
    let mut p = from;
    while p < text.len() {
        let nl = p + text[p..].iter().position(|&b| b == b'\n')?;
        if let Some(n) = entity_at(text, nl + 1) {
            return Some((nl + 1, n));
        }
        p = nl + 1;
    }
    None
}

/// Cuts a block into chunks of about `target` bytes at entity lines.
pub(crate) fn split(
    text: &[u8],
    next: Option<Next>,
    target: usize,
) -> Vec<(Range<usize>, Option<Next>)> {
    let mut out = Vec::new();
    let mut start = 0;
    while text.len() - start > target + target / 2 {
        match next_boundary(text, start + target) {
            Some((p, n)) => {
                out.push((start..p, Some(n)));
                start = p;
            }
            None => break,
        }
    }
    out.push((start..text.len(), next));
    out
}

/// Parses a block's chunks in parallel; results in file order.
pub(crate) fn parse_block(block: &Block) -> Vec<Result<ChunkOut, ChunkError>> {
    let chunks = split(&block.text, block.next, CHUNK);
    chunks
        .into_par_iter()
        .map(|(range, next)| parse_chunk(&block.text[range], next))
        .collect()
}

/// Reads `reader` to the end in blocks of whole entities, calling `take` for each in order;
/// stops early when `take` returns false.
#[cfg(test)]
pub(crate) fn read_blocks<R: Read>(
    reader: R,
    block: usize,
    take: impl FnMut(Block) -> bool,
) -> io::Result<()> {
    read_blocks_into(reader, block, take, || None)
}

/// [`read_blocks`], filling buffers `spare` hands back (the text of blocks already parsed)
/// before it allocates new ones: a fresh buffer is fresh memory, paid for in page faults as
/// it is first written (for a 257 MB file, 65,000 of them).
pub(crate) fn read_blocks_into<R: Read>(
    mut reader: R,
    block: usize,
    mut take: impl FnMut(Block) -> bool,
    mut spare: impl FnMut() -> Option<Vec<u8>>,
) -> io::Result<()> {
    let mut buf: Vec<u8> = Vec::new();
    let mut want = block;
    loop {
        let have = buf.len();
        if have < want {
            buf.reserve(want - have);
            let got = (&mut reader)
                .take((want - have) as u64)
                .read_to_end(&mut buf)?;
            if got < want - have {
                // The end of the input.
                take(Block {
                    text: buf,
                    next: None,
                });
                return Ok(());
            }
        }
        match last_boundary(&buf) {
            Some((p, n)) => {
                let need = block.max(buf.len() - p);
                let mut rest = match spare() {
                    Some(mut v) if v.capacity() >= need => {
                        v.clear();
                        v
                    }
                    _ => Vec::with_capacity(need),
                };
                rest.extend_from_slice(&buf[p..]);
                buf.truncate(p);
                if !take(Block {
                    text: buf,
                    next: Some(n),
                }) {
                    return Ok(());
                }
                buf = rest;
                want = block;
            }
            // One entity larger than a block: read more.
            None => want = buf.len() * 2,
        }
    }
}

/// Reads blocks on a thread of their own while this thread parses: `each` gets every block's
/// chunk results in order and returns false to stop.
pub(crate) fn parse_stream<R: Read + Send, E>(
    reader: R,
    block: usize,
    mut each: impl FnMut(Vec<Result<ChunkOut, ChunkError>>) -> Result<(), E>,
    io_error: impl Fn(io::Error) -> E,
) -> Result<(), E> {
    std::thread::scope(|s| {
        let (tx, rx) = sync_channel::<io::Result<Block>>(1);
        // Parsed blocks' buffers go back to the reader to be filled again.
        let (back, spare) = std::sync::mpsc::channel::<Vec<u8>>();
        s.spawn(move || {
            let status = read_blocks_into(
                reader,
                block,
                |b| tx.send(Ok(b)).is_ok(),
                || spare.try_recv().ok(),
            );
            if let Err(e) = status {
                let _ = tx.send(Err(e));
            }
        });
        for message in rx {
            let block = message.map_err(&io_error)?;
            let results = parse_block(&block);
            let _ = back.send(block.text);
            each(results)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entity_lines_only() {
        let t = b"s 1 2 3 4\n  pp 3\nfrom 1 2 3\nfoo\nsx 1\n1 2 3\nv\np";
        let at = |p| entity_at(t, p).map(|n| (n.keyword, n.col));
        assert_eq!(at(0), Some(("s", 1)));
        assert_eq!(at(10), Some(("pp", 3)));
        assert_eq!(at(17), None, "from");
        assert_eq!(at(28), None, "foo");
        assert_eq!(at(32), None, "sx");
        assert_eq!(at(37), None, "numbers");
        assert_eq!(at(43), Some(("v", 1)));
        assert_eq!(at(45), None, "`p` cut by the end of the text could be `pp`");
    }

    #[test]
    fn blocks_end_before_entity_lines() {
        let text =
            b"v\nfrom 0 0 0\nat 1 0 0\nup 0 0 1\nangle 40\np 3\n0 0 0\n1 0 0\n0 1 0\ns 0 0 0 1\n";
        for block in 1..text.len() + 2 {
            let mut blocks = Vec::new();
            read_blocks(&text[..], block, |b| {
                blocks.push(b);
                true
            })
            .unwrap();
            let joined: Vec<u8> = blocks.iter().flat_map(|b| b.text.clone()).collect();
            assert_eq!(joined, text, "block size {block}");
            for b in &blocks[..blocks.len() - 1] {
                assert!(b.next.is_some());
            }
            assert!(blocks.last().unwrap().next.is_none());
            for b in &blocks[1..] {
                assert!(
                    entity_at(&b.text, 0).is_some(),
                    "block starts inside an entity: {:?}",
                    String::from_utf8_lossy(&b.text)
                );
            }
        }
    }

    /// Buffers handed back (still holding an earlier block's text) give the same blocks.
    #[test]
    fn recycled_buffers_give_the_same_blocks() {
        let mut text = Vec::new();
        for i in 0..200 {
            text.extend_from_slice(format!("s {i} 0 0 1\np 3\n0 0 0\n1 0 0\n0 1 0\n").as_bytes());
        }
        for block in [16, 50, 333] {
            let mut plain = Vec::new();
            read_blocks(&text[..], block, |b| {
                plain.push(b.text);
                true
            })
            .unwrap();
            let mut recycled = Vec::new();
            let mut handed = 0;
            read_blocks_into(
                &text[..],
                block,
                |b| {
                    recycled.push(b.text);
                    true
                },
                || {
                    handed += 1;
                    Some(vec![b'#'; 4 * block])
                },
            )
            .unwrap();
            assert!(handed > 3);
            assert_eq!(recycled, plain, "block size {block}");
        }
    }

    #[test]
    fn split_covers_the_block() {
        let mut text = Vec::new();
        for i in 0..1000 {
            text.extend_from_slice(format!("s {i} 0 0 1\np 3\n0 0 0\n1 0 0\n0 1 0\n").as_bytes());
        }
        let parts = split(&text, None, 1000);
        assert!(parts.len() > 10);
        let mut at = 0;
        for (r, n) in &parts {
            assert_eq!(r.start, at);
            at = r.end;
            if at < text.len() {
                assert!(["s", "p"].contains(&n.unwrap().keyword));
            }
        }
        assert_eq!(at, text.len());
    }
}
