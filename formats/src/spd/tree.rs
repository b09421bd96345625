//! `tree`: a branching tree.
//!
//! A trunk of length 1 rises from the origin (radius 0.15 at the ground, narrowing by the
//! factor 0.67 along every branch). Every branch forks into two: one 0.65 as long, leaning 40
//! degrees from its parent, the other 0.7 as long, leaning 25 degrees; each branch carries its
//! own frame, in which the first fork turns 90 degrees about the branch axis and the second
//! 230 degrees before leaning (the trunk's frame is turned -90 degrees about z). `size` levels
//! of forks: 2^(size+1) - 1 branches (size 11: 4095), each an open cone with a sphere at its
//! tip, written depth first (first fork first). The tree stands on a 100x100 square lawn under
//! seven lights.

use std::io;

use super::{add, apply, fill, mat_mul, rotation, view, Sink, BACKGROUND, M3, V3};

pub fn generate(size: u32, s: &mut dyn Sink) -> io::Result<()> {
    s.background(BACKGROUND)?;
    s.view(&view(
        [4.5, 0.4, 2.0],
        [0.0, 0.0, 1.5],
        [0.0, 0.0, 1.0],
        1.0,
    ))?;
    for l in [
        [-5.0, 5.0, 50.0],
        [30.0, -30.0, 30.0],
        [-40.0, -30.0, 20.0],
        [10.0, 30.0, 40.0],
        [-30.0, 40.0, 10.0],
        [50.0, 25.0, 20.0],
        [-10.0, -60.0, 30.0],
    ] {
        s.light(l)?;
    }
    s.fill(&fill([0.2, 0.7, 0.2], 1.0, 0.0, 0.0, 0.0, 0.0))?;
    s.polygon(&[
        [50.0, 50.0, 0.0],
        [-50.0, 50.0, 0.0],
        [-50.0, -50.0, 0.0],
        [50.0, -50.0, 0.0],
    ])?;
    s.fill(&fill([0.55, 0.4, 0.2], 1.0, 0.0, 0.0, 0.0, 0.0))?;
    let forks = [fork(90.0, 40.0, 0.65), fork(230.0, 25.0, 0.7)];
    branch(s, &forks, [0.0; 3], &rot_z(-90.0), 1.0, 0.15, size)
}

/// A fork's turn about the branch axis, lean and relative length.
struct Fork {
    turn: M3,
    length: f64,
}

fn rot_z(deg: f64) -> M3 {
    rotation([0.0, 0.0, 1.0], deg.to_radians())
}

fn fork(turn: f64, lean: f64, length: f64) -> Fork {
    Fork {
        turn: mat_mul(&rot_z(turn), &rotation([0.0, 1.0, 0.0], lean.to_radians())),
        length,
    }
}

fn branch(
    s: &mut dyn Sink,
    forks: &[Fork; 2],
    base: V3,
    frame: &M3,
    length: f64,
    base_r: f64,
    depth: u32,
) -> io::Result<()> {
    let tip = add(base, apply(frame, [0.0, 0.0, length]));
    let tip_r = base_r * 0.67;
    s.cone(base, base_r, tip, tip_r)?;
    s.sphere(tip, tip_r)?;
    if depth == 0 {
        return Ok(());
    }
    for f in forks {
        let m = mat_mul(frame, &f.turn);
        branch(s, forks, tip, &m, length * f.length, tip_r, depth - 1)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn branch_counts() {
        for size in [0u32, 1, 11] {
            let c = super::super::count("tree", size).unwrap();
            assert_eq!(c.cones, 2u64.pow(size + 1) - 1, "size {size}");
            assert_eq!(c.spheres, c.cones);
        }
    }
}
