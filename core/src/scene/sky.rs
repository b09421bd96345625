//! A gradient background (`background: Gradient(...)`, Tachyon's BACKGROUND_GRADIENT),
//! evaluated for each ray that hits nothing.

use crate::math::{DVec3, Vec3A};
use luxon_formats::{GradientDesc, GradientKind};

/// The gradient in render space, ready to evaluate.
#[derive(Clone, Copy, Debug)]
pub struct Sky {
    kind: GradientKind,
    up: Vec3A,
    /// Where the mix is 0 (for `OrthoPlane`, moved into render space: origins there are
    /// relative to the world offset), and 1 / (top − bottom) (infinite for a sharp horizon).
    bottom: f32,
    inv_range: f32,
    top_color: Vec3A,
    bottom_color: Vec3A,
}

impl Sky {
    pub fn new(g: &GradientDesc, world_offset: DVec3) -> Sky {
        let up = DVec3::from(g.up);
        let bottom = match g.kind {
            GradientKind::Sphere => g.bottom,
            GradientKind::OrthoPlane => g.bottom - up.dot(world_offset),
        };
        Sky {
            kind: g.kind,
            up: up.as_vec3().into(),
            bottom: bottom as f32,
            inv_range: (1.0 / (g.top - g.bottom)) as f32,
            top_color: Vec3A::from(g.top_color.map(|x| x as f32)),
            bottom_color: Vec3A::from(g.bottom_color.map(|x| x as f32)),
        }
    }

    /// The colour a ray from `origin` along `dir` (unit length) sees.
    #[inline]
    pub fn toward(&self, origin: Vec3A, dir: Vec3A) -> Vec3A {
        let x = match self.kind {
            GradientKind::Sphere => dir.dot(self.up),
            GradientKind::OrthoPlane => origin.dot(self.up),
        };
        let t = (x - self.bottom) * self.inv_range;
        // Clamped to 0..1; the NaN of a sharp horizon hit exactly (0 · ∞) becomes 0.
        let t = if t >= 0.0 { t.min(1.0) } else { 0.0 };
        t * self.top_color + (1.0 - t) * self.bottom_color
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sky(kind: GradientKind, top: f64, bottom: f64) -> Sky {
        let g = GradientDesc {
            kind,
            up: [0.0, 2.0, 0.0],
            top,
            bottom,
            top_color: [1.0, 0.0, 0.0],
            bottom_color: [0.0, 0.0, 1.0],
        };
        Sky::new(&g, DVec3::new(0.0, 0.25, 0.0))
    }

    #[test]
    fn the_mix_runs_along_up_and_is_clamped() {
        let s = sky(GradientKind::Sphere, 1.0, -1.0);
        let o = Vec3A::ZERO;
        // x = up·dir = 2·dir.y, not normalised.
        assert_eq!(s.toward(o, Vec3A::Y), Vec3A::new(1.0, 0.0, 0.0));
        assert_eq!(s.toward(o, -Vec3A::Y), Vec3A::new(0.0, 0.0, 1.0));
        let half = s.toward(o, Vec3A::X);
        assert!((half - Vec3A::new(0.5, 0.0, 0.5)).abs().max_element() < 1e-6);
        let quarter = s.toward(o, Vec3A::new(0.0, 0.25, 0.0));
        assert!((quarter - Vec3A::new(0.75, 0.0, 0.25)).abs().max_element() < 1e-6);
    }

    #[test]
    fn an_ortho_plane_follows_the_world_origin_of_the_ray() {
        let s = sky(GradientKind::OrthoPlane, 1.0, 0.0);
        // Render-space y = -0.25 is world y = 0: x = 0, the bottom colour.
        let c = s.toward(Vec3A::new(5.0, -0.25, 3.0), Vec3A::Y);
        assert!(
            (c - Vec3A::new(0.0, 0.0, 1.0)).abs().max_element() < 1e-6,
            "{c}"
        );
        let c = s.toward(Vec3A::new(0.0, 0.0, 0.0), -Vec3A::Y);
        assert!(
            (c - Vec3A::new(0.5, 0.0, 0.5)).abs().max_element() < 1e-6,
            "{c}"
        );
    }

    #[test]
    fn equal_top_and_bottom_make_a_sharp_horizon() {
        let s = sky(GradientKind::Sphere, 0.5, 0.5);
        let o = Vec3A::ZERO;
        assert_eq!(s.toward(o, Vec3A::new(0.0, 0.3, 0.95)), Vec3A::X);
        assert_eq!(s.toward(o, Vec3A::new(0.0, 0.2, 0.98)), Vec3A::Z);
        assert_eq!(s.toward(o, Vec3A::new(0.0, 0.25, 0.97)), Vec3A::Z);
    }
}
