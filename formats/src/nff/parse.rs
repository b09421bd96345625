//! The chunk parser: NFF text that starts at an entity keyword (or the file start) into
//! primitives grouped by material, with positions local to the chunk. Chunks are parsed in
//! parallel; `super::assemble` fixes up what depends on earlier chunks (the material in effect,
//! line numbers).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use super::lex::{parse_f64, parse_u32, Lines, NumError};
use super::polygon::Triangulator;
use super::NffStats;
use crate::error::shown;

/// A position in a chunk: 0-based line in the chunk, 1-based column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Loc {
    pub line: u32,
    pub col: u32,
}

/// An error in a chunk, positioned in the chunk.
#[derive(Debug)]
pub(crate) struct ChunkError {
    pub at: Loc,
    pub message: String,
}

/// The entity keywords: a line starting with one of these starts a self-contained entity, so
/// the text can be cut before it.
pub(crate) const ENTITIES: [&str; 8] = ["v", "b", "l", "f", "c", "s", "p", "pp"];
const VIEW_KEYS: [&str; 6] = ["from", "at", "up", "angle", "hither", "resolution"];

/// The raw `f` values: r g b Kd Ks Shine T ior.
pub(crate) type Fill = [f64; 8];

#[derive(Clone, Debug)]
pub(crate) struct View {
    pub from: [f64; 3],
    pub at: [f64; 3],
    pub up: [f64; 3],
    pub angle: f64,
    pub resolution: Option<(u32, u32)>,
}

#[derive(Clone, Debug)]
pub(crate) enum Directive {
    View(View),
    Background([f64; 3]),
    Light {
        position: [f64; 3],
        color: Option<[f64; 3]>,
    },
}

/// Primitives of one material (and with or without vertex normals), in file order.
#[derive(Debug, Default)]
pub(crate) struct Bucket {
    /// Local material index, or `None`: the material in effect where the chunk starts.
    pub material: Option<u32>,
    pub with_normals: bool,
    /// The first primitive.
    pub first: Loc,
    pub spheres: Vec<[f64; 4]>,
    pub cones: Vec<[f64; 8]>,
    pub positions: Vec<[f64; 3]>,
    pub normals: Vec<[f64; 3]>,
    pub indices: Vec<[u64; 3]>,
}

/// The kinds of warnings: a file gets the first of each kind, with a count of the rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum NoteKind {
    NegativeSphereRadius,
    NegativeConeRadius,
    PolygonFan,
}

/// Something accepted with a caveat: a warning.
#[derive(Debug)]
pub(crate) struct Note {
    pub at: Loc,
    pub kind: NoteKind,
    pub message: String,
}

#[derive(Debug, Default)]
pub(crate) struct ChunkOut {
    /// Newlines in the chunk.
    pub lines: u32,
    pub directives: Vec<(Directive, Loc)>,
    /// The distinct `f` values of the chunk, first use first.
    pub fills: Vec<(Fill, Loc)>,
    /// The material in effect at the chunk's end (local index), `None`: unchanged.
    pub end_fill: Option<u32>,
    pub buckets: Vec<Bucket>,
    pub stats: NffStats,
    pub notes: Vec<Note>,
}

/// What follows a chunk that is not the last one: the entity keyword on its first line.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Next {
    pub keyword: &'static str,
    pub col: u32,
}

struct Parser<'a> {
    l: Lines<'a>,
    next: Option<Next>,
    out: ChunkOut,
    fill_index: HashMap<[u64; 8], u32>,
    current_fill: Option<u32>,
    /// Bucket in use for primitives without / with normals; reset by `f`.
    bucket: [Option<usize>; 2],
    /// Whether the current line was already used (the view block reads one line ahead).
    pending: bool,
    verts: Vec<[f64; 3]>,
    vnormals: Vec<[f64; 3]>,
    tris: Vec<[u32; 3]>,
    tri: Triangulator,
    /// Per bucket: where each distinct (position, normal) is stored.
    vertex_maps: Vec<VertexMap>,
    /// Polygon vertex -> bucket vertex.
    remap: Vec<u64>,
}

/// Vertex (position and normal bits) to its index in a bucket.
type VertexMap = HashMap<[u64; 6], u32, BuildHasherDefault<WordHasher>>;

/// A fast hasher for keys of whole 64-bit words (multiply-rotate, as in rustc's FxHasher);
/// vertices are not attacker-chosen keys.
#[derive(Default)]
struct WordHasher(u64);

impl Hasher for WordHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for c in bytes.chunks(8) {
            let mut w = [0u8; 8];
            w[..c.len()].copy_from_slice(c);
            self.write_u64(u64::from_le_bytes(w));
        }
    }

    #[inline]
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }

    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

type Result<T> = std::result::Result<T, ChunkError>;

/// Parses one chunk. `next` is `None` for the file's last chunk.
pub(crate) fn parse_chunk(text: &[u8], next: Option<Next>) -> Result<ChunkOut> {
    let mut p = Parser {
        l: Lines::new(text),
        next,
        out: ChunkOut::default(),
        fill_index: HashMap::new(),
        current_fill: None,
        bucket: [None; 2],
        pending: false,
        verts: Vec::new(),
        vnormals: Vec::new(),
        tris: Vec::new(),
        tri: Triangulator::default(),
        vertex_maps: Vec::new(),
        remap: Vec::new(),
    };
    p.run()?;
    while p.l.advance() {}
    p.out.lines = p.l.newlines();
    p.out.end_fill = p.current_fill;
    for b in &mut p.out.buckets {
        b.spheres.shrink_to_fit();
        b.cones.shrink_to_fit();
        b.positions.shrink_to_fit();
        b.normals.shrink_to_fit();
        b.indices.shrink_to_fit();
    }
    Ok(p.out)
}

/// A token of the file as it may be echoed in a message (see `shown`).
fn show(token: &[u8]) -> String {
    shown(&String::from_utf8_lossy(token)).into_owned()
}

impl<'a> Parser<'a> {
    fn err<T>(&self, col: u32, message: impl Into<String>) -> Result<T> {
        Err(ChunkError {
            at: Loc {
                line: self.l.line,
                col,
            },
            message: message.into(),
        })
    }

    fn loc(&self, k: usize) -> Loc {
        Loc {
            line: self.l.line,
            col: self.l.col(k),
        }
    }

    /// A warning at token `k` of the current line.
    fn note(&mut self, k: usize, kind: NoteKind, message: String) {
        let at = self.loc(k);
        self.out.notes.push(Note { at, kind, message });
    }

    /// A negative radius (token `k`): NFF's "only the inside is visible". Luxon's spheres and
    /// cones are seen from both sides: the radius is made positive, with a warning.
    fn negative_radius(&mut self, k: usize, shape: &str, kind: NoteKind) {
        let written = show(self.l.tok(k));
        let message = format!(
            "{shape} radius {written} is negative (NFF's inside-only {shape}); Luxon's {shape}s \
             are two-sided, so it is drawn with radius {}",
            written.trim_start_matches('-')
        );
        self.note(k, kind, message);
    }

    /// The next line, or an error saying what was `expected` if the chunk ends first.
    fn line_for(&mut self, expected: &dyn Fn() -> String) -> Result<()> {
        if self.l.advance() {
            return Ok(());
        }
        match self.next {
            // The next chunk starts with an entity keyword: that is what was found.
            Some(n) => Err(ChunkError {
                at: Loc {
                    line: self.l.newlines(),
                    col: n.col,
                },
                message: format!("expected {}, found `{}`", expected(), n.keyword),
            }),
            None => {
                let (line, col) = self.l.end_position();
                Err(ChunkError {
                    at: Loc { line, col },
                    message: format!("the file ends early; expected {}", expected()),
                })
            }
        }
    }

    fn run(&mut self) -> Result<()> {
        loop {
            if !self.pending && !self.l.advance() {
                return Ok(());
            }
            self.pending = false;
            let kw = self.l.tok(0);
            match kw {
                b"s" => self.sphere()?,
                b"p" => self.polygon(false)?,
                b"pp" => self.polygon(true)?,
                b"c" => self.cone()?,
                b"f" => self.fill()?,
                b"l" => self.light()?,
                b"b" => self.background()?,
                b"v" => self.view()?,
                _ => return self.unknown_keyword(0),
            }
        }
    }

    fn unknown_keyword<T>(&self, k: usize) -> Result<T> {
        let kw = self.l.tok(k);
        let col = self.l.col(k);
        let list = "`v`, `b`, `l`, `f`, `c`, `s`, `p`, `pp` or a `#` comment";
        if parse_f64(kw).is_ok() || parse_f64(kw) == Err(NumError::NotFinite) {
            return self.err(
                col,
                format!(
                    "expected an NFF entity keyword ({list}), found the number `{}` \
                     (more values than the entity before it takes?)",
                    show(kw)
                ),
            );
        }
        let word = String::from_utf8_lossy(kw);
        let mut msg = format!("unknown NFF keyword `{}`", show(kw));
        if let Some(s) = crate::error::suggest(&word, ENTITIES.iter().copied().chain(VIEW_KEYS)) {
            if VIEW_KEYS.contains(&s) && VIEW_KEYS.contains(&word.as_ref()) {
                msg = format!("`{word}` belongs in a `v` view block, after `v`");
            } else {
                msg.push_str(&format!("; did you mean `{s}`?"));
            }
        }
        self.err(col, format!("{msg}; expected {list}"))
    }

    /// Reads tokens `from..from + N` of the current line as numbers; the line must have
    /// exactly `from + N` tokens. `what` names the entity, `names` the values.
    fn numbers<const N: usize>(&self, from: usize, what: &str, names: &str) -> Result<[f64; N]> {
        let have = self.l.toks.len() - from;
        if have != N {
            let col = self.l.col(from + N.min(have));
            return if have < N {
                self.err(
                    col,
                    format!(
                        "{what} takes {N} numbers ({names}), found {have}; expected another number"
                    ),
                )
            } else {
                self.err(
                    col,
                    format!(
                        "{what} takes {N} numbers ({names}), found {have}; unexpected `{}`",
                        show(self.l.tok(from + N))
                    ),
                )
            };
        }
        let mut v = [0.0; N];
        for (i, x) in v.iter_mut().enumerate() {
            *x = self.number(from + i, what, names)?;
        }
        Ok(v)
    }

    #[inline]
    fn number(&self, k: usize, what: &str, names: &str) -> Result<f64> {
        let t = self.l.tok(k);
        match parse_f64(t) {
            Ok(v) => Ok(v),
            Err(NumError::NotANumber) => self.err(
                self.l.col(k),
                format!("expected a number ({what}: {names}), found `{}`", show(t)),
            ),
            Err(NumError::NotFinite) => self.err(
                self.l.col(k),
                format!(
                    "expected a finite number ({what}: {names}), found `{}`: NaN and infinities are not allowed",
                    show(t)
                ),
            ),
        }
    }

    /// Index of the bucket for the current material; `first` positions a new bucket.
    fn bucket(&mut self, with_normals: bool, first: Loc) -> usize {
        let slot = with_normals as usize;
        if let Some(i) = self.bucket[slot] {
            return i;
        }
        let material = self.current_fill;
        let found = self
            .out
            .buckets
            .iter()
            .position(|b| b.material == material && b.with_normals == with_normals);
        let i = found.unwrap_or_else(|| {
            self.out.buckets.push(Bucket {
                material,
                with_normals,
                first,
                ..Default::default()
            });
            self.out.buckets.len() - 1
        });
        self.bucket[slot] = Some(i);
        i
    }

    fn sphere(&mut self) -> Result<()> {
        let s = self.numbers::<4>(1, "`s` sphere", "x y z radius")?;
        if s[3] == 0.0 {
            return self.err(
                self.l.col(4),
                "sphere radius is 0; expected a radius other than 0",
            );
        }
        if s[3] < 0.0 {
            self.negative_radius(4, "sphere", NoteKind::NegativeSphereRadius);
        }
        let s = [s[0], s[1], s[2], s[3].abs()];
        self.out.stats.spheres += 1;
        let b = self.bucket(false, self.loc(0));
        self.out.buckets[b].spheres.push(s);
        Ok(())
    }

    fn cone(&mut self) -> Result<()> {
        let names = "base x y z radius, apex x y z radius";
        let kw_loc = self.loc(0);
        let c: [f64; 8] = match self.l.toks.len() - 1 {
            // The one-line form the SPD programs write.
            8 => {
                let c = self.numbers::<8>(1, "`c` cone", names)?;
                for k in [3, 7] {
                    if c[k] < 0.0 {
                        self.negative_radius(k + 1, "cone", NoteKind::NegativeConeRadius);
                    }
                }
                c
            }
            // The two-line form of NFF.TXT.
            0 => {
                let start = self.l.line;
                let expected = |part: &'static str| {
                    move || {
                        format!(
                            "the cone's {part} line (x y z radius) after `c` on line {}",
                            start + 1
                        )
                    }
                };
                self.line_for(&expected("base"))?;
                let b = self.numbers::<4>(0, "`c` cone base", "x y z radius")?;
                if b[3] < 0.0 {
                    self.negative_radius(3, "cone", NoteKind::NegativeConeRadius);
                }
                self.line_for(&expected("apex"))?;
                let a = self.numbers::<4>(0, "`c` cone apex", "x y z radius")?;
                if a[3] < 0.0 {
                    self.negative_radius(3, "cone", NoteKind::NegativeConeRadius);
                }
                [b[0], b[1], b[2], b[3], a[0], a[1], a[2], a[3]]
            }
            n => {
                return self.err(
                    self.l.col(1),
                    format!(
                        "`c` takes 8 numbers on its line ({names}) or none (then base and apex \
                         on the next two lines), found {n}"
                    ),
                )
            }
        };
        let (rb, ra) = (c[3].abs(), c[7].abs());
        if rb == 0.0 && ra == 0.0 {
            return Err(ChunkError {
                at: kw_loc,
                message: "cone radii are both 0; expected a radius other than 0".into(),
            });
        }
        if c[0..3] == c[4..7] {
            return Err(ChunkError {
                at: kw_loc,
                message:
                    "cone base and apex are the same point; expected an axis of non-zero length"
                        .into(),
            });
        }
        let c = [c[0], c[1], c[2], rb, c[4], c[5], c[6], ra];
        self.out.stats.cones += 1;
        let b = self.bucket(false, kw_loc);
        self.out.buckets[b].cones.push(c);
        Ok(())
    }

    fn polygon(&mut self, patch: bool) -> Result<()> {
        let what = if patch { "`pp` patch" } else { "`p` polygon" };
        let kw_loc = self.loc(0);
        if self.l.toks.len() != 2 {
            let k = self.l.toks.len().min(2);
            return self.err(
                self.l.col(k),
                format!(
                    "{what} takes 1 number on its line (the vertex count), found {}",
                    self.l.toks.len() - 1
                ),
            );
        }
        let count = match parse_u32(self.l.tok(1)) {
            Some(n) => n,
            None => {
                return self.err(
                    self.l.col(1),
                    format!(
                        "expected a whole vertex count after `{}`, found `{}`",
                        if patch { "pp" } else { "p" },
                        show(self.l.tok(1))
                    ),
                )
            }
        };
        if count < 3 {
            return self.err(
                self.l.col(1),
                format!("a polygon needs at least 3 vertices, found {count}"),
            );
        }
        let start_line = self.l.line;
        self.verts.clear();
        self.vnormals.clear();
        for k in 0..count {
            // The hot path: a line of plain numbers.
            if patch {
                let mut v = [0.0; 6];
                if self.l.numbers_line(&mut v) {
                    self.verts.push([v[0], v[1], v[2]]);
                    self.vnormals.push([v[3], v[4], v[5]]);
                    continue;
                }
            } else {
                let mut v = [0.0; 3];
                if self.l.numbers_line(&mut v) {
                    self.verts.push(v);
                    continue;
                }
            }
            let expected = || {
                format!(
                    "vertex {} of {count} ({}) of the {what} on line {}",
                    k + 1,
                    if patch { "x y z nx ny nz" } else { "x y z" },
                    start_line + 1
                )
            };
            self.line_for(&expected)?;
            let first = self.l.tok(0);
            if first.first().is_some_and(u8::is_ascii_alphabetic)
                && parse_f64(first) == Err(NumError::NotANumber)
            {
                return self.err(
                    self.l.col(0),
                    format!("expected {}, found `{}`", expected(), show(first)),
                );
            }
            if patch {
                let v = self.numbers::<6>(0, "`pp` vertex", "x y z nx ny nz")?;
                self.verts.push([v[0], v[1], v[2]]);
                self.vnormals.push([v[3], v[4], v[5]]);
            } else {
                let v = self.numbers::<3>(0, "`p` vertex", "x y z")?;
                self.verts.push(v);
            }
        }
        self.tris.clear();
        let outcome = self.tri.triangulate(&self.verts, &mut self.tris);
        if outcome.fan > 0 {
            self.out.notes.push(Note {
                at: kw_loc,
                kind: NoteKind::PolygonFan,
                message: format!(
                    "{what} of {count} vertices could not be cut into ears within its time \
                     budget (it intersects itself or is very irregular); its last {} triangles \
                     are a fan from one corner, which may cover area outside the polygon",
                    outcome.fan
                ),
            });
        }
        if patch {
            self.out.stats.patches += 1;
        } else {
            self.out.stats.polygons += 1;
        }
        self.out.stats.triangles += self.tris.len() as u64;
        let i = self.bucket(patch, kw_loc);
        // Vertices shared with earlier polygons of the bucket (same position and normal, to
        // the bit) are stored once: a tessellated surface such as the SPD teapot needs about a
        // sixth of the memory then.
        if self.vertex_maps.len() <= i {
            self.vertex_maps.resize_with(i + 1, VertexMap::default);
        }
        let b = &mut self.out.buckets[i];
        let map = &mut self.vertex_maps[i];
        self.remap.clear();
        for (k, p) in self.verts.iter().enumerate() {
            let n = if patch { self.vnormals[k] } else { [0.0; 3] };
            let key = [p[0], p[1], p[2], n[0], n[1], n[2]].map(f64::to_bits);
            let next = b.positions.len() as u32;
            let index = *map.entry(key).or_insert(next);
            if index == next {
                b.positions.push(*p);
                if patch {
                    b.normals.push(n);
                }
            }
            self.remap.push(index as u64);
        }
        let remap = &self.remap;
        b.indices
            .extend(self.tris.iter().map(|t| t.map(|k| remap[k as usize])));
        Ok(())
    }

    fn fill(&mut self) -> Result<()> {
        let f = self.numbers::<8>(1, "`f` fill", "r g b Kd Ks Shine T index_of_refraction")?;
        for (i, name) in ["red", "green", "blue", "Kd", "Ks", "Shine", "T"]
            .iter()
            .enumerate()
        {
            if f[i] < 0.0 {
                return self.err(
                    self.l.col(i + 1),
                    format!(
                        "`f` {name} is {}; expected a value >= 0",
                        show(self.l.tok(i + 1))
                    ),
                );
            }
        }
        if f[7] < 0.0 {
            return self.err(
                self.l.col(8),
                format!(
                    "`f` index of refraction is {}; expected a value >= 0 (0: none)",
                    show(self.l.tok(8))
                ),
            );
        }
        self.out.stats.fills += 1;
        let key = f.map(f64::to_bits);
        let index = match self.fill_index.get(&key) {
            Some(&i) => i,
            None => {
                let i = self.out.fills.len() as u32;
                self.out.fills.push((f, self.loc(0)));
                self.fill_index.insert(key, i);
                i
            }
        };
        if self.current_fill != Some(index) {
            self.current_fill = Some(index);
            self.bucket = [None; 2];
        }
        Ok(())
    }

    fn light(&mut self) -> Result<()> {
        let names = "x y z, optionally r g b";
        let (position, color) = match self.l.toks.len() - 1 {
            3 => (self.numbers::<3>(1, "`l` light", names)?, None),
            6 => {
                let v = self.numbers::<6>(1, "`l` light", names)?;
                if let Some(k) = (3..6).find(|&k| v[k] < 0.0) {
                    return self.err(
                        self.l.col(k + 1),
                        format!(
                            "light colour {} is negative; expected a value >= 0",
                            show(self.l.tok(k + 1))
                        ),
                    );
                }
                ([v[0], v[1], v[2]], Some([v[3], v[4], v[5]]))
            }
            n => {
                let col = self.l.col(if n < 3 { n + 1 } else { 4.min(n + 1) });
                return self.err(
                    col,
                    format!("`l` light takes 3 numbers (x y z) or 6 (x y z r g b), found {n}"),
                );
            }
        };
        self.out.stats.lights += 1;
        let at = self.loc(0);
        self.out
            .directives
            .push((Directive::Light { position, color }, at));
        Ok(())
    }

    fn background(&mut self) -> Result<()> {
        let c = self.numbers::<3>(1, "`b` background", "r g b")?;
        let at = self.loc(0);
        self.out.directives.push((Directive::Background(c), at));
        Ok(())
    }

    fn view(&mut self) -> Result<()> {
        let at = self.loc(0);
        if self.l.toks.len() > 1 {
            return self.err(
                self.l.col(1),
                format!(
                    "`v` stands alone on its line; found `{}` (from, at, up, angle, hither and \
                     resolution follow on lines of their own)",
                    show(self.l.tok(1))
                ),
            );
        }
        let view = self.view_lines()?.into_view(at)?;
        self.out.directives.push((Directive::View(view), at));
        Ok(())
    }

    /// The lines after `v`, up to the next entity (which is left `pending`).
    fn view_lines(&mut self) -> Result<ViewLines> {
        let mut v = ViewLines::default();
        while self.l.advance() {
            let key = self.l.tok(0);
            let Some(k) = VIEW_KEYS.iter().position(|v| v.as_bytes() == key) else {
                if ENTITIES.iter().any(|e| e.as_bytes() == key) {
                    // The next entity ends the view.
                    self.pending = true;
                    break;
                }
                return self.unknown_keyword(0);
            };
            let name = VIEW_KEYS[k];
            let seen = match k {
                0 => v.from.is_some(),
                1 => v.look.is_some(),
                2 => v.up.is_some(),
                3 => v.angle.is_some(),
                4 => v.hither.is_some(),
                _ => v.resolution.is_some(),
            };
            if seen {
                return self.err(
                    self.l.col(0),
                    format!("`{name}` given twice in one `v` view"),
                );
            }
            match k {
                0 => v.from = Some(self.numbers::<3>(1, "`from`", "x y z")?),
                1 => v.look = Some(self.numbers::<3>(1, "`at`", "x y z")?),
                2 => {
                    v.up = Some(self.numbers::<3>(1, "`up`", "x y z")?);
                    v.up_at = Loc {
                        line: self.l.line,
                        col: self.l.col(1),
                    };
                }
                3 => v.angle = Some(self.view_angle()?),
                // Read and checked, then ignored: Luxon has no near clipping plane.
                4 => v.hither = Some(self.numbers::<1>(1, "`hither`", "near distance")?[0]),
                _ => v.resolution = Some(self.view_resolution()?),
            }
        }
        Ok(v)
    }

    /// `angle a`: the full field of view in degrees.
    fn view_angle(&self) -> Result<f64> {
        let [a] = self.numbers::<1>(1, "`angle`", "full field of view in degrees")?;
        if !(a > 0.0 && a < 180.0) {
            return self.err(
                self.l.col(1),
                format!(
                    "`angle` is {}; expected a field of view in (0, 180) degrees",
                    show(self.l.tok(1))
                ),
            );
        }
        Ok(a)
    }

    /// `resolution w h`: the image size in pixels.
    fn view_resolution(&self) -> Result<(u32, u32)> {
        if self.l.toks.len() != 3 {
            return self.err(
                self.l.col(self.l.toks.len().min(3)),
                format!(
                    "`resolution` takes 2 whole numbers (width height), found {}",
                    self.l.toks.len() - 1
                ),
            );
        }
        let mut r = [0u32; 2];
        for i in 0..2 {
            r[i] = match parse_u32(self.l.tok(i + 1)) {
                Some(v) if (1..=65536).contains(&v) => v,
                _ => {
                    return self.err(
                        self.l.col(i + 1),
                        format!(
                            "expected a whole number of pixels in 1..=65536 for the {}, found `{}`",
                            ["width", "height"][i],
                            show(self.l.tok(i + 1))
                        ),
                    )
                }
            };
        }
        Ok((r[0], r[1]))
    }
}

/// The lines of one `v` view, as read.
#[derive(Default)]
struct ViewLines {
    from: Option<[f64; 3]>,
    look: Option<[f64; 3]>,
    up: Option<[f64; 3]>,
    angle: Option<f64>,
    hither: Option<f64>,
    resolution: Option<(u32, u32)>,
    /// Where the `up` vector was given, for its error.
    up_at: Loc,
}

impl ViewLines {
    /// The view, if it is complete and `from`, `at` and `up` make a frame; `at` is the `v`.
    fn into_view(self, at: Loc) -> Result<View> {
        let missing: Vec<&str> = [
            ("from", self.from.is_none()),
            ("at", self.look.is_none()),
            ("up", self.up.is_none()),
            ("angle", self.angle.is_none()),
        ]
        .iter()
        .filter(|m| m.1)
        .map(|m| m.0)
        .collect();
        let (Some(from), Some(look), Some(up), Some(angle)) =
            (self.from, self.look, self.up, self.angle)
        else {
            return Err(ChunkError {
                at,
                message: format!(
                    "the `v` view lacks {}; expected lines `from x y z`, `at x y z`, `up x y z`, \
                     `angle degrees` (and optionally `hither d`, `resolution w h`) after `v`",
                    missing
                        .iter()
                        .map(|m| format!("`{m}`"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            });
        };
        let dir = [look[0] - from[0], look[1] - from[1], look[2] - from[2]];
        if dir == [0.0; 3] {
            return Err(ChunkError {
                at,
                message: "the `v` view's `from` and `at` are the same point; expected a direction to look in".into(),
            });
        }
        let cross = [
            dir[1] * up[2] - dir[2] * up[1],
            dir[2] * up[0] - dir[0] * up[2],
            dir[0] * up[1] - dir[1] * up[0],
        ];
        let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if norm(cross) <= 1e-9 * norm(dir) * norm(up) {
            return Err(ChunkError {
                at: self.up_at,
                message: "`up` is zero or parallel to the viewing direction (from -> at); expected a vector across it".into(),
            });
        }
        Ok(View {
            from,
            at: look,
            up,
            angle,
            resolution: self.resolution,
        })
    }
}
