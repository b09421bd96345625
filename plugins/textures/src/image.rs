//! The `image` entry: an image file mapped onto surfaces, filtered, through the shared cache.

use crate::cache::{self, Cache, CachedImage};
use crate::decode::{plan, probe, Plan};
use crate::mapping::{Kind, Mapping};
use crate::mipmap::{
    bilinear, bilinear_inside, level_pair, mip_level, nearest, trilinear, Level, Wrap,
};
use crate::params::{up, yes, Factors};
use luxon_plugin::abi::{TexQuery, READS_DISTANCE, READS_FOOTPRINT, READS_POINT, READS_UV};
use luxon_plugin::{invalid, Context, Describe, Error, Texture};
use serde::Deserialize;
use std::sync::Arc;

/// What an image that cannot be decoded looks like.
pub const MAGENTA: [f32; 4] = [1.0, 0.0, 1.0, 1.0];

#[derive(Clone, Copy, Debug, Default, PartialEq, Deserialize)]
pub enum Filter {
    /// The texel under the point, full resolution.
    #[serde(rename = "nearest", alias = "Nearest")]
    Nearest,
    /// The four nearest texels, full resolution.
    #[serde(rename = "bilinear", alias = "Bilinear")]
    Bilinear,
    /// Trilinear between the two MIP levels the ray's footprint falls between.
    #[default]
    #[serde(rename = "mip", alias = "Mip")]
    Mip,
    /// Tachyon's MIP blur, which grows with the distance the ray travelled rather than with
    /// the pixel's footprint: `tachyon(k)` blends levels `d (L − 0.9999)` of `L`, with
    /// `d = k × distance` (planar), or that over `8 ×` the point's distance from `center`
    /// (cylindrical, spherical), clamped to [0, 1]; from level `L − 2` on, the 1×1 level alone.
    /// Texels are placed as Tachyon places them (the first and last texel centres at 0 and 1,
    /// wrapping by the fractional part; `wrap` is not read). The Tachyon importer writes
    /// `k = 0.05 × |SCALE|` (the larger of its two).
    #[serde(rename = "tachyon", alias = "Tachyon")]
    Tachyon(f64),
}

/// Tachyon's level count for a `w × h` image: the bit length of the larger side (256: 9
/// levels, 256² down to 1²).
fn tachyon_levels(w: usize, h: usize) -> usize {
    (usize::BITS - w.max(h).leading_zeros()) as usize
}

/// `x`'s fractional part, in [0, 1).
fn fract(x: f64) -> f64 {
    let f = x - x.floor();
    if f < 1.0 {
        f
    } else {
        0.0
    }
}

/// Bilinear as Tachyon's `ImageMap` places texels: `u` = 0 and 1 on the first and last texel
/// centres of a row (`x = (w − 1) u`), `v` from the top row likewise.
fn tachyon_bilinear(level: &Level, u: f64, v: f64) -> [f32; 4] {
    let (w, h) = level.last();
    bilinear_inside(level, w * u, h * v)
}

/// The two levels and the weight of the second that Tachyon's MIP lookup blends for blur `d`
/// on a pyramid of `levels`, as its `MIPMap` does: `d` clamped to [0, 1] is spread over
/// `levels − 0.9999`, and past the second-coarsest level the coarsest is used alone.
fn tachyon_pair(d: f64, levels: usize) -> (usize, usize, f32) {
    let d = if d.is_nan() { 1.0 } else { d.clamp(0.0, 1.0) };
    let at = d * (levels as f64 - 0.9999);
    let lo = at as usize;
    if lo + 2 < levels {
        (lo, lo + 1, (at - lo as f64) as f32)
    } else {
        let last = levels.saturating_sub(1);
        (last, last, 0.0)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageParams {
    file: String,
    #[serde(default = "yes")]
    srgb: bool,
    #[serde(default)]
    mapping: Kind,
    center: Option<[f64; 3]>,
    axis: Option<[f64; 3]>,
    #[serde(default)]
    scale: Factors<2>,
    #[serde(default)]
    rotate: f64,
    #[serde(default)]
    offset: [f64; 2],
    #[serde(default)]
    wrap: Wrap,
    #[serde(default)]
    filter: Filter,
}

pub struct ImageTexture {
    cache: Arc<Cache>,
    image: Arc<CachedImage>,
    mapping: Mapping,
    wrap: Wrap,
    filter: Filter,
}

impl Describe for ImageTexture {
    const NAME: &'static str = "image";
    const DESCRIPTION: &'static str = "An image file (PNG, JPEG, TGA, PPM, EXR) mapped by mesh uv or a planar, cylindrical or spherical projection; MIP-mapped, loaded on first use into a shared LRU cache.";
    const PARAMS: &'static str = "\
file: path = required  PNG, JPEG, TGA, PPM/PGM/PBM/PAM or OpenEXR file, relative to the scene file
srgb: bool = true  integer (8/16-bit) sources are sRGB-encoded; false: already linear (EXR is always linear)
mapping: uv|planar|cylindrical|spherical = uv  mesh texture coordinates, or a projection around `center`/`axis`
center: (x, y, z) = (0, 0, 0)  origin of the projection (not with `uv`)
axis: (x, y, z) = (0, 1, 0)  plane normal (planar) or pole (cylindrical, spherical); not with `uv`
scale: f64 or (u, v) = 1.0  size of one copy of the image in mapping units (not 0; negative mirrors)
rotate: f64 = 0.0  turns the image counter-clockwise, degrees
offset: (u, v) = (0, 0)  where the image's corner (0, 0) lands, mapping units
wrap: repeat|clamp|mirror = repeat  outside the image: tile, extend the edges, or tile mirrored
filter: nearest|bilinear|mip|tachyon(k) = mip  mip: trilinear, level chosen from the ray's footprint; tachyon(k): Tachyon's blur, k × the distance the ray travelled";
}

/// The most memory one image may use while it is decoded (see `decode.rs`): its MIP levels
/// from the first one kept, plus what the decoder holds. An image whose full pyramid does not
/// fit is used from the first level that does (with a warning); a format decoded whole whose
/// buffer alone does not fit is refused.
///
/// It is the texture cache budget (`texture_cache_bytes`), or when that is 0 the cache's
/// default of 1 GiB ([`cache::DEFAULT_BUDGET`]): levels that do not fit the cache cannot stay
/// resident anyway (they would be evicted after each decode and decoded again), and 1 GiB holds
/// the full pyramid of a 7000×7000 image, more than a 4K or 8K render resolves. When the host
/// gives a memory budget (`memory_budget`, 0 when unknown), the cap is at most what is left of
/// it, so a decode never takes memory the rest of the scene was promised.
pub fn decode_cap(ctx: &Context) -> u64 {
    let cache = match ctx.texture_cache_bytes {
        0 => cache::DEFAULT_BUDGET,
        bytes => bytes,
    };
    match ctx.memory_budget {
        0 => cache,
        left => cache.min(left),
    }
}

impl ImageTexture {
    /// `create` with an explicit cache (the plugin uses `cache::global`).
    pub fn create_in(p: ImageParams, ctx: &Context, cache: Arc<Cache>) -> Result<Self, Error> {
        if p.mapping == Kind::Uv {
            for (name, given) in [("center", p.center.is_some()), ("axis", p.axis.is_some())] {
                if given {
                    return Err(invalid(format!(
                        "parameter `{name}` has no effect with `uv` mapping \
                         (it places planar, cylindrical and spherical projections)"
                    )));
                }
            }
        }
        let mapping = Mapping::new(
            p.mapping,
            p.center.unwrap_or_default(),
            p.axis.unwrap_or_else(up),
            p.scale,
            p.rotate,
            p.offset,
        )?;
        if p.file.is_empty() {
            return Err(invalid("parameter `file` must name an image file"));
        }
        if let Filter::Tachyon(k) = p.filter {
            if !(k.is_finite() && k >= 0.0) {
                return Err(invalid(format!(
                    "filter `tachyon({k})`: the blur per unit of distance must be a finite \
                     number ≥ 0"
                )));
            }
            if p.mapping == Kind::Uv {
                return Err(invalid(
                    "filter `tachyon` follows Tachyon's planar, cylindrical and spherical \
                     image maps; use it with one of those mappings",
                ));
            }
        }
        let path = ctx.resolve(&p.file);
        let header = probe(&path)?;
        let plan = Plan {
            // Only MIP filtering reads the coarser levels.
            mip: matches!(p.filter, Filter::Mip | Filter::Tachyon(_)),
            ..plan(&path.display().to_string(), &header, decode_cap(ctx))?
        };
        let image = cache.register(&path, header, p.srgb, plan);
        Ok(ImageTexture {
            cache,
            image,
            mapping,
            wrap: p.wrap,
            filter: p.filter,
        })
    }
}

impl Drop for ImageTexture {
    fn drop(&mut self) {
        self.cache.release(&self.image);
    }
}

impl Texture for ImageTexture {
    type Params = ImageParams;

    fn create(p: ImageParams, ctx: &Context) -> Result<Self, Error> {
        let cache = cache::global();
        cache.set_budget(ctx.texture_cache_bytes);
        Self::create_in(p, ctx, cache)
    }

    /// uv mapping reads the coordinates (and their footprint); the projections the point,
    /// and MIP filtering the world footprint too.
    fn reads(&self) -> u32 {
        match (self.mapping.kind(), self.filter) {
            (Kind::Uv, _) => READS_UV,
            (_, Filter::Mip) => READS_POINT | READS_FOOTPRINT,
            (_, Filter::Tachyon(_)) => READS_POINT | READS_DISTANCE,
            _ => READS_POINT,
        }
    }

    /// Magenta where the image cannot be decoded (the host calls `try_eval`, which fails).
    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        self.try_eval(q).unwrap_or(MAGENTA)
    }

    fn try_eval(&self, q: &TexQuery) -> Result<[f32; 4], Error> {
        let (wrap, img) = (self.wrap, &*self.image);
        let got = match self.filter {
            Filter::Nearest => {
                let (s, t) = self.mapping.point(q);
                (self.cache).with_level(img, 0, |a| nearest(a, s, t, wrap))
            }
            Filter::Bilinear => {
                let (s, t) = self.mapping.point(q);
                (self.cache).with_level(img, 0, |a| bilinear(a, s, t, wrap))
            }
            Filter::Mip => {
                let l = self.mapping.lookup(q);
                // The footprint in level-0 texels: the wider of the two directions.
                let texels = (l.ds * img.width() as f64).max(l.dt * img.height() as f64);
                let n = img.levels();
                let (lo, hi, f) = level_pair(mip_level(texels, n), n);
                self.cache
                    .with_levels(img, lo, hi, |a, b| trilinear(a, b, f, l.s, l.t, wrap))
            }
            Filter::Tachyon(k) => {
                let (s, t) = self.mapping.point(q);
                let radial = match self.mapping.kind() {
                    Kind::Cylindrical | Kind::Spherical => 1e-9 + 8.0 * self.mapping.radius(q),
                    _ => 1.0,
                };
                let d = k * f64::from(q.distance) / radial;
                let n = tachyon_levels(img.width(), img.height()).min(img.levels());
                let (lo, hi, f) = tachyon_pair(d, n);
                let (u, v) = (fract(s), fract(1.0 - t));
                self.cache.with_levels(img, lo, hi, |a, b| {
                    let ca = tachyon_bilinear(a, u, v);
                    let cb = if f > 0.0 {
                        tachyon_bilinear(b, u, v)
                    } else {
                        ca
                    };
                    std::array::from_fn(|c| ca[c] + f * (cb[c] - ca[c]))
                })
            }
        };
        got.map_err(Error::new)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cache::Log;
    use crate::decode::srgb_to_linear;
    use crate::testutil::*;
    use std::sync::Mutex;

    fn quiet() -> Log {
        Box::new(|_, _| {})
    }

    fn grey(v: f32) -> [f32; 4] {
        [v, v, v, 1.0]
    }

    /// A 4×2 PNG: row 0 (top) greys 0, 40, 80, 120; row 1 greys 160, 200, 240, 255; alpha 255.
    const TOP: [u8; 4] = [0, 40, 80, 120];
    const BOTTOM: [u8; 4] = [160, 200, 240, 255];

    fn fixture(dir: &TempDir) {
        write_png(&dir.path("ramp.png"), 4, 2, |x, y| {
            let v = if y == 0 { TOP } else { BOTTOM }[x as usize];
            [v, v, v, 255]
        });
    }

    fn lin(v: u8) -> f32 {
        srgb_to_linear(v as f32 / 255.0)
    }

    fn tex(dir: &TempDir, params: &str) -> ImageTexture {
        make_in(params, &ctx_in(dir.dir())).unwrap()
    }

    /// uv of texel (x, y)'s centre on a 4×2 image.
    fn centre(x: u32, y: u32) -> [f32; 2] {
        [(x as f32 + 0.5) / 4.0, 1.0 - (y as f32 + 0.5) / 2.0]
    }

    #[test]
    fn png_nearest_and_bilinear() {
        let dir = TempDir::new("img-png");
        fixture(&dir);
        let near = tex(&dir, r#"(file: "ramp.png", filter: nearest)"#);
        let bil = tex(&dir, r#"(file: "ramp.png", filter: bilinear, wrap: clamp)"#);
        for y in 0..2 {
            for x in 0..4 {
                let v = if y == 0 { TOP } else { BOTTOM }[x as usize];
                assert_eq!(at_uv(&near, centre(x, y), 0.0), grey(lin(v)), "({x}, {y})");
                assert!(close(at_uv(&bil, centre(x, y), 0.0), grey(lin(v)), 1e-6));
            }
        }
        // Half-way between the centres of (1, 0) and (2, 0), and of all four around (2, 1).
        let c = at_uv(&bil, [0.5, 0.75], 0.0);
        assert!(close(c, grey((lin(40) + lin(80)) / 2.0), 1e-6), "{c:?}");
        assert_eq!(at_uv(&near, [0.5, 0.75], 0.0), grey(lin(80)));
        let c = at_uv(&bil, [0.5, 0.5], 0.0);
        let want = (lin(40) + lin(80) + lin(200) + lin(240)) / 4.0;
        assert!(close(c, grey(want), 1e-6), "{c:?}");
        // srgb: false reads the bytes as linear.
        let raw = tex(&dir, r#"(file: "ramp.png", filter: nearest, srgb: false)"#);
        assert_eq!(at_uv(&raw, centre(1, 0), 0.0), grey(40.0 / 255.0));
    }

    #[test]
    fn declares_what_its_mapping_reads() {
        use luxon_plugin::abi::{READS_FOOTPRINT, READS_POINT, READS_UV};
        let dir = TempDir::new("img-reads");
        fixture(&dir);
        let reads = |p: &str| tex(&dir, &format!(r#"(file: "ramp.png", {p})"#)).reads();
        // A projection reads the point (and the world footprint under MIP filtering), never
        // uv: the host then skips a sphere's uv. uv mapping reads uv and its footprint.
        assert_eq!(reads("mapping: spherical, filter: bilinear"), READS_POINT);
        assert_eq!(reads("mapping: planar, filter: nearest"), READS_POINT);
        assert_eq!(reads("mapping: cylindrical"), READS_POINT | READS_FOOTPRINT);
        assert_eq!(reads("filter: bilinear"), READS_UV);
        assert_eq!(reads(""), READS_UV);
    }

    #[test]
    fn wrap_modes_through_the_texture() {
        let dir = TempDir::new("img-wrap");
        fixture(&dir);
        let mk = |w: &str| {
            tex(
                &dir,
                &format!(r#"(file: "ramp.png", filter: nearest, wrap: {w})"#),
            )
        };
        // u = 1.3 is column 5.2; v = 0.75 is the top row.
        let uv = [1.3, 0.75];
        assert_eq!(at_uv(&mk("repeat"), uv, 0.0), grey(lin(TOP[1])));
        assert_eq!(at_uv(&mk("clamp"), uv, 0.0), grey(lin(TOP[3])));
        assert_eq!(at_uv(&mk("mirror"), uv, 0.0), grey(lin(TOP[2])));
        // Capitalised names are accepted too.
        assert_eq!(at_uv(&mk("Mirror"), [-0.2, 0.75], 0.0), grey(lin(TOP[0])));
        // v beyond the top wraps to the bottom row under repeat.
        assert_eq!(at_uv(&mk("repeat"), [0.1, 1.25], 0.0), grey(lin(BOTTOM[0])));
        assert_eq!(at_uv(&mk("clamp"), [0.1, 1.25], 0.0), grey(lin(TOP[0])));
    }

    #[test]
    fn mappings_reach_known_texels() {
        let dir = TempDir::new("img-map");
        fixture(&dir);
        // Planar on the floor: u = x, v = -z, one image per 2 world units.
        let planar = tex(
            &dir,
            r#"(file: "ramp.png", filter: nearest, mapping: planar, scale: 2)"#,
        );
        // x = 1.1 -> s = 0.55 -> column 2; z = -0.5 -> t = 0.25 -> bottom row.
        assert_eq!(at(&planar, [1.1, 3.0, -0.5]), grey(lin(BOTTOM[2])));
        assert_eq!(at(&planar, [0.1, 0.0, -1.9]), grey(lin(TOP[0])));
        // Tiled: x = 2.1 is the next copy's column 0.
        assert_eq!(at(&planar, [2.1, 0.0, -1.9]), grey(lin(TOP[0])));
        // Cylindrical around y: longitude 0.25 at -z -> column 1; height 0.75 -> top row.
        let cyl = tex(
            &dir,
            r#"(file: "ramp.png", filter: nearest, mapping: cylindrical)"#,
        );
        assert_eq!(at(&cyl, [0.0, 0.75, -3.0]), grey(lin(TOP[1])));
        assert_eq!(at(&cyl, [-1.0, 0.25, 0.0]), grey(lin(BOTTOM[2])));
        // Spherical with a centre: the point due +x of the centre, slightly north -> column 0
        // of the top row; at -z, slightly south -> column 1 of the bottom row.
        let sph = tex(
            &dir,
            r#"(file: "ramp.png", filter: nearest, mapping: spherical, center: (5, 0, 0))"#,
        );
        assert_eq!(at(&sph, [6.0, 0.1, 0.0]), grey(lin(TOP[0])));
        assert_eq!(at(&sph, [5.0, -0.1, -1.0]), grey(lin(BOTTOM[1])));
        // A tilted axis: planar with normal +z (a wall): u = x, v = y.
        let wall = tex(
            &dir,
            r#"(file: "ramp.png", filter: nearest, mapping: planar, axis: (0, 0, 1))"#,
        );
        assert_eq!(at(&wall, [0.6, 0.9, 7.0]), grey(lin(TOP[2])));
        assert_eq!(at(&wall, [0.6, 0.1, 7.0]), grey(lin(BOTTOM[2])));
    }

    #[test]
    fn mip_level_from_the_footprint() {
        let dir = TempDir::new("img-mip");
        // 64×64, texels alternate black and white: level 0 is 0 or 1, every coarser level 0.5.
        write_png(&dir.path("fine.png"), 64, 64, |x, y| {
            let v = if (x + y) % 2 == 0 { 255 } else { 0 };
            [v, v, v, 255]
        });
        let t = tex(&dir, r#"(file: "fine.png")"#);
        let c = |x: u32, y: u32| [(x as f32 + 0.5) / 64.0, 1.0 - (y as f32 + 0.5) / 64.0];
        // Footprint 0: level 0, bilinear at a texel centre = the texel.
        assert_eq!(at_uv(&t, c(0, 0), 0.0), grey(1.0));
        assert_eq!(at_uv(&t, c(1, 0), 0.0), grey(0.0));
        // One texel wide: still level 0.
        assert_eq!(at_uv(&t, c(1, 0), 1.0 / 64.0), grey(0.0));
        // 4 texels: level 2 (mean grey).
        assert!(close(at_uv(&t, c(1, 0), 4.0 / 64.0), grey(0.5), 1e-6));
        // √2 texels: half-way between level 0 (0) and level 1 (0.5).
        let v = at_uv(&t, c(1, 0), std::f32::consts::SQRT_2 / 64.0);
        assert!(close(v, grey(0.25), 1e-4), "{v:?}");
        // Planar mapping: the world footprint goes through the mapping's scale. One image per
        // 2 world units: 64 texels per 2 units, so a footprint of 1/32 unit is one texel and
        // 1/8 unit is 4 texels.
        let p = tex(&dir, r#"(file: "fine.png", mapping: planar, scale: 2)"#);
        // Column 1, row 63 (white): u = 3/64 -> s = 1.5/64, v = 1/64 -> t = 0.5/64.
        let q = |foot: f32| TexQuery {
            p: [3.0 / 64.0, 0.0, -1.0 / 64.0],
            footprint: foot,
            ..Default::default()
        };
        assert_eq!(p.eval(&q(0.0)), grey(1.0));
        assert_eq!(p.eval(&q(1.0 / 32.0)), grey(1.0));
        assert!(close(p.eval(&q(1.0 / 8.0)), grey(0.5), 1e-6));
    }

    #[test]
    fn exr_is_linear_and_keeps_alpha() {
        let dir = TempDir::new("img-exr");
        write_exr(&dir.path("hdr.exr"), 3, 2, |x, y| {
            [x as f32 * 2.5, y as f32 + 0.25, 7.0, 0.5]
        });
        let t = tex(&dir, r#"(file: "hdr.exr", filter: nearest)"#);
        let c = |x: u32, y: u32| [(x as f32 + 0.5) / 3.0, 1.0 - (y as f32 + 0.5) / 2.0];
        assert_eq!(at_uv(&t, c(2, 1), 0.0), [5.0, 1.25, 7.0, 0.5]);
        assert_eq!(at_uv(&t, c(0, 0), 0.0), [0.0, 0.25, 7.0, 0.5]);
        // srgb does not touch float data.
        let t = tex(&dir, r#"(file: "hdr.exr", filter: nearest, srgb: true)"#);
        assert_eq!(at_uv(&t, c(1, 0), 0.0), [2.5, 0.25, 7.0, 0.5]);
        // MIP levels of a 3×2 image: level 1 is 1×1, the mean.
        let t = tex(&dir, r#"(file: "hdr.exr", wrap: clamp)"#);
        let m = at_uv(&t, [0.5, 0.5], 2.0);
        assert!(close(m, [2.5, 0.75, 7.0, 0.5], 1e-5), "{m:?}");
    }

    #[test]
    fn other_formats_decode() {
        let dir = TempDir::new("img-formats");
        let img = image::RgbImage::from_fn(2, 2, |x, _| {
            image::Rgb([if x == 0 { 0 } else { 255 }, 128, 0])
        });
        for ext in ["ppm", "tga"] {
            let p = dir.path(&format!("t.{ext}"));
            img.save(&p).unwrap();
            let t = tex(&dir, &format!(r#"(file: "t.{ext}", filter: nearest)"#));
            assert_eq!(
                at_uv(&t, [0.75, 0.75], 0.0),
                [1.0, lin(128), 0.0, 1.0],
                "{ext}"
            );
            assert_eq!(
                at_uv(&t, [0.25, 0.25], 0.0),
                [0.0, lin(128), 0.0, 1.0],
                "{ext}"
            );
        }
        // JPEG is lossy: one flat colour, loose tolerance.
        let flat = image::RgbImage::from_pixel(8, 8, image::Rgb([200, 128, 30]));
        flat.save(dir.path("t.jpg")).unwrap();
        let t = tex(&dir, r#"(file: "t.jpg", filter: nearest)"#);
        let c = at_uv(&t, [0.5, 0.5], 0.0);
        assert!(close(c, [lin(200), lin(128), lin(30), 1.0], 0.02), "{c:?}");
    }

    #[test]
    fn create_time_errors() {
        let dir = TempDir::new("img-errors");
        fixture(&dir);
        let err = |params: &str| {
            make_in::<ImageTexture>(params, &ctx_in(dir.dir()))
                .err()
                .unwrap()
                .message
        };
        let e = err(r#"(file: "missing.png")"#);
        let resolved = dir.path("missing.png");
        assert!(
            e.contains(&format!("`{}` not found", resolved.display())),
            "{e}"
        );
        std::fs::write(dir.path("notes.png"), "not an image at all").unwrap();
        let e = err(r#"(file: "notes.png")"#);
        assert!(
            e.contains("cannot read image") || e.contains("not in a recognised format"),
            "{e}"
        );
        std::fs::write(dir.path("notes.txt"), "plain text").unwrap();
        let e = err(r#"(file: "notes.txt")"#);
        assert!(e.contains("not in a recognised format"), "{e}");
        // A GIF header: recognised, but not a supported format.
        std::fs::write(dir.path("anim.gif"), b"GIF89a\x01\x00\x01\x00\x00\x00\x00").unwrap();
        let e = err(r#"(file: "anim.gif")"#);
        assert!(e.contains("not supported"), "{e}");
        let e = err(r#"(file: "ramp.png", wrap: tile)"#);
        assert!(e.contains("tile"), "{e}");
        let e = err(r#"(file: "ramp.png", filter: cubic)"#);
        assert!(e.contains("cubic"), "{e}");
        let e = err(r#"(file: "ramp.png", scale: (1, 0))"#);
        assert!(e.contains("`scale` must not be 0"), "{e}");
        let e = err(r#"(file: "ramp.png", center: (1, 0, 0))"#);
        assert!(e.contains("`center` has no effect"), "{e}");
        let e = err(r#"(file: "ramp.png", mapping: planar, axis: (0, 0, 0))"#);
        assert!(e.contains("`axis`"), "{e}");
        let e = err(r#"(fiel: "ramp.png")"#);
        assert!(e.contains("did you mean `file`"), "{e}");
        let e = err(r#"(file: "")"#);
        assert!(e.contains("`file`"), "{e}");
    }

    #[test]
    fn decode_failure_on_first_use_fails_the_lookup_with_its_reason() {
        let dir = TempDir::new("img-corrupt");
        fixture(&dir);
        let seen = Arc::new(Mutex::new(Vec::<String>::new()));
        let s = seen.clone();
        let cache = Arc::new(Cache::new(
            0,
            Box::new(move |_, m| s.lock().unwrap().push(m.into())),
        ));
        let p: ImageParams = luxon_plugin::parse_params(r#"(file: "ramp.png")"#).unwrap();
        let t = ImageTexture::create_in(p, &ctx_in(dir.dir()), cache).unwrap();
        // Corrupt the data after create (header intact).
        let bytes = std::fs::read(dir.path("ramp.png")).unwrap();
        let mut bad = bytes[..33].to_vec();
        bad.extend_from_slice(&[
            0, 0, 0, 10, b'I', b'D', b'A', b'T', 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 0, 0, 0, 0,
        ]);
        std::fs::write(dir.path("ramp.png"), bad).unwrap();
        let q = |u: f32| TexQuery {
            uv: [u, 0.5],
            ..Default::default()
        };
        let e = t.try_eval(&q(0.5)).unwrap_err().message;
        let path = dir.path("ramp.png");
        assert!(
            e.starts_with(&format!("cannot decode image `{}`: ", path.display())),
            "{e}"
        );
        assert_eq!(t.try_eval(&q(0.1)).unwrap_err().message, e);
        // `eval` gives a stand-in; nothing is logged (the message goes to the host).
        assert_eq!(at_uv(&t, [0.5, 0.5], 0.0), MAGENTA);
        assert!(
            seen.lock().unwrap().is_empty(),
            "{:?}",
            seen.lock().unwrap()
        );
    }

    #[test]
    fn an_image_over_the_decode_cap_is_used_smaller_with_one_warning() {
        let dir = TempDir::new("img-cap");
        // 64×64 columns of greys; its levels from 16×16 on need 5,456 bytes.
        write_png(&dir.path("wide.png"), 64, 64, |x, _| {
            let v = (x * 4) as u8;
            [v, v, v, 255]
        });
        let seen = Arc::new(Mutex::new(Vec::<(u32, String)>::new()));
        let s = seen.clone();
        let cache = Arc::new(Cache::new(
            0,
            Box::new(move |l, m| s.lock().unwrap().push((l, m.into()))),
        ));
        let mut ctx = ctx_in(dir.dir());
        ctx.texture_cache_bytes = 5_456 + 128 * 64;
        assert_eq!(decode_cap(&ctx), 5_456 + 128 * 64);
        let mk = |params: &str| {
            let p: ImageParams = luxon_plugin::parse_params(params).unwrap();
            ImageTexture::create_in(p, &ctx, cache.clone()).unwrap()
        };
        let near = mk(r#"(file: "wide.png", filter: nearest)"#);
        let _again = mk(r#"(file: "wide.png", filter: bilinear)"#);
        assert_eq!((near.image.width(), near.image.height()), (16, 16));
        // No MIP levels: nearest and bilinear filtering read only the first.
        assert_eq!(near.image.levels(), 1);
        let seen = seen.lock().unwrap().clone();
        assert_eq!(seen.len(), 1, "one warning per image: {seen:?}");
        assert_eq!(seen[0].0, 1);
        assert!(
            seen[0]
                .1
                .contains("wide.png` (64x64) is decoded at 16x16 to stay within")
                && seen[0].1.contains("texture memory cap of 13.3 KiB"),
            "{}",
            seen[0].1
        );
        // Texel 5 of 16 averages columns 20..24 of the full image.
        let want = (20..24).map(|x| lin(x * 4)).sum::<f32>() / 4.0;
        let got = at_uv(&near, [5.5 / 16.0, 0.5], 0.0);
        assert!(close(got, grey(want), 1e-6), "{got:?} vs {want}");
        // Under the default cap (1 GiB) the same file is used whole, without a warning.
        let full: ImageTexture = make_in(r#"(file: "wide.png")"#, &ctx_in(dir.dir())).unwrap();
        assert_eq!(full.image.width(), 64);
        assert_eq!(decode_cap(&ctx_in(dir.dir())), 1 << 30);
    }

    /// The host's memory budget bounds the cap too: what is left of it, when less than the
    /// texture cache.
    #[test]
    fn the_decode_cap_keeps_to_the_memory_budget() {
        let dir = TempDir::new("img-budget");
        let mut ctx = ctx_in(dir.dir());
        ctx.memory_budget = 1 << 20;
        assert_eq!(decode_cap(&ctx), 1 << 20);
        ctx.texture_cache_bytes = 4096;
        assert_eq!(decode_cap(&ctx), 4096);
        ctx.memory_budget = 0;
        ctx.texture_cache_bytes = 0;
        assert_eq!(decode_cap(&ctx), 1 << 30);
        // An image over the budget's cap is used smaller, as over the cache's.
        write_png(&dir.path("wide.png"), 64, 64, |x, _| {
            let v = (x * 4) as u8;
            [v, v, v, 255]
        });
        let cache = Arc::new(Cache::new(0, quiet()));
        ctx.memory_budget = 5_456 + 128 * 64;
        let p: ImageParams = luxon_plugin::parse_params(r#"(file: "wide.png")"#).unwrap();
        let t = ImageTexture::create_in(p, &ctx, cache).unwrap();
        assert_eq!((t.image.width(), t.image.height()), (16, 16));
    }

    #[test]
    fn a_whole_decode_over_the_cap_is_refused_at_create() {
        let dir = TempDir::new("img-refuse");
        image::RgbImage::from_pixel(300, 200, image::Rgb([9, 99, 199]))
            .save(dir.path("photo.jpg"))
            .unwrap();
        let mut ctx = ctx_in(dir.dir());
        ctx.texture_cache_bytes = 100_000;
        let e = make_in::<ImageTexture>(r#"(file: "photo.jpg")"#, &ctx)
            .err()
            .unwrap()
            .message;
        assert!(
            e.contains(
                "photo.jpg` (300x200 JPEG) needs 175.8 KiB to decode, more than the \
                        texture memory cap of 97.7 KiB"
            ),
            "{e}"
        );
    }

    #[test]
    fn plain_filters_read_the_same_texels_without_mip_levels() {
        let dir = TempDir::new("img-no-mip");
        write_png(&dir.path("n.png"), 13, 7, |x, y| {
            let v = (x * 19 + y * 37) as u8;
            [v, v / 2, 255 - v, 255]
        });
        let mk = |cache: &Arc<Cache>, params: &str| {
            let p: ImageParams = luxon_plugin::parse_params(params).unwrap();
            ImageTexture::create_in(p, &ctx_in(dir.dir()), cache.clone()).unwrap()
        };
        // Alone, a bilinear texture's entry has no MIP levels; after a MIP texture of the same
        // file, it shares that one's pyramid.
        let alone = Arc::new(Cache::new(0, quiet()));
        let shared = Arc::new(Cache::new(0, quiet()));
        for filter in ["nearest", "bilinear"] {
            let params = format!(r#"(file: "n.png", filter: {filter})"#);
            let plain = mk(&alone, &params);
            let _mip = mk(&shared, r#"(file: "n.png")"#);
            let beside = mk(&shared, &params);
            assert_eq!((plain.image.levels(), beside.image.levels()), (1, 4));
            for k in 0..50 {
                let uv = [k as f32 * 0.071 - 0.3, k as f32 * 0.043 + 0.1];
                let (a, b) = (at_uv(&plain, uv, 0.0), at_uv(&beside, uv, 0.0));
                assert_eq!(
                    a.map(f32::to_bits),
                    b.map(f32::to_bits),
                    "{filter} at {uv:?}"
                );
            }
        }
    }

    #[test]
    fn instances_share_one_cached_image() {
        let dir = TempDir::new("img-share");
        fixture(&dir);
        let cache = Arc::new(Cache::new(0, quiet()));
        let mk = |params: &str| {
            let p: ImageParams = luxon_plugin::parse_params(params).unwrap();
            ImageTexture::create_in(p, &ctx_in(dir.dir()), cache.clone()).unwrap()
        };
        let a = mk(r#"(file: "ramp.png", filter: nearest)"#);
        let b = mk(r#"(file: "ramp.png", filter: bilinear, mapping: planar)"#);
        assert!(Arc::ptr_eq(&a.image, &b.image));
        at_uv(&a, [0.5, 0.5], 0.0);
        at(&b, [0.5, 0.0, -0.5]);
        assert_eq!(cache.stats().decodes, 1);
        drop(a);
        assert!(cache.stats().resident > 0);
        drop(b);
        assert_eq!(
            cache.stats().resident,
            0,
            "the last instance frees the texels"
        );
    }

    #[test]
    fn tachyon_levels_and_blends_are_tachyons() {
        assert_eq!(tachyon_levels(256, 256), 9);
        assert_eq!(tachyon_levels(300, 200), 9);
        assert_eq!(tachyon_levels(4, 2), 3);
        assert_eq!(tachyon_levels(1, 1), 1);
        assert_eq!(tachyon_pair(0.0, 9), (0, 1, 0.0));
        assert_eq!(tachyon_pair(-3.0, 9), (0, 1, 0.0));
        let (lo, hi, f) = tachyon_pair(0.8, 9);
        assert_eq!((lo, hi), (6, 7));
        assert!((f - 0.40).abs() < 1e-3, "{f}");
        // From level L − 2 on: the coarsest level alone, however much it is past it.
        assert_eq!(tachyon_pair(0.9, 9), (8, 8, 0.0));
        assert_eq!(tachyon_pair(7.0, 9), (8, 8, 0.0));
        assert_eq!(tachyon_pair(f64::NAN, 9), (8, 8, 0.0));
        assert_eq!(tachyon_pair(0.5, 1), (0, 0, 0.0));
        assert_eq!(fract(-0.25), 0.75);
        assert_eq!(fract(3.0), 0.0);
        assert_eq!(fract(-1e-20), 0.0);
    }

    #[test]
    fn tachyon_filter_blurs_by_distance_and_places_texels_as_tachyon() {
        let dir = TempDir::new("img-tachyon");
        fixture(&dir);
        // Planar about +y: s = x, t = -z; k = 0.1 per unit of distance.
        let t = tex(
            &dir,
            r#"(file: "ramp.png", srgb: false, mapping: planar, filter: tachyon(0.1))"#,
        );
        assert_eq!(t.reads(), READS_POINT | READS_DISTANCE);
        let at_d = |p: [f64; 3], distance: f32| {
            t.eval(&TexQuery {
                p,
                distance,
                ..Default::default()
            })
        };
        let g = |v: f32| grey(v / 255.0);
        // Level 0: u = 0 and v = 0 are the first texel's centre, u = 0.5 half-way between the
        // second and third (Tachyon's x = (w − 1) u), v = 0.5 half-way between the rows.
        assert_eq!(at_d([0.0, 0.0, 0.0], 0.0), g(0.0));
        assert!(close(at_d([0.5, 0.0, 0.0], 0.0), g(60.0), 1e-6));
        assert!(close(at_d([0.0, 0.0, -0.5], 0.0), g(80.0), 1e-6));
        assert!(
            close(at_d([2.5, 0.0, -7.0], 0.0), g(60.0), 1e-6),
            "wraps by u's fraction"
        );
        // d = 0.25 on 3 levels: level 0.500025, half-way to the 2 × 1 level (100 and 173.75).
        let c = at_d([0.0, 0.0, 0.0], 2.5);
        assert!(close(c, g(0.500025 * 100.0), 1e-4), "{c:?}");
        // Far away: the 1 × 1 level, the mean of all eight texels.
        let mean = (0.0 + 40.0 + 80.0 + 120.0 + 160.0 + 200.0 + 240.0 + 255.0) / 8.0;
        assert!(close(at_d([0.3, 0.0, -0.2], 50.0), g(mean), 1e-4));
        // A bad blur, and uv mapping (Tachyon's maps are projections), are refused.
        for bad in [
            r#"(file: "ramp.png", mapping: planar, filter: tachyon(-1.0))"#,
            r#"(file: "ramp.png", filter: tachyon(0.1))"#,
        ] {
            let e = make_in::<ImageTexture>(bad, &ctx_in(dir.dir()))
                .err()
                .unwrap();
            assert!(e.to_string().contains("tachyon"), "{e}");
        }
    }
}
