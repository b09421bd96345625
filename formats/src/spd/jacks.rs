//! `jacks`: recursive jacks, "sort of like a Menger sponge".
//!
//! Alexander Enzmann's SPD program `jacks`, from its description: a jack is three cylinders of
//! radius 0.1 along the axes from -1 to 1, with a sphere of radius 0.2 at each of the six ends,
//! the whole scaled by 0.75 so that neighbours do not touch. Below the top level, each jack has
//! eight children, one in each octant its arms divide space into: a copy of the whole
//! construction scaled by 1/2 about the point `(±1/2, ±1/2, ±1/2)` of the parent's frame
//! (x outermost, then y, then z, minus before plus). `size` levels: `(8^size - 1) / 7` jacks,
//! each written as its x, y, z cylinders, then its spheres at +x, +y, +z, -x, -y, -z.
//! Everything is turned by -20 degrees about y, then -30 degrees about x (right-handed), and
//! looked at from -8 on z with a 25-degree view at 256x256, one light, pink with a highlight,
//! on a dark purple background.
//!
//! Counts (from the construction; the header of the SPD's `jacks.c` 3.14 leaves its table
//! blank): `3 (8^size - 1) / 7` cylinders and `6 (8^size - 1) / 7` spheres: size 1 (the SPD's
//! default) 3 and 6, size 2 27 and 54, size 4 1,755 and 3,510.

use std::io;

use super::{add, apply, fill, mat_mul, mul, rotation, Sink, View, M3, V3};

/// The SPD's "DarkPurple".
const DARK_PURPLE: [f64; 3] = [0.2, 0.05, 0.2];
/// The SPD's "Pink".
const PINK: [f64; 3] = [0.737, 0.561, 0.561];

pub fn generate(size: u32, s: &mut dyn Sink) -> io::Result<()> {
    s.background(DARK_PURPLE)?;
    s.view(&View {
        from: [0.0, 0.0, -8.0],
        at: [0.0; 3],
        up: [0.0, 1.0, 0.0],
        angle: 25.0,
        hither: 0.001,
        resolution: (256, 256),
    })?;
    s.light([-10.0, 3.0, -20.0])?;
    let turn = mat_mul(
        &rotation([1.0, 0.0, 0.0], (-30.0f64).to_radians()),
        &rotation([0.0, 1.0, 0.0], (-20.0f64).to_radians()),
    );
    s.fill(&fill(PINK, 0.7, 0.7, 20.0, 0.0, 1.0))?;
    jack(s, &turn, [0.0; 3], 1.0, size)
}

/// The jack of the frame centred at `c` (before the turn) with scale `scale`, and its
/// descendants `levels - 1` deep.
fn jack(s: &mut dyn Sink, turn: &M3, c: V3, scale: f64, levels: u32) -> io::Result<()> {
    if levels == 0 {
        return Ok(());
    }
    let k = 0.75 * scale;
    let at = |p: V3| apply(turn, add(c, mul(p, k)));
    let axes: [V3; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for a in axes {
        s.cone(at(mul(a, -1.0)), 0.1 * k, at(a), 0.1 * k)?;
    }
    for sign in [1.0, -1.0] {
        for a in axes {
            s.sphere(at(mul(a, sign)), 0.2 * k)?;
        }
    }
    for i in [-0.5, 0.5] {
        for j in [-0.5, 0.5] {
            for l in [-0.5, 0.5] {
                let child = add(c, mul([i, j, l], scale));
                jack(s, turn, child, 0.5 * scale, levels - 1)?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::{add, count, length, mul, sub, Recorder};

    #[test]
    fn jack_counts() {
        for (size, jacks) in [(1u64, 1u64), (2, 9), (3, 73), (4, 585)] {
            let c = count("jacks", size as u32).unwrap();
            assert_eq!(jacks, (8u64.pow(size as u32) - 1) / 7);
            assert_eq!((c.cones, c.spheres), (3 * jacks, 6 * jacks), "size {size}");
            assert_eq!((c.polygons, c.lights, c.fills), (0, 1, 1));
        }
    }

    /// The top jack: arms of length 1.5 through the origin, end balls of radius 0.15, each
    /// cylinder ending at two of the balls; children half the size.
    #[test]
    fn jack_geometry() {
        let r = Recorder::of("jacks", 2);
        for (b, br, a, ar) in &r.cones[..3] {
            assert!((length(sub(*a, *b)) - 1.5).abs() < 1e-12);
            assert!((br - 0.075).abs() < 1e-15 && (ar - 0.075).abs() < 1e-15);
            assert!(length(add(*a, *b)) < 1e-12, "centred on the origin");
            assert!(r.spheres[..6]
                .iter()
                .any(|(c, _)| length(sub(*c, *a)) < 1e-12));
        }
        for (_, radius) in &r.spheres[..6] {
            assert!((radius - 0.15).abs() < 1e-15);
        }
        // The first child sits at (-1/2, -1/2, -1/2) before the turn: distance sqrt(3)/2.
        let (b, _, a, ar) = r.cones[3];
        assert!((length(mul(add(a, b), 0.5)) - 0.75f64.sqrt()).abs() < 1e-12);
        assert!((ar - 0.0375).abs() < 1e-15);
        // The turn moves +x off the x axis: the top jack's x cylinder is not axis-aligned.
        let (_, _, a, _) = r.cones[0];
        assert!(a[1].abs() > 0.1 && a[2].abs() > 0.1, "{a:?}");
    }
}
