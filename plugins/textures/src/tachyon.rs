//! Tachyon's procedural textures (TEXFUNC 3 marble, 4 wood, 6 cylindrical checker) and its
//! volume image (TEXFUNC 10), computed
//! as Tachyon 0.99b6 computes them, so that scenes imported from Tachyon look as Tachyon draws
//! them. The formulas were measured against `tachyon-nox` pixel by pixel
//! (`/work/notes/tachyon-mapping.md` §5.9); the tests hold values read from its images.
//!
//! They take Tachyon's own parameters (`center`, `scale`), not the shared placement: Tachyon
//! ignores ROTATE, and marble ignores every parameter. Points are in the scene's world; the
//! Tachyon importer mirrors Tachyon's left-handed world by negating z, and passes `center` and
//! `scale` so that each pattern sees Tachyon's coordinates (marble and the cylindrical
//! checker are symmetric in z; wood's `scale.z` is negated).

use crate::band::{cos_band, sin_band};
use crate::params::{color, Factors};
use luxon_plugin::abi::{TexQuery, READS_POINT};
use luxon_plugin::{finite, invalid, Context, Describe, Error, Texture};
use serde::Deserialize;
use std::f64::consts::{FRAC_PI_2, TAU};
use std::sync::OnceLock;

/// Cells per axis of Tachyon's noise lattice.
const N: usize = 28;

/// Tachyon's noise lattice, flattened x-major (`(x·28 + y)·28 + z`), followed by zeros: its
/// lookups read one cell past the last index of an axis (index 28), which in the flat table
/// is the next row, or past the end of the table (where Tachyon finds zeros: measured).
fn lattice() -> &'static [i32] {
    static TABLE: OnceLock<Vec<i32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        let at = |x: usize, y: usize, z: usize| (x * N + y) * N + z;
        // The last flat index a lookup reaches is at(28, 28, 28).
        let mut t = vec![0i32; at(N, N, N) + 1];
        // Filled in x, y, z order from the generator s ← 1099087573·s mod 2³², s₀ = 1234567.
        let mut s: u32 = 1_234_567;
        for x in 0..N {
            for y in 0..N {
                for z in 0..N {
                    s = s.wrapping_mul(1_099_087_573);
                    t[at(x, y, z)] = (f64::from(s) * 2.328_306_436_5e-10 * 12000.0) as i32;
                }
            }
        }
        // Index 27 repeats index 0 on every axis.
        let last = N - 1;
        for x in 0..N {
            for y in 0..N {
                for z in 0..N {
                    let k = |i: usize| if i == last { 0 } else { i };
                    t[at(x, y, z)] = t[at(k(x), k(y), k(z))];
                }
            }
        }
        t
    })
}

/// Tachyon's value noise at `p`: 0..12000, interpolated trilinearly in integer steps (each
/// lerp `a + trunc((b - a)·f)`, x first, then y, then z), from |x|, |y|, |z|.
fn noise(p: [f64; 3]) -> i64 {
    let t = lattice();
    let p = p.map(f64::abs);
    // `as` saturates far away (and maps NaN to 0): no panic, some lattice cell.
    let i = p.map(|v| (v as i64).rem_euclid(N as i64) as usize);
    let f = p.map(f64::fract);
    // The eight corners lie within N·N + N + 1 cells of the first (the table's end included):
    // one bounds check for the slice instead of eight.
    let first = (i[0] * N + i[1]) * N + i[2];
    let cell = &t[first..=first + N * N + N + 1];
    let g = |dx: usize, dy: usize, dz: usize| i64::from(cell[(dx * N + dy) * N + dz]);
    let lerp = |a: i64, b: i64, f: f64| a + ((b - a) as f64 * f) as i64;
    let x00 = lerp(g(0, 0, 0), g(1, 0, 0), f[0]);
    let x01 = lerp(g(0, 0, 1), g(1, 0, 1), f[0]);
    let x10 = lerp(g(0, 1, 0), g(1, 1, 0), f[0]);
    let x11 = lerp(g(0, 1, 1), g(1, 1, 1), f[0]);
    let y0 = lerp(x00, x10, f[1]);
    let y1 = lerp(x01, x11, f[1]);
    lerp(y0, y1, f[2])
}

/// C's `(int) v`: toward zero, saturating.
fn trunc(v: f64) -> i64 {
    v as i64
}

// ------------------------------------------------------------------------------------------------
// marble (TEXFUNC 3)
// ------------------------------------------------------------------------------------------------

/// Tachyon's marble: bands across x, bent by its value noise, in fixed colours.
pub struct TachyonMarble;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NoParams {}

impl Describe for TachyonMarble {
    const NAME: &'static str = "tachyon_marble";
    const DESCRIPTION: &'static str =
        "Tachyon's TEXFUNC 3 (marble), as Tachyon 0.99b6 computes it; no parameters (Tachyon ignores CENTER, ROTATE, SCALE and COLOR).";
    const PARAMS: &'static str = "";
}

impl Texture for TachyonMarble {
    type Params = NoParams;

    /// The point alone.
    fn reads(&self) -> u32 {
        READS_POINT
    }

    fn create(_p: NoParams, _ctx: &Context) -> Result<Self, Error> {
        Ok(TachyonMarble)
    }

    // Tachyon's factor 6.28 is not quite 2π; the pattern needs its value.
    #[allow(clippy::approx_constant)]
    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        // Tachyon reads the hit point in single precision (measured: it matches more pixels).
        let p = q.p.map(|v| v as f32 as f64);
        let mut d = p[0] + 0.0006 * noise(p) as f64;
        d *= (trunc(d) % 25) as f64;
        let i = (0.1 * (d - 10.0 - 20.0 * (trunc(d) as f64 * 0.05)).abs()).clamp(0.0, 1.0);
        // `(0.5 * (1.0 + (i * 6.28).sin())) as f32` and so on, bitwise, without libm's cost.
        [
            sin_band(i * 6.28),
            sin_band(i * 16.28),
            cos_band(i * 30.28),
            1.0,
        ]
    }
}

// ------------------------------------------------------------------------------------------------
// wood (TEXFUNC 4)
// ------------------------------------------------------------------------------------------------

/// Tachyon's wood: rings around the y axis through `center`, waved by the angle.
pub struct TachyonWood {
    center: [f64; 3],
    scale: [f64; 3],
    light: [f32; 4],
    dark: [f32; 4],
}

fn wood_light() -> [f64; 3] {
    [0.8, 1.0, 0.2]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WoodParams {
    #[serde(default)]
    center: [f64; 3],
    #[serde(default)]
    scale: Factors<3>,
    #[serde(default = "wood_light")]
    light: [f64; 3],
    #[serde(default)]
    dark: [f64; 3],
}

impl Describe for TachyonWood {
    const NAME: &'static str = "tachyon_wood";
    const DESCRIPTION: &'static str =
        "Tachyon's TEXFUNC 4 (wood): rings around the y axis through `center`, as Tachyon 0.99b6 computes them.";
    const PARAMS: &'static str = concat!(
        "center: (x, y, z) = (0, 0, 0)  Tachyon's CENTER: the rings' axis runs through it along y\n",
        "scale: f64 or (x, y, z) = 1.0  Tachyon's SCALE: the point is (p - center) / scale per axis (not 0; negative mirrors)\n",
        "light: (r, g, b) = (0.8, 1, 0.2)  the rings' colour (Tachyon's)\n",
        "dark: (r, g, b) = (0, 0, 0)  between the rings (Tachyon's)"
    );
}

impl Texture for TachyonWood {
    type Params = WoodParams;

    /// The point alone.
    fn reads(&self) -> u32 {
        READS_POINT
    }

    fn create(p: WoodParams, _ctx: &Context) -> Result<Self, Error> {
        Ok(TachyonWood {
            center: finite("center", p.center)?,
            scale: p.scale.nonzero("scale")?,
            light: color("light", p.light)?,
            dark: color("dark", p.dark)?,
        })
    }

    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        let [x, y, z]: [f64; 3] =
            std::array::from_fn(|k| (q.p[k] - self.center[k]) / self.scale[k]);
        let angle = if z == 0.0 { FRAC_PI_2 } else { (x / z).atan() };
        let r = x.hypot(z) + 3.0 * (20.0 * angle + y / 150.0).sin();
        // C's `(int)(r + 0.5) % 60`: truncated, so rings near the axis (r < -0.5) count as
        // negative, below 40, light.
        if trunc(r + 0.5) % 60 < 40 {
            self.light
        } else {
            self.dark
        }
    }
}

// ------------------------------------------------------------------------------------------------
// cylindrical checker (TEXFUNC 6)
// ------------------------------------------------------------------------------------------------

/// Tachyon's cylindrical checker: 18 sectors around the z axis through `center`, bands a tenth
/// high along it.
pub struct TachyonCylinderChecker {
    center: [f64; 3],
    even: [f32; 4],
    odd: [f32; 4],
}

fn checker_even() -> [f64; 3] {
    [0.0, 0.2, 1.0]
}

fn checker_odd() -> [f64; 3] {
    [1.0, 0.2, 0.0]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CylinderCheckerParams {
    #[serde(default)]
    center: [f64; 3],
    #[serde(default = "checker_even")]
    even: [f64; 3],
    #[serde(default = "checker_odd")]
    odd: [f64; 3],
}

impl Describe for TachyonCylinderChecker {
    const NAME: &'static str = "tachyon_cylinder_checker";
    const DESCRIPTION: &'static str =
        "Tachyon's TEXFUNC 6 (cylindrical checker): 18 sectors around the z axis through `center` by bands 0.1 high, as Tachyon 0.99b6 computes them.";
    const PARAMS: &'static str = concat!(
        "center: (x, y, z) = (0, 0, 0)  Tachyon's CENTER: the axis runs through it along z\n",
        "even: (r, g, b) = (0, 0.2, 1)  cells whose sector and band numbers sum to an even number (Tachyon's colour)\n",
        "odd: (r, g, b) = (1, 0.2, 0)  the other cells (Tachyon's colour)"
    );
}

impl Texture for TachyonCylinderChecker {
    type Params = CylinderCheckerParams;

    /// The point alone.
    fn reads(&self) -> u32 {
        READS_POINT
    }

    fn create(p: CylinderCheckerParams, _ctx: &Context) -> Result<Self, Error> {
        Ok(TachyonCylinderChecker {
            center: finite("center", p.center)?,
            even: color("even", p.even)?,
            odd: color("odd", p.odd)?,
        })
    }

    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        let [x, y, z]: [f64; 3] = std::array::from_fn(|k| q.p[k] - self.center[k]);
        // u: the angle about z from +x toward +y, in turns; v: the height along z.
        let r = x.hypot(y);
        let mut u = if r > 0.0 {
            (x / r).clamp(-1.0, 1.0).acos() / TAU
        } else {
            0.0
        };
        if y < 0.0 {
            u = 1.0 - u;
        }
        let k = (u.abs() * 18.0).floor() as i64 + (z.abs() * 10.0).floor() as i64;
        if k % 2 == 0 {
            self.even
        } else {
            self.odd
        }
    }
}

// ------------------------------------------------------------------------------------------------
// volume image (TEXFUNC 10 with an IMAGEDEF)
// ------------------------------------------------------------------------------------------------

/// Tachyon's volume image: a block of RGB texels (an IMAGEDEF) filling a unit cube of texture
/// space, repeated, looked up trilinearly.
pub struct TachyonVolumeImage {
    size: [usize; 3],
    rgb: Vec<u8>,
    center: [f64; 3],
    axes: [[f64; 3]; 3],
    offset: [f64; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VolumeImageParams {
    size: [u32; 3],
    rgb: Vec<u8>,
    #[serde(default)]
    center: [f64; 3],
    #[serde(default = "axis_u")]
    u: [f64; 3],
    #[serde(default = "axis_v")]
    v: [f64; 3],
    #[serde(default = "axis_w")]
    w: [f64; 3],
    #[serde(default)]
    offset: [f64; 3],
}

fn axis_u() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}

fn axis_v() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

fn axis_w() -> [f64; 3] {
    [0.0, 0.0, 1.0]
}

impl Describe for TachyonVolumeImage {
    const NAME: &'static str = "tachyon_volume_image";
    const DESCRIPTION: &'static str =
        "Tachyon's TEXFUNC 10: an IMAGEDEF block of RGB texels repeated through space, looked up trilinearly, as Tachyon 0.99b6 does.";
    const PARAMS: &'static str = concat!(
        "size: (nx, ny, nz) = required  texels along u, v and w (each 1 or more)\n",
        "rgb: [u8, ...] = required  3·nx·ny·nz bytes: r, g, b per texel, u fastest, then v, then w\n",
        "center: (x, y, z) = (0, 0, 0)  Tachyon's CENTER\n",
        "u: (x, y, z) = (1, 0, 0)  texture u = u·(p - center) + offset.x (Tachyon's UAXIS times SCALE.x)\n",
        "v: (x, y, z) = (0, 1, 0)  likewise for v (VAXIS times SCALE.y)\n",
        "w: (x, y, z) = (0, 0, 1)  likewise for w (WAXIS times SCALE.z)\n",
        "offset: (u, v, w) = (0, 0, 0)  Tachyon's ROTATE"
    );
}

impl Texture for TachyonVolumeImage {
    type Params = VolumeImageParams;

    /// The point alone.
    fn reads(&self) -> u32 {
        READS_POINT
    }

    fn create(p: VolumeImageParams, _ctx: &Context) -> Result<Self, Error> {
        let size = p.size.map(|n| n as usize);
        if size.contains(&0) {
            return Err(invalid(format!(
                "`size` is {:?}; expected at least 1 texel along each axis",
                p.size
            )));
        }
        let texels = size.iter().try_fold(1usize, |a, &n| a.checked_mul(n));
        if texels.and_then(|t| t.checked_mul(3)) != Some(p.rgb.len()) {
            return Err(invalid(format!(
                "`rgb` has {} bytes; expected 3 per texel of a {} × {} × {} block",
                p.rgb.len(),
                p.size[0],
                p.size[1],
                p.size[2]
            )));
        }
        Ok(TachyonVolumeImage {
            size,
            rgb: p.rgb,
            center: finite("center", p.center)?,
            axes: [finite("u", p.u)?, finite("v", p.v)?, finite("w", p.w)?],
            offset: finite("offset", p.offset)?,
        })
    }

    fn eval(&self, q: &TexQuery) -> [f32; 4] {
        let d: [f64; 3] = std::array::from_fn(|k| q.p[k] - self.center[k]);
        // Texture coordinates wrapped into [0, 1), then texel coordinates with the first and
        // last texel centres at 0 and 1 (as Tachyon's image maps).
        let at: [f64; 3] = std::array::from_fn(|k| {
            let a = self.axes[k];
            let t = a[0] * d[0] + a[1] * d[1] + a[2] * d[2] + self.offset[k];
            let t = t - t.floor();
            // NaN (a point at infinity) looks up the first texel.
            if t.is_finite() {
                t * (self.size[k] - 1) as f64
            } else {
                0.0
            }
        });
        let i: [usize; 3] = std::array::from_fn(|k| (at[k] as usize).min(self.size[k] - 1));
        let f: [f64; 3] = std::array::from_fn(|k| at[k] - i[k] as f64);
        let next: [usize; 3] = std::array::from_fn(|k| (i[k] + 1).min(self.size[k] - 1));
        let [nx, ny, _] = self.size;
        let texel = |x: usize, y: usize, z: usize| {
            let o = 3 * ((z * ny + y) * nx + x);
            [0, 1, 2].map(|c| f64::from(self.rgb[o + c]))
        };
        let lerp = |a: [f64; 3], b: [f64; 3], t: f64| [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * t);
        let plane = |z: usize| {
            let y0 = lerp(texel(i[0], i[1], z), texel(next[0], i[1], z), f[0]);
            let y1 = lerp(texel(i[0], next[1], z), texel(next[0], next[1], z), f[0]);
            lerp(y0, y1, f[1])
        };
        let c = lerp(plane(i[2]), plane(next[2]), f[2]);
        [
            (c[0] / 255.0) as f32,
            (c[1] / 255.0) as f32,
            (c[2] / 255.0) as f32,
            1.0,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::{at, make};

    /// Tachyon's 8-bit value of a colour: floor(255·c).
    fn code(c: [f32; 4]) -> [i32; 3] {
        [0, 1, 2].map(|k| (255.0 * f64::from(c[k])) as i32)
    }

    /// Pixels of `tachyon-nox` images of a plane with TEXFUNC 3 (orthographic view, ambient 1):
    /// the hit point and the pixel. The second group lies where lookups reach lattice index 28
    /// (x, y and z near 27.5).
    const MARBLE: [([f64; 3], [i32; 3]); 16] = [
        ([12.133333333333333, 10.266666666666666, 2.6], [69, 204, 4]),
        ([6.300000000000001, 4.433333333333333, 2.6], [94, 141, 33]),
        ([12.966666666666669, 11.1, 2.6], [89, 154, 18]),
        ([11.3, 8.6, 2.6], [110, 97, 103]),
        ([10.466666666666669, 10.266666666666666, 2.6], [68, 205, 5]),
        ([6.300000000000001, 5.266666666666667, 2.6], [75, 188, 0]),
        ([9.633333333333333, 6.1, 2.6], [94, 139, 36]),
        ([12.133333333333333, 6.1, 2.6], [64, 216, 15]),
        (
            [26.416666666666668, 28.666666666666668, 27.6],
            [58, 227, 33],
        ),
        (
            [28.083333333333332, 26.166666666666668, 27.6],
            [97, 131, 45],
        ),
        ([29.333333333333332, 29.5, 27.6], [109, 101, 96]),
        (
            [25.583333333333332, 27.833333333333332, 27.6],
            [98, 129, 49],
        ),
        (
            [29.333333333333332, 29.083333333333332, 27.6],
            [102, 119, 65],
        ),
        ([27.25, 26.583333333333332, 27.6], [122, 68, 160]),
        ([28.083333333333332, 27.0, 27.6], [77, 185, 0]),
        ([26.0, 26.583333333333332, 27.6], [102, 118, 67]),
    ];

    #[test]
    fn marble_matches_tachyon() {
        let t: TachyonMarble = make("()").unwrap();
        for (p, want) in MARBLE {
            let got = code(at(&t, p));
            assert!(
                (0..3).all(|k| (got[k] - want[k]).abs() <= 1),
                "{p:?}: {got:?}, Tachyon {want:?}"
            );
            // Symmetric in z (Tachyon's noise takes |z|): the importer's mirror changes nothing.
            assert_eq!(at(&t, p), at(&t, [p[0], p[1], -p[2]]));
        }
        assert!(make::<TachyonMarble>("(scale: 2)").is_err());
    }

    #[test]
    fn noise_lattice_is_tachyons() {
        let t = lattice();
        // Index 27 repeats index 0; beyond the table, zeros.
        let at = |x: usize, y: usize, z: usize| t[(x * N + y) * N + z];
        assert_eq!(at(27, 5, 9), at(0, 5, 9));
        assert_eq!(at(3, 27, 27), at(3, 0, 0));
        assert_eq!(t[N * N * N], 0);
        assert!(t[..N * N * N].iter().all(|v| (0..12000).contains(v)));
        // Whole points give lattice values; far and odd points do not panic.
        assert_eq!(noise([1.0, 2.0, 3.0]), i64::from(at(1, 2, 3)));
        assert_eq!(noise([-1.0, 2.0, -3.0]), i64::from(at(1, 2, 3)));
        let _ = noise([1e300, f64::NAN, -f64::INFINITY]);
    }

    /// `tachyon-nox` images (24×24) of a plane y = 0.4 seen from above with TEXFUNC 4: `#` the
    /// rings' colour (0.8, 1, 0.2), `.` black. Pixel (row r, column i) is the point
    /// (x0 + (i + 1)·step, 0.4, z0 − r·step).
    struct Image {
        center: [f64; 3],
        scale: [f64; 3],
        x0: f64,
        z0: f64,
        step: f64,
        rows: [&'static str; 24],
    }

    const WOOD: [Image; 4] = [
        // Near the axis r < -0.5 happens: C's remainder keeps it below 40 (light), all light.
        Image {
            center: [0.2, 0.0, -0.3],
            scale: [1.0; 3],
            x0: -3.8,
            z0: 3.7,
            step: 1.0 / 3.0,
            rows: ["########################"; 24],
        },
        Image {
            center: [0.2, 0.0, -0.3],
            scale: [1.0; 3],
            x0: -30.0,
            z0: 40.0,
            step: 5.0,
            rows: [
                "....#..#.......#########",
                "..######.#.....#########",
                "##########.....#########",
                "############.....#######",
                "############.....#######",
                "#############....#######",
                "#############....#######",
                "##############....######",
                "##############...#######",
                "#############....#######",
                "##############...#######",
                "############......######",
                "#############...########",
                "###########.....########",
                ".##########.....########",
                ".#.######......#########",
                "...#..#.......#########.",
                "..............#########.",
                "...........############.",
                "##.........############.",
                "##.###.##############...",
                "####################....",
                "####################....",
                "###################....#",
            ],
        },
        // lscapes.dat's SCALE and CENTER.
        Image {
            center: [0.0, 2.0, 6.0],
            scale: [0.001; 3],
            x0: -0.03,
            z0: 6.08,
            step: 0.005,
            rows: [
                "################.......#",
                "###################.....",
                "####################....",
                "####################....",
                "###.##..#############...",
                ".#.......#.###########..",
                "............###########.",
                "..............##########",
                "....#.#.......##########",
                ".#########....##########",
                ".##########.....########",
                "###########......#######",
                "#############...########",
                "#############....#######",
                "#############.....######",
                "##############...#######",
                "#############....#######",
                "##############....######",
                "#############.....######",
                "#############....#######",
                "#############...########",
                "############.....#######",
                "##########......########",
                ".#########.....#########",
            ],
        },
        Image {
            center: [0.5, 0.1, 0.7],
            scale: [0.3, 2.0, 0.5],
            x0: -10.0,
            z0: 23.0,
            step: 5.0 / 3.0,
            rows: [
                "............##########..",
                ".....#.#......#########.",
                "...#.#.#.......########.",
                "...#####.#....#########.",
                ".#########....#########.",
                ".#########.#...########.",
                ".###########....#######.",
                "###########.....#######.",
                "############....#######.",
                "#############...########",
                "############....########",
                "############.....#######",
                "#############....#######",
                "#############....#######",
                "############....#######.",
                "#############...#######.",
                "#############...#######.",
                "#############....######.",
                "############.....######.",
                "############....########",
                "############...#########",
                "###########....#########",
                "..#########....########.",
                "..#######.#....########.",
            ],
        },
    ];

    fn v3(v: [f64; 3]) -> String {
        format!("({}, {}, {})", v[0], v[1], v[2])
    }

    #[test]
    fn wood_matches_tachyon() {
        let light = [0.8f32, 1.0, 0.2, 1.0];
        for img in &WOOD {
            let t: TachyonWood = make(&format!(
                "(center: {}, scale: {})",
                v3(img.center),
                v3(img.scale)
            ))
            .unwrap();
            // The importer's mirror: z negated in the point, the centre and the scale.
            let m: TachyonWood = make(&format!(
                "(center: {}, scale: {})",
                v3([img.center[0], img.center[1], -img.center[2]]),
                v3([img.scale[0], img.scale[1], -img.scale[2]])
            ))
            .unwrap();
            for (r, row) in img.rows.iter().enumerate() {
                for (i, b) in row.bytes().enumerate() {
                    let p = [
                        img.x0 + (i + 1) as f64 * img.step,
                        0.4,
                        img.z0 - r as f64 * img.step,
                    ];
                    let want = if b == b'#' {
                        light
                    } else {
                        [0.0, 0.0, 0.0, 1.0]
                    };
                    assert_eq!(at(&t, p), want, "{:?} row {r} column {i}", img.center);
                    assert_eq!(
                        at(&m, [p[0], p[1], -p[2]]),
                        want,
                        "mirrored, row {r} col {i}"
                    );
                }
            }
        }
        for bad in [
            "(scale: 0)",
            "(scale: (1, NaN, 1))",
            "(center: (inf, 0, 0))",
            "(dark: (-1, 0, 0))",
        ] {
            assert!(make::<TachyonWood>(bad).is_err(), "{bad}");
        }
    }

    /// `tachyon-nox` images (24×24) of planes z = 0.37 and z = 0.28 facing the camera with
    /// TEXFUNC 6 CENTER 0.3 −0.2 0.15: `#` (1, 0.2, 0), `.` (0, 0.2, 1). Pixel (r, i) is the
    /// point (−1.1 + (i + 1)/8, 1.6 − r/8, z). The bands differ in parity: one image is the
    /// other's negative.
    const CYLINDER_037: [&str; 24] = [
        "..######.....######.....",
        "...#####.....#####......",
        "....#####....#####......",
        "....#####....####.......",
        ".....####....####......#",
        ".....####...####......##",
        "#.....###...####.....###",
        "##....###...###.....####",
        "###....###..##....######",
        "####....##..##...#######",
        "#####...##.##...#######.",
        ".######..#.##..#####....",
        "....####.#.#..###.......",
        ".......##..####.........",
        "..........##............",
        "#########...############",
        "######...##.#..#########",
        "####....#.#.##....######",
        "#.....###.#..##......###",
        ".....###..##.###.......#",
        "....###...##..###.......",
        "...####...##...####.....",
        "..####...###...#####....",
        "######...###....#####...",
    ];
    const CYLINDER_028: [&str; 24] = [
        "##......#####......#####",
        "###.....#####.....######",
        "####.....####.....######",
        "####.....####....#######",
        "#####....####....######.",
        "#####....###....######..",
        ".#####...###....#####...",
        "..####...###...#####....",
        "...####...##..####......",
        "....####..##..###.......",
        ".....###..#..###.......#",
        "#......##.#..##.....####",
        "####....#.#.##...#######",
        "#######..##....#########",
        "##########..############",
        ".........###............",
        "......###..#.##.........",
        "....####.#.#..####......",
        ".#####...#.##..######...",
        "#####...##..#...#######.",
        "####...###..##...#######",
        "###....###..###....#####",
        "##....###...###.....####",
        "......###...####.....###",
    ];

    #[test]
    fn cylinder_checker_matches_tachyon() {
        let t: TachyonCylinderChecker = make("(center: (0.3, -0.2, 0.15))").unwrap();
        let odd = [1.0f32, 0.2, 0.0, 1.0];
        let even = [0.0f32, 0.2, 1.0, 1.0];
        for (z, rows) in [(0.37, CYLINDER_037), (0.28, CYLINDER_028)] {
            for (r, row) in rows.iter().enumerate() {
                for (i, b) in row.bytes().enumerate() {
                    let p = [-1.1 + (i + 1) as f64 / 8.0, 1.6 - r as f64 / 8.0, z];
                    let want = if b == b'#' { odd } else { even };
                    assert_eq!(at(&t, p), want, "z {z} row {r} column {i}");
                    // Mirrored about z = 0.15 (the importer's mirror negates z and the centre).
                    assert_eq!(at(&t, [p[0], p[1], 0.3 - z]), want);
                }
            }
        }
        // On the axis: no NaN.
        assert!(at(&t, [0.3, -0.2, 0.5]).iter().all(|c| c.is_finite()));
        assert!(make::<TachyonCylinderChecker>("(odd: (0, -1, 0))").is_err());
    }

    #[test]
    fn volume_image_is_trilinear_and_wraps() {
        // 2 × 1 × 2: red, green on the first slice; blue, white on the second.
        let t: TachyonVolumeImage =
            make("(size: (2, 1, 2), rgb: [255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255])")
                .unwrap();
        let close = |a: [f32; 4], b: [f32; 3]| (0..3).all(|k| (a[k] - b[k]).abs() < 1e-6);
        assert!(close(at(&t, [0.0, 0.0, 0.0]), [1.0, 0.0, 0.0]));
        assert!(close(at(&t, [0.5, 0.0, 0.0]), [0.5, 0.5, 0.0]));
        assert!(close(at(&t, [0.25, 0.7, 0.5]), [0.5, 0.25, 0.5]));
        // u, v and w repeat every unit.
        assert!(close(
            at(&t, [-0.75, 3.7, 2.5]),
            at(&t, [0.25, 0.7, 0.5])[..3].try_into().unwrap()
        ));
        // Axes, centre and offset: u = 2·(x − 1) + 0.25.
        let t: TachyonVolumeImage = make(
            "(size: (2, 1, 1), rgb: [0, 0, 0, 255, 255, 255], center: (1, 0, 0), u: (2, 0, 0), offset: (0.25, 0, 0))",
        )
        .unwrap();
        assert!(close(at(&t, [1.125, 0.0, 0.0]), [0.5, 0.5, 0.5]));
        // Points at infinity look up the first texel.
        assert!(close(at(&t, [f64::INFINITY, 0.0, 0.0]), [0.0, 0.0, 0.0]));
    }

    #[test]
    fn volume_image_checks_its_block() {
        let e = make::<TachyonVolumeImage>("(size: (2, 0, 1), rgb: [])")
            .err()
            .unwrap();
        assert!(e.to_string().contains("at least 1 texel"), "{e}");
        let e = make::<TachyonVolumeImage>("(size: (2, 1, 1), rgb: [1, 2, 3])")
            .err()
            .unwrap();
        assert!(
            e.to_string()
                .contains("`rgb` has 3 bytes; expected 3 per texel of a 2 × 1 × 1 block"),
            "{e}"
        );
    }
}
