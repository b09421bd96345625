//! `tetra`: the Sierpinski tetrahedron.
//!
//! The regular tetrahedron with corners (1, 1, 1), (-1, -1, 1), (-1, 1, -1), (1, -1, -1) is
//! replaced by the four half-size tetrahedra at its corners, `size` times over; the
//! 4^size smallest are written as their four triangular faces (4^(size+1) triangles; size 5:
//! 4096), the faces of each oriented outwards. The sub-tetrahedra are visited corner by
//! corner in the order 2nd, 3rd, 4th, 1st.

use std::io;

use super::{add, fill, mul, view, Sink, BACKGROUND, V3};

pub fn generate(size: u32, s: &mut dyn Sink) -> io::Result<()> {
    s.background(BACKGROUND)?;
    s.view(&view(
        [1.02285, -3.17715, -2.17451],
        [-0.004103, -0.004103, 0.216539],
        [-0.816497, -0.816497, 0.816497],
        1.0,
    ))?;
    s.light([2.0, -18.0, -5.0])?;
    s.fill(&fill([1.0, 0.2, 0.2], 1.0, 0.0, 0.0, 0.0, 0.0))?;
    let corners = [
        [1.0, 1.0, 1.0],
        [-1.0, -1.0, 1.0],
        [-1.0, 1.0, -1.0],
        [1.0, -1.0, -1.0],
    ];
    tetra(s, &corners, size)
}

fn tetra(s: &mut dyn Sink, v: &[V3; 4], depth: u32) -> io::Result<()> {
    if depth == 0 {
        for f in [[1, 2, 3], [0, 3, 2], [3, 0, 1], [2, 1, 0]] {
            s.polygon(&f.map(|i| v[i]))?;
        }
        return Ok(());
    }
    for k in [1, 2, 3, 0] {
        let child = std::array::from_fn(|i| mul(add(v[i], v[k]), 0.5));
        tetra(s, &child, depth - 1)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn triangle_counts() {
        for size in [0u32, 1, 5] {
            let c = super::super::count("tetra", size).unwrap();
            assert_eq!(c.polygons, 4u64.pow(size + 1), "size {size}");
        }
    }
}
