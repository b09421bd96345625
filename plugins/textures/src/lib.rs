//! # luxon-textures: texture plugins for Luxon
//!
//! Procedural solid textures, texture trees and image textures. Colours are linear RGB (values
//! above 1 are allowed); alpha is 1 except for image textures with an alpha channel. Every
//! texture is deterministic and safe to evaluate from many threads at once.
//!
//! | texture    | what |
//! |------------|------|
//! | `constant` | one colour everywhere |
//! | `checker`  | a 3D checkerboard of cubes; each cell colour may be another texture |
//! | `blend`    | two textures or colours mixed by a third |
//! | `gradient` | a clamped linear blend between two colours along an axis |
//! | `marble`   | Perlin's marble: stripes bent by turbulence |
//! | `wood`     | growth rings around an axis, wobbled by noise |
//! | `noise`    | Perlin's improved gradient noise, fractal ("grit") |
//! | `image`    | an image file (PNG, JPEG, TGA, PPM, EXR), mapped, tiled, MIP-mapped, cached |
//! | `tachyon_marble` | Tachyon's TEXFUNC 3 (marble), as Tachyon computes it |
//! | `tachyon_wood` | Tachyon's TEXFUNC 4 (wood) |
//! | `tachyon_cylinder_checker` | Tachyon's TEXFUNC 6 (cylindrical checker) |
//! | `tachyon_volume_image` | Tachyon's TEXFUNC 10 (an IMAGEDEF block of texels) |
//!
//! ## Placement of solid textures
//!
//! `constant`, `checker`, `gradient`, `marble`, `wood` and `noise` share three parameters that
//! place the pattern in the world (`transform.rs`):
//!
//! | name        | type                   | default     | meaning |
//! |-------------|------------------------|-------------|---------|
//! | `scale`     | f64 or `(x, y, z)`, > 0 | `1.0`      | world units per pattern unit (one number: the same on every axis) |
//! | `rotate`    | `(x, y, z)` degrees    | `(0, 0, 0)` | turns the pattern about x, then y, then z |
//! | `translate` | `(x, y, z)`            | `(0, 0, 0)` | where the pattern's origin lands |
//!
//! The lookup point is `S⁻¹ · Rᵀ · (p - translate)` with `R = Rz · Ry · Rx`. They are accepted
//! by `constant` too, where they change nothing.
//!
//! ## Texture trees
//!
//! The inputs of `checker` (`even`, `odd`) and `blend` (`a`, `b`, `mix`) are each a grey level
//! (`0.5`), a colour (`(r, g, b)`) or another texture of this plugin written inline by its
//! capitalised name with its own parameters: `Constant(...)`, `Checker(...)`, `Blend(...)`,
//! `Gradient(...)`, `Marble(...)`, `Wood(...)`, `Noise(...)`, `Image(...)` (`Marble()` takes
//! every default). Trees nest to any depth. A nested texture is evaluated at the same shading
//! point as its parent, placed by its own parameters only. Errors name the path to the input:
//! ``` `odd`: `even`: parameter `turbulence` must not be negative ```.
//!
//! ## Parameters
//!
//! `constant`
//!
//! | name    | type        | default  | meaning |
//! |---------|-------------|----------|---------|
//! | `color` | `(r, g, b)` | required | the colour |
//!
//! `checker` (and placement)
//!
//! | name     | type  | default     | meaning |
//! |----------|-------|-------------|---------|
//! | `even`   | input | `(1, 1, 1)` | cells whose indices sum to an even number (e.g. the cell at the origin) |
//! | `odd`    | input | `(0, 0, 0)` | the other cells |
//! | `offset` | `(x, y, z)` | `(0, 0, 0)` | older name of `translate` (a cell corner); give one of them |
//!
//! `scale` is the edge length of a cell. The cell of a point has indices `floor(l)` per axis of
//! its pattern-space point `l`, so cells are half-open, `[k, k + 1)`: a point exactly on a
//! boundary belongs to the cell on its positive side, for negative coordinates as for positive
//! ones. Points within 1e-4 cell units of a boundary are snapped onto it first, so that rounding
//! noise in hit points on a surface lying on a boundary (the floor `y = 0` with the default
//! grid) cannot make the pattern speckle between two cells.
//!
//! `blend`
//!
//! | name  | type  | default     | meaning |
//! |-------|-------|-------------|---------|
//! | `a`   | input | `(0, 0, 0)` | where `mix` is 0 |
//! | `b`   | input | `(1, 1, 1)` | where `mix` is 1 |
//! | `mix` | input | `0.5`       | weight of `b`, per channel, clamped to [0, 1] (alpha: the mean) |
//!
//! `gradient` (and placement)
//!
//! | name    | type        | default     | meaning |
//! |---------|-------------|-------------|---------|
//! | `from`  | `(r, g, b)` | `(0, 0, 0)` | colour at `start` and before it |
//! | `to`    | `(r, g, b)` | `(1, 1, 1)` | colour at `end` and after it |
//! | `axis`  | `(x, y, z)` | `(0, 1, 0)` | direction of the blend in pattern space, normalised (must not be zero) |
//! | `start` | f64         | `0.0`       | where the blend starts: distance along `axis` from the pattern origin |
//! | `end`   | f64         | `1.0`       | where it ends (must differ from `start`; may be smaller) |
//!
//! The colour at pattern point `l` is `from + (to - from) * clamp((dot(l, axis) - start) /
//! (end - start), 0, 1)`.
//!
//! `marble` (and placement)
//!
//! | name         | type        | default              | meaning |
//! |--------------|-------------|----------------------|---------|
//! | `base`       | `(r, g, b)` | `(0.8, 0.78, 0.74)`  | the stone |
//! | `vein`       | `(r, g, b)` | `(0.1, 0.1, 0.12)`   | the veins |
//! | `turbulence` | f64 ≥ 0     | `1.0`                | how far veins wander, in stripe widths (0: straight) |
//! | `sharpness`  | f64 > 0     | `3.0`                | exponent of the vein profile (larger: thinner veins) |
//! | `octaves`    | 1..=16      | `5`                  | octaves of turbulence |
//! | `seed`       | u64         | `0`                  | noise seed |
//!
//! With phase `φ = l.x + turbulence · turb(l)` (Perlin's turbulence, in [0, 1]) the vein
//! weight is `((1 - cos 2πφ) / 2)^sharpness`: stone at whole `φ`, vein half-way; one stripe per
//! pattern unit across the pattern's x axis.
//!
//! `wood` (and placement)
//!
//! | name         | type        | default               | meaning |
//! |--------------|-------------|-----------------------|---------|
//! | `light`      | `(r, g, b)` | `(0.73, 0.48, 0.24)`  | early wood, at whole radii |
//! | `dark`       | `(r, g, b)` | `(0.26, 0.1, 0.025)`  | late wood, half-way between rings |
//! | `turbulence` | f64 ≥ 0     | `0.15`                | ring wobble, in ring spacings (0: circles) |
//! | `octaves`    | 1..=16      | `3`                   | octaves of noise |
//! | `seed`       | u64         | `0`                   | noise seed |
//!
//! Rings around the pattern's y axis (turn it with `rotate`), one per pattern unit of radius:
//! weight `(1 - cos 2πr) / 2` with `r = hypot(l.x, l.z) + turbulence · fbm(l)`.
//!
//! `noise` (and placement)
//!
//! | name         | type        | default     | meaning |
//! |--------------|-------------|-------------|---------|
//! | `from`       | `(r, g, b)` | `(0, 0, 0)` | where the noise is lowest |
//! | `to`         | `(r, g, b)` | `(1, 1, 1)` | where it is highest |
//! | `octaves`    | 1..=16      | `4`         | octaves summed |
//! | `gain`       | f64 > 0     | `0.5`       | amplitude ratio between octaves |
//! | `lacunarity` | f64 > 0     | `2.0`       | frequency ratio between octaves |
//! | `turbulent`  | bool        | `false`     | sum absolute values (creased, Perlin's turbulence) |
//! | `seed`       | u64         | `0`         | noise seed: a permutation table shuffled from it |
//!
//! The weight of `to` is `0.5 + 0.5 · fbm(l)` (or `turb(l)`), clamped to [0, 1]; sums are
//! divided by the total amplitude, so every octave count keeps the range. One octave of noise is
//! exactly 0 (weight 0.5) at whole pattern coordinates.
//!
//! `tachyon_marble`, `tachyon_wood`, `tachyon_cylinder_checker`, `tachyon_volume_image`
//!
//! Tachyon's procedural textures, for scenes imported from Tachyon (`.dat`): the formulas of
//! Tachyon 0.99b6, measured against `tachyon-nox` pixel by pixel (`tachyon.rs`). They take
//! Tachyon's own parameters instead of the shared placement (Tachyon ignores ROTATE). Colours
//! are Tachyon's display values, as the importer keeps every Tachyon colour.
//!
//! | texture | name     | type        | default | meaning |
//! |---------|----------|-------------|---------|---------|
//! | `tachyon_marble` | — | | | no parameters: Tachyon's marble ignores CENTER, ROTATE, SCALE and COLOR |
//! | `tachyon_wood` | `center` | `(x, y, z)` | `(0, 0, 0)` | the rings' axis runs through it along y |
//! | | `scale` | f64 or `(x, y, z)`, not 0 | `1.0` | the point is `(p - center) / scale` per axis (a negative factor mirrors) |
//! | | `light` | `(r, g, b)` | `(0.8, 1, 0.2)` | the rings |
//! | | `dark` | `(r, g, b)` | `(0, 0, 0)` | between them |
//! | `tachyon_cylinder_checker` | `center` | `(x, y, z)` | `(0, 0, 0)` | the axis runs through it along z |
//! | | `even` | `(r, g, b)` | `(0, 0.2, 1)` | cells whose sector and band sum to an even number |
//! | | `odd` | `(r, g, b)` | `(1, 0.2, 0)` | the others |
//! | `tachyon_volume_image` | `size` | `(nx, ny, nz)`, each ≥ 1 | required | texels along u, v, w |
//! | | `rgb` | `[u8, ...]` | required | 3·nx·ny·nz bytes, r, g, b per texel, u fastest, then v, then w |
//! | | `center` | `(x, y, z)` | `(0, 0, 0)` | Tachyon's CENTER |
//! | | `u`, `v`, `w` | `(x, y, z)` | the x, y, z axes | `u = u·(p − center) + offset.x` (UAXIS × SCALE.x), likewise v, w |
//! | | `offset` | `(u, v, w)` | `(0, 0, 0)` | Tachyon's ROTATE |
//!
//! - Marble: with Tachyon's value noise `n(p)` (a 28³ lattice of integers 0..12000 filled from
//!   the sequence s ← 1099087573·s mod 2³², s₀ = 1234567, interpolated from |x|, |y|, |z| in
//!   integer steps; the point in single precision, as Tachyon reads it), `d = x + 0.0006·n`,
//!   `d ← d·(trunc(d) mod 25)`, `i = clamp(0.1·|d − 10 − trunc(d)|, 0, 1)`, colour
//!   `((1 + sin 6.28i)/2, (1 + sin 16.28i)/2, (1 + cos 30.28i)/2)`: bands across x.
//! - Wood: with `q = (p − center)/scale`, `r = hypot(q.x, q.z) + 3·sin(20·atan(q.x/q.z) +
//!   q.y/150)`; `light` where `trunc(r + 0.5) mod 60 < 40` (C's remainder), else `dark`.
//! - Cylindrical checker: with `q = p − center`, `u` = the angle of `(q.x, q.y)` from +x toward
//!   +y in turns, cell `floor(18·u) + floor(10·|q.z|)`.
//! - Volume image: `u, v, w` wrapped into [0, 1) (`t − floor(t)`), texel coordinates
//!   `u·(nx − 1)` … (the first and last texels' centres at 0 and 1), trilinear between the 8
//!   texels around, bytes / 255 (no gamma, like Tachyon's colours).
//!
//! `image`
//!
//! | name      | type | default    | meaning |
//! |-----------|------|------------|---------|
//! | `file`    | path | required   | PNG, JPEG, TGA, PPM/PGM/PBM/PAM or OpenEXR, relative to the scene file |
//! | `srgb`    | bool | `true`     | 8- and 16-bit sources are sRGB-encoded (decoded to linear); `false`: already linear. EXR is always linear |
//! | `mapping` | `uv`, `planar`, `cylindrical`, `spherical` | `uv` | mesh texture coordinates, or a projection |
//! | `center`  | `(x, y, z)` | `(0, 0, 0)` | origin of the projection (not with `uv`) |
//! | `axis`    | `(x, y, z)` | `(0, 1, 0)` | plane normal (planar) or pole (cylindrical, spherical); not with `uv` |
//! | `scale`   | f64 or `(u, v)`, not 0 | `1.0` | size of one copy of the image in mapping units (negative: mirrored along that direction) |
//! | `rotate`  | f64 degrees | `0` | turns the image counter-clockwise |
//! | `offset`  | `(u, v)` | `(0, 0)` | where the image's corner `(0, 0)` lands |
//! | `wrap`    | `repeat`, `clamp`, `mirror` | `repeat` | outside [0, 1): tile, extend the edge texels, tile mirrored |
//! | `filter`  | `nearest`, `bilinear`, `mip`, `tachyon(k)` | `mip` | `mip`: trilinear between MIP levels chosen from the ray's footprint; `tachyon(k)`: Tachyon's image-map blur, levels chosen from k × the distance the ray travelled, texels placed as Tachyon places them (what the Tachyon importer writes) |
//!
//! Names of `mapping`, `wrap` and `filter` may also be capitalised (`Planar`). Image
//! coordinates `(s, t)` have `(0, 0)` at the image's bottom-left corner and `(1, 1)` at its
//! top-right. The mappings are defined in `mapping.rs`: `planar` gives `u = d · e1`,
//! `v = d · e2` for `d = p - center` in a frame `e1` (world x made perpendicular to `axis`),
//! `e2 = axis × e1` (floor, default axis: `u = x`, `v = -z`; wall with axis `(0, 0, 1)`:
//! `u = x`, `v = y`); `cylindrical` gives the longitude / 2π and the height along the axis;
//! `spherical` the longitude / 2π and the latitude mapped to [0, 1]. Then
//! `(s, t) = R(-rotate) · ((u, v) - offset) / scale`.
//!
//! **MIP level.** The footprint is measured in level-0 texels: under `uv` mapping from the
//! host's `uv_footprint`, under the projections from the world `footprint` through the
//! mapping's derivatives and `scale` (planar: `footprint / scale` image widths). The level is
//! `log2(texels)`, clamped to the pyramid (a footprint of 0 or 1 texel is level 0; 4 texels is
//! level 2), blended linearly between the two levels around it. The pyramid is built once per
//! decode with an exact area (box) filter that also handles odd sizes (`mipmap.rs`).
//!
//! **Loading and the cache.** `create` checks that the file exists and reads its header
//! (errors name the resolved path); the texels are decoded on the first lookup. Every image of
//! the library lives in one LRU cache bounded by the call context's texture cache budget
//! (`texture_cache_bytes`: the render setting `texture_cache`, by default 1 GiB or a quarter of
//! the memory budget when that is less; 0, from a host that gives none: 1 GiB), counted per MIP
//! level; lookups that hit take no lock.
//! Least recently used levels are evicted when the budget is exceeded and decoded again when
//! needed, so scenes with more texture data than the budget still render; a warning says once
//! when that happens (the cache is thrashing), with the budget and the data size. An image
//! that cannot be decoded makes its lookups fail (`try_eval`) with the decoder's reason, which
//! the host reports as the render's one error, naming the texture. See `cache.rs`.
//!
//! **Large images.** Each image is decoded within a cap: the texture cache budget, at most what
//! is left of the host's memory budget (`memory_budget`). An image whose MIP pyramid does not
//! fit is used from the first level that does, with a warning (a PNG is streamed, so only those
//! levels are ever held); a format decoded whole whose buffer does not fit is refused at
//! create. See `decode.rs`.
//!
//! ## Scene
//!
//! ```ron
//! textures: {
//!     "checks": (plugin: "checker", params: (scale: 0.5)),
//!     "sky": (plugin: "gradient", params: (from: (1, 1, 1), to: (0.2, 0.4, 0.9), start: 0, end: 10)),
//!     "stone": (plugin: "marble", params: (scale: 0.4, rotate: (0, 30, 10), seed: 7)),
//!     "table": (plugin: "wood", params: (scale: 0.05, rotate: (90, 0, 0))),
//!     "grit": (plugin: "noise", params: (from: (0.3, 0.3, 0.3), to: (0.6, 0.6, 0.6), scale: 0.02)),
//!     "tiles": (plugin: "checker", params: (
//!         scale: 1,
//!         even: Marble(scale: 0.5),
//!         odd: Blend(a: Wood(scale: 0.1), b: Image(file: "wood.png", mapping: planar), mix: 0.3),
//!     )),
//!     "earth": (plugin: "image", params: (file: "earth.jpg", mapping: spherical, center: (0, 1, 0))),
//!     "label": (plugin: "image", params: (file: "label.exr", wrap: clamp, filter: bilinear)),
//!     "veined": (plugin: "tachyon_marble", params: ()),
//!     "rings": (plugin: "tachyon_wood", params: (center: (0, 2, -6), scale: (0.001, 0.001, -0.001))),
//!     "stripes": (plugin: "tachyon_cylinder_checker", params: (center: (-2.5, -0.5, -5))),
//! },
//! materials: {
//!     "floor": (texture: "tiles", diffuse: 0.8),
//! },
//! ```

// Unsafe code only in the texture cache (`cache.rs`: its lock-free resident levels).
#![deny(unsafe_code)]

// Levels shared through atomic pointers.
#[allow(unsafe_code)]
mod cache;
// Public for the `image_texture` fuzz target (tests/fuzz): probe, plan and decode from bytes.
mod band;
pub mod decode;
mod image;
mod mapping;
mod mipmap;
mod noise;
mod params;
mod procedural;
mod reduce;
mod tachyon;
mod texels;
mod transform;
mod tree;

#[cfg(test)]
mod testutil;

pub use crate::image::ImageTexture;
pub use procedural::{Checker, Constant, Gradient, Marble, Noise, Wood};
pub use tachyon::{TachyonCylinderChecker, TachyonMarble, TachyonVolumeImage, TachyonWood};
pub use tree::Blend;

luxon_plugin::export!(
    library: "luxon-textures",
    textures: [
        Constant,
        Checker,
        Blend,
        Gradient,
        Marble,
        Wood,
        Noise,
        ImageTexture,
        TachyonMarble,
        TachyonWood,
        TachyonCylinderChecker,
        TachyonVolumeImage
    ]
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{ctx_in, make_in, write_png, TempDir};
    use luxon_plugin::abi::TexQuery;
    use luxon_plugin::Texture;

    /// Points and uvs spread over a few cells and image copies.
    fn queries() -> Vec<TexQuery> {
        (0..4000)
            .map(|i| {
                let t = i as f64;
                TexQuery {
                    p: [
                        (t * 0.618_034).fract() * 6.0 - 3.0,
                        (t * 0.414_214).fract() * 6.0 - 3.0,
                        (t * 0.732_051).fract() * 6.0 - 3.0,
                    ],
                    uv: [
                        (t * 0.1234).fract() as f32 * 3.0,
                        (t * 0.377).fract() as f32,
                    ],
                    footprint: (i % 5) as f32 * 0.01,
                    uv_footprint: (i % 7) as f32 * 0.02,
                    ..Default::default()
                }
            })
            .collect()
    }

    fn run<T: Texture>(t: &T, qs: &[TexQuery]) -> Vec<[u32; 4]> {
        qs.iter().map(|q| t.eval(q).map(f32::to_bits)).collect()
    }

    #[test]
    fn concurrent_evals_are_identical() {
        let dir = TempDir::new("lib-threads");
        write_png(&dir.path("a.png"), 37, 23, |x, y| {
            [(x * 7) as u8, (y * 11) as u8, 90, 255]
        });
        write_png(&dir.path("b.png"), 16, 16, |x, y| {
            [(x * 16) as u8, 0, (y * 16) as u8, 200]
        });
        let ctx = ctx_in(dir.dir());
        let tree: Checker = make_in(
            r#"(scale: 0.7, rotate: (10, 20, 30),
                even: Blend(a: Marble(seed: 2), b: Image(file: "a.png"), mix: Noise(seed: 5)),
                odd: Checker(even: Wood(), odd: Image(file: "b.png", mapping: spherical, wrap: mirror)))"#,
            &ctx,
        )
        .unwrap();
        let uv: ImageTexture =
            make_in(r#"(file: "a.png", scale: (0.5, 2), rotate: 15)"#, &ctx).unwrap();
        let qs = queries();
        let want_tree = run(&tree, &qs);
        let want_uv = run(&uv, &qs);
        std::thread::scope(|s| {
            let handles: Vec<_> = (0..4)
                .map(|k| {
                    let (tree, uv, qs) = (&tree, &uv, &qs);
                    s.spawn(move || {
                        // Each thread walks the queries from a different start.
                        let mut order: Vec<usize> = (0..qs.len()).collect();
                        order.rotate_left(k * 997);
                        order
                            .into_iter()
                            .map(|i| {
                                (
                                    i,
                                    tree.eval(&qs[i]).map(f32::to_bits),
                                    uv.eval(&qs[i]).map(f32::to_bits),
                                )
                            })
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            for h in handles {
                for (i, t, u) in h.join().unwrap() {
                    assert_eq!(t, want_tree[i], "tree, query {i}");
                    assert_eq!(u, want_uv[i], "uv image, query {i}");
                }
            }
        });
        // Every colour is finite.
        assert!(want_tree
            .iter()
            .flatten()
            .all(|&b| f32::from_bits(b).is_finite()));
    }

    #[test]
    fn concurrent_evals_under_a_thrashing_cache_are_identical() {
        let dir = TempDir::new("lib-thrash");
        for (k, name) in ["p.png", "q.png", "r.png"].iter().enumerate() {
            write_png(&dir.path(name), 32, 32, |x, y| {
                [(x * 8) as u8, (y * 8) as u8, 60 * k as u8, 255]
            });
        }
        let cache = std::sync::Arc::new(cache::Cache::new(20_000, Box::new(|_, _| {})));
        let ctx = ctx_in(dir.dir());
        let textures: Vec<ImageTexture> = ["p.png", "q.png", "r.png"]
            .iter()
            .map(|f| {
                let p = luxon_plugin::parse_params(&format!(r#"(file: "{f}")"#)).unwrap();
                ImageTexture::create_in(p, &ctx, cache.clone()).unwrap()
            })
            .collect();
        let qs = queries();
        let want: Vec<Vec<[u32; 4]>> = textures.iter().map(|t| run(t, &qs)).collect();
        std::thread::scope(|s| {
            for k in 0..4 {
                let (textures, qs, want) = (&textures, &qs, &want);
                s.spawn(move || {
                    for i in 0..qs.len() {
                        let j = (i + k) % 3;
                        assert_eq!(textures[j].eval(&qs[i]).map(f32::to_bits), want[j][i]);
                    }
                });
            }
        });
        let stats = cache.stats();
        assert!(stats.evictions > 0 && stats.decodes > 3, "{stats:?}");
    }
}
