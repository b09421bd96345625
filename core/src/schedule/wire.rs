//! Chunks and statistics as bytes, for messages between ranks (all ranks run the same binary on
//! machines of one byte order, so native-endian words are enough).

use super::{RankStats, WorkerStats};
use crate::framebuffer::{Chunk, Span};
use crate::geometry::Counters;
use std::time::Duration;

fn put32(b: &mut Vec<u8>, v: u32) {
    b.extend_from_slice(&v.to_ne_bytes());
}

fn put64(b: &mut Vec<u8>, v: u64) {
    b.extend_from_slice(&v.to_ne_bytes());
}

struct Reader<'a>(&'a [u8]);

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let (head, rest) = self.0.split_at_checked(N)?;
        self.0 = rest;
        head.try_into().ok()
    }
    fn u32(&mut self) -> Option<u32> {
        self.take().map(u32::from_ne_bytes)
    }
    fn u64(&mut self) -> Option<u64> {
        self.take().map(u64::from_ne_bytes)
    }
}

/// `[spans][has depth][y x0 step count]*[rgba f32]*[depth f32]*` (depth values only when
/// `has depth` is 1).
pub fn encode_chunk(c: &Chunk) -> Vec<u8> {
    let mut b = Vec::with_capacity(8 + c.spans.len() * 16 + (c.rgba.len() + c.depth.len()) * 4);
    put32(&mut b, c.spans.len() as u32);
    put32(&mut b, u32::from(!c.depth.is_empty()));
    for s in &c.spans {
        for v in [s.y, s.x0, s.step, s.count] {
            put32(&mut b, v);
        }
    }
    for v in c.rgba.iter().chain(&c.depth) {
        put32(&mut b, v.to_bits());
    }
    b
}

pub fn decode_chunk(bytes: &[u8]) -> Option<Chunk> {
    let mut r = Reader(bytes);
    let n = r.u32()? as usize;
    let has_depth = match r.u32()? {
        0 => false,
        1 => true,
        _ => return None,
    };
    let mut spans = Vec::with_capacity(n.min(bytes.len() / 16));
    for _ in 0..n {
        spans.push(Span {
            y: r.u32()?,
            x0: r.u32()?,
            step: r.u32()?,
            count: r.u32()?,
        });
    }
    let pixels: usize = spans.iter().map(|s| s.count as usize).sum();
    // The spans' counts are only a claim: reserve no more than the message holds.
    let mut rgba = Vec::with_capacity(pixels.saturating_mul(4).min(r.0.len() / 4));
    for _ in 0..pixels * 4 {
        rgba.push(f32::from_bits(r.u32()?));
    }
    let mut depth = Vec::with_capacity(if has_depth {
        pixels.min(r.0.len() / 4)
    } else {
        0
    });
    for _ in 0..if has_depth { pixels } else { 0 } {
        depth.push(f32::from_bits(r.u32()?));
    }
    r.0.is_empty().then_some(Chunk { spans, rgba, depth })
}

/// `[rank][time ns][threads][units pixels primary shadow reflection refraction occlusion tests nan volume_samples busy]*[instances][nan]*`
pub fn encode_stats(s: &RankStats) -> Vec<u8> {
    let mut b = Vec::new();
    put64(&mut b, s.rank as u64);
    put64(&mut b, s.time.as_nanos() as u64);
    put64(&mut b, s.threads.len() as u64);
    for w in &s.threads {
        let c = &w.counters;
        for v in [
            w.units,
            w.pixels,
            c.primary,
            c.shadow,
            c.reflection,
            c.refraction,
            c.occlusion,
            c.tests,
            c.nan_pixels,
            c.volume_samples,
            w.busy.as_nanos() as u64,
        ] {
            put64(&mut b, v);
        }
    }
    put64(&mut b, s.nan_sources.len() as u64);
    for &n in &s.nan_sources {
        put64(&mut b, n);
    }
    b
}

pub fn decode_stats(bytes: &[u8]) -> Option<RankStats> {
    let mut r = Reader(bytes);
    let rank = r.u64()? as usize;
    let time = Duration::from_nanos(r.u64()?);
    let n = r.u64()? as usize;
    let mut threads = Vec::with_capacity(n.min(bytes.len() / 80));
    for _ in 0..n {
        threads.push(WorkerStats {
            units: r.u64()?,
            pixels: r.u64()?,
            counters: Counters {
                primary: r.u64()?,
                shadow: r.u64()?,
                reflection: r.u64()?,
                refraction: r.u64()?,
                occlusion: r.u64()?,
                tests: r.u64()?,
                nan_pixels: r.u64()?,
                volume_samples: r.u64()?,
            },
            busy: Duration::from_nanos(r.u64()?),
        });
    }
    let n = r.u64()? as usize;
    let mut nan_sources = Vec::with_capacity(n.min(bytes.len() / 8));
    for _ in 0..n {
        nan_sources.push(r.u64()?);
    }
    r.0.is_empty().then_some(RankStats {
        rank,
        threads,
        time,
        nan_sources,
    })
}

/// How a group's frame ended, sent by its leader to the rank that deals frames.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameResult {
    pub frame: u32,
    /// The files written (`Ok`) or why the frame failed.
    pub outcome: Result<Vec<String>, String>,
    /// Seconds from taking the frame to writing its files.
    pub seconds: f64,
}

/// `[frame][ok][seconds][count]([length][bytes])*` (ok: `count` file names; failed: one
/// message).
pub fn encode_frame_result(r: &FrameResult) -> Vec<u8> {
    let mut b = Vec::new();
    put32(&mut b, r.frame);
    put32(&mut b, u32::from(r.outcome.is_ok()));
    put64(&mut b, r.seconds.to_bits());
    let texts = match &r.outcome {
        Ok(files) => files.clone(),
        Err(m) => vec![m.clone()],
    };
    put32(&mut b, texts.len() as u32);
    for t in texts {
        put32(&mut b, t.len() as u32);
        b.extend_from_slice(t.as_bytes());
    }
    b
}

pub fn decode_frame_result(bytes: &[u8]) -> Option<FrameResult> {
    let mut r = Reader(bytes);
    let frame = r.u32()?;
    let ok = match r.u32()? {
        0 => false,
        1 => true,
        _ => return None,
    };
    let seconds = f64::from_bits(r.u64()?);
    let n = r.u32()? as usize;
    let mut texts = Vec::with_capacity(n.min(bytes.len() / 4));
    for _ in 0..n {
        let len = r.u32()? as usize;
        let (text, rest) = r.0.split_at_checked(len)?;
        r.0 = rest;
        texts.push(String::from_utf8_lossy(text).into_owned());
    }
    if !r.0.is_empty() || (!ok && texts.len() != 1) {
        return None;
    }
    let outcome = match ok {
        true => Ok(texts),
        false => Err(texts.remove(0)),
    };
    Some(FrameResult {
        frame,
        outcome,
        seconds,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A message whose spans claim billions of pixels it does not hold is refused without
    /// reserving memory for them.
    #[test]
    fn a_chunk_claiming_more_pixels_than_it_holds_is_refused() {
        let mut b = Vec::new();
        put32(&mut b, 2);
        put32(&mut b, 1);
        for _ in 0..2 {
            for v in [0, 0, 1, u32::MAX] {
                put32(&mut b, v);
            }
        }
        put32(&mut b, 0);
        assert!(decode_chunk(&b).is_none());
    }

    #[test]
    fn chunks_and_stats_round_trip() {
        let c = Chunk {
            spans: vec![
                Span {
                    y: 3,
                    x0: 1,
                    step: 2,
                    count: 2,
                },
                Span {
                    y: 4,
                    x0: 0,
                    step: 1,
                    count: 1,
                },
            ],
            rgba: (0..12).map(|i| i as f32 * 0.37 - 1.0).collect(),
            depth: Vec::new(),
        };
        let b = encode_chunk(&c);
        assert_eq!(decode_chunk(&b), Some(c.clone()));
        assert_eq!(decode_chunk(&b[..b.len() - 1]), None);
        // With depth: one value per pixel, INFINITY (nothing hit) included.
        let c = Chunk {
            depth: vec![4.5, f32::INFINITY, 0.25],
            ..c
        };
        let b = encode_chunk(&c);
        assert_eq!(decode_chunk(&b), Some(c));
        assert_eq!(decode_chunk(&b[..b.len() - 4]), None);
        let s = RankStats {
            rank: 2,
            time: Duration::from_millis(1234),
            threads: vec![WorkerStats {
                units: 5,
                pixels: 80,
                counters: Counters {
                    primary: 80,
                    shadow: 7,
                    reflection: 6,
                    refraction: 5,
                    occlusion: 2,
                    tests: 4,
                    nan_pixels: 1,
                    volume_samples: 3,
                },
                busy: Duration::from_micros(99),
            }],
            nan_sources: vec![0, 12, 0],
        };
        assert_eq!(decode_stats(&encode_stats(&s)), Some(s));
    }

    #[test]
    fn frame_results_round_trip() {
        let results = [
            FrameResult {
                frame: 37,
                outcome: Ok(vec!["out/f0037.png".into(), "out/f0037.exr".into()]),
                seconds: 1.25,
            },
            FrameResult {
                frame: 3,
                outcome: Err("the camera's `up` has zero length at frame 3".into()),
                seconds: 0.0,
            },
        ];
        for r in results {
            let b = encode_frame_result(&r);
            assert_eq!(decode_frame_result(&b), Some(r));
            assert_eq!(decode_frame_result(&b[..b.len() - 1]), None);
            let mut longer = b.clone();
            longer.push(0);
            assert_eq!(decode_frame_result(&longer), None);
        }
    }
}
