//! The perspective camera. The world is re-centred on the camera, so its origin is (0, 0, 0)
//! in render space and precision is best where the viewer looks from.

use crate::math::Vec3A;
use crate::ray::Ray;
use luxon_formats::{CameraDesc, Projection};

#[derive(Clone, Debug)]
pub struct Camera {
    pub origin: Vec3A,
    pub forward: Vec3A,
    /// Right and up, scaled to the image plane's half width and half height at unit distance.
    pub right: Vec3A,
    pub up: Vec3A,
}

impl Camera {
    /// `origin` is the camera position in render space (zero when the world is centred on it).
    pub fn new(desc: &CameraDesc, origin: Vec3A, width: u32, height: u32) -> Camera {
        let pos = glam::DVec3::from(desc.position);
        let forward = (glam::DVec3::from(desc.look_at) - pos).normalize();
        let right = forward.cross(glam::DVec3::from(desc.up)).normalize();
        let up = right.cross(forward);
        let half_h = match desc.projection {
            Projection::Perspective { fov_deg } => (fov_deg.to_radians() * 0.5).tan(),
            Projection::PerspectiveZoom { zoom } => 1.0 / zoom,
        };
        let aspect = desc.aspect.unwrap_or(width as f64 / height as f64);
        let half_w = half_h * aspect;
        Camera {
            origin,
            forward: Vec3A::from(forward.as_vec3()),
            right: Vec3A::from((right * half_w).as_vec3()),
            up: Vec3A::from((up * half_h).as_vec3()),
        }
    }

    /// The ray through image position (`x`, `y`) in pixels from the top-left corner.
    #[inline]
    pub fn ray(&self, x: f32, y: f32, width: u32, height: u32, time: f32) -> Ray {
        let sx = 2.0 * x / width as f32 - 1.0;
        let sy = 1.0 - 2.0 * y / height as f32;
        let d = (self.forward + sx * self.right + sy * self.up).normalize();
        Ray::new(self.origin, d, time)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_pixel_looks_forward_and_corners_span_the_fov() {
        let desc = CameraDesc {
            position: [0.0, 0.0, 0.0],
            look_at: [0.0, 0.0, -1.0],
            up: [0.0, 1.0, 0.0],
            projection: Projection::Perspective { fov_deg: 90.0 },
            aspect: None,
        };
        let cam = Camera::new(&desc, Vec3A::ZERO, 200, 100);
        let c = cam.ray(100.0, 50.0, 200, 100, 0.0);
        assert!((c.dir - Vec3A::new(0.0, 0.0, -1.0)).length() < 1e-6);
        // Top edge: 45 degrees up. Right edge: atan(2) to the right (aspect 2).
        let top = cam.ray(100.0, 0.0, 200, 100, 0.0);
        assert!((top.dir.y - (0.5f32).sqrt()).abs() < 1e-6);
        let right = cam.ray(200.0, 50.0, 200, 100, 0.0);
        assert!(right.dir.x > 0.0 && (right.dir.x / -right.dir.z - 2.0).abs() < 1e-5);
    }
}
