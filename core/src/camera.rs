//! Cameras: perspective, orthographic, angular fisheye and equirectangular projections, each
//! optionally with a frustum override (perspective, orthographic, equirectangular), a thin lens
//! (depth of field) and two eyes in one image (stereo). The world is re-centred on the camera, so its origin is
//! (0, 0, 0) in render space and precision is best where the viewer looks from.
//!
//! A camera ray is built in up to three steps:
//!
//! 1. **Projection**: the image position gives a ray from the (mono) camera. Perspective:
//!    through the window `forward + shift + sx·right + sy·up` at unit distance. Orthographic:
//!    along `forward` from the window point `origin + shift + sx·right + sy·up`. Fisheye
//!    (angular, equidistant): the angle from `forward` is proportional to the distance from the
//!    image centre, `fov / 2` at half the image height. Equirectangular: longitude −180° at the
//!    left edge to +180° at the right, latitude +90° at the top to −90° at the bottom, or the
//!    frustum's window in degrees (Tachyon's FISHEYE is such a window).
//! 2. **Stereo**: the eye sits `eye_separation / 2` to the left or right of the camera (along
//!    `right`; for equirectangular along the horizontal perpendicular of each ray's longitude:
//!    omni-directional stereo, so every viewing direction of a VR panorama has a correct pair).
//!    The eyes look parallel, each ray aimed at the point the mono ray meets the convergence
//!    surface: the plane at depth `convergence` (perspective, orthographic: asymmetric,
//!    off-axis frusta, no keystone distortion) or the sphere of radius `convergence` (fisheye,
//!    equirectangular). Points at that distance have zero parallax.
//! 3. **Depth of field**: the ray starts at a point of a thin lens of radius `aperture` around
//!    the eye and passes through the point where the pinhole ray meets the focal surface (plane
//!    at depth `focal_distance`, or for fisheye and equirectangular the sphere of that radius,
//!    the lens then lying across the ray). The lens point comes from a hash of the bits of the
//!    ray's (x, y, time), mapped to the disk concentrically (Shirley & Chiu): deterministic per
//!    pixel sample whatever the thread, rank or decomposition, and different for every
//!    antialiasing sample since the jittered positions differ. Aperture 0 is a pinhole.

use crate::math::Vec3A;
use crate::ray::Ray;
use crate::sampler::{hash, to_unit};
use luxon_formats::{CameraDesc, Projection, StereoLayout};
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};

/// Rays a pinhole camera makes side by side ([`Camera::primaries`]).
pub const BATCH: usize = 8;

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Perspective,
    Orthographic,
    /// Angle from `forward` at unit image radius, and the horizontal scale (aspect).
    Fisheye {
        half_angle: f32,
        aspect: f32,
    },
    /// The window's centre and half extents in radians of longitude and latitude (−π..π by
    /// −π/2..π/2 unless a frustum says otherwise).
    Equirectangular {
        lon: f32,
        lat: f32,
        half_lon: f32,
        half_lat: f32,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Eyes {
    layout: StereoLayout,
    half_separation: f32,
    convergence: f32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Lens {
    radius: f32,
    focal_distance: f32,
}

#[derive(Clone, Debug)]
pub struct Camera {
    pub origin: Vec3A,
    pub forward: Vec3A,
    /// Right and up, scaled to the image window's half width and half height: at unit distance
    /// (perspective), in world units (orthographic), in radians (fisheye: the angle at the
    /// window's edge; equirectangular: the window's half extents).
    pub right: Vec3A,
    pub up: Vec3A,
    /// The window's centre relative to `forward` (perspective) or to `origin` (orthographic):
    /// non-zero only for an off-centre `frustum`.
    shift: Vec3A,
    right_unit: Vec3A,
    up_unit: Vec3A,
    kind: Kind,
    eyes: Option<Eyes>,
    lens: Option<Lens>,
    /// Texture footprint of a primary ray: width at the eye and growth per unit distance.
    footprint: (f32, f32),
    /// A plain perspective camera (one eye, no lens), the per-pixel common case: its rays are
    /// made inline from `centre` (`forward + shift`, the first sum of the general formula).
    pinhole: bool,
    centre: Vec3A,
}

impl Camera {
    /// `origin` is the camera position in render space (zero when the world is centred on it).
    /// `width` × `height` is the whole image (both eyes for stereo).
    pub fn new(desc: &CameraDesc, origin: Vec3A, width: u32, height: u32) -> Camera {
        let pos = glam::DVec3::from(desc.position);
        let forward = (glam::DVec3::from(desc.look_at) - pos).normalize();
        let right = forward.cross(glam::DVec3::from(desc.up)).normalize();
        let up = right.cross(forward);
        let (eye_w, eye_h) = match desc.stereo.map(|s| s.layout) {
            None => (width as f64, height as f64),
            Some(StereoLayout::SideBySide) => (width as f64 / 2.0, height as f64),
            Some(StereoLayout::OverUnder) => (width as f64, height as f64 / 2.0),
        };
        let aspect = desc.aspect.unwrap_or(eye_w / eye_h);
        // Half width, half height and centre of the window.
        let window = |half_h: f64| (half_h * aspect, half_h, 0.0, 0.0);
        let (kind, (half_w, half_h, cx, cy)) = match desc.projection {
            Projection::Perspective { fov_deg } => (
                Kind::Perspective,
                window((fov_deg.to_radians() * 0.5).tan()),
            ),
            // Tachyon's zoom 1 is a window 1 high at unit distance (measured with tachyon-nox).
            Projection::PerspectiveZoom { zoom } => (Kind::Perspective, window(0.5 / zoom)),
            Projection::Orthographic { height } => (Kind::Orthographic, window(height * 0.5)),
            Projection::Fisheye { fov_deg } => {
                let half_angle = fov_deg.to_radians() * 0.5;
                let kind = Kind::Fisheye {
                    half_angle: half_angle as f32,
                    aspect: aspect as f32,
                };
                (kind, window(half_angle))
            }
            Projection::Equirectangular => {
                // Degrees of longitude and latitude: the whole sphere or the frustum's window.
                let [l, r, b, t] = desc
                    .frustum
                    .map_or([-180.0, 180.0, -90.0, 90.0], |f| {
                        [f.left, f.right, f.bottom, f.top]
                    })
                    .map(f64::to_radians);
                let (half_w, half_h) = ((r - l) * 0.5, (t - b) * 0.5);
                let kind = Kind::Equirectangular {
                    lon: ((r + l) * 0.5) as f32,
                    lat: ((t + b) * 0.5) as f32,
                    half_lon: half_w as f32,
                    half_lat: half_h as f32,
                };
                (kind, (half_w, half_h, 0.0, 0.0))
            }
        };
        let (half_w, half_h, cx, cy) = match (desc.frustum, kind) {
            (Some(f), Kind::Perspective | Kind::Orthographic) => (
                (f.right - f.left) * 0.5,
                (f.top - f.bottom) * 0.5,
                (f.right + f.left) * 0.5,
                (f.top + f.bottom) * 0.5,
            ),
            _ => (half_w, half_h, cx, cy),
        };
        let v = |d: glam::DVec3| Vec3A::from(d.as_vec3());
        let per_pixel = (2.0 * half_h / eye_h) as f32;
        let footprint = match kind {
            Kind::Orthographic => (per_pixel, 0.0),
            _ => (0.0, per_pixel),
        };
        let eyes = desc.stereo.map(|s| Eyes {
            layout: s.layout,
            half_separation: (s.eye_separation * 0.5) as f32,
            convergence: s.convergence as f32,
        });
        let lens = desc
            .depth_of_field
            .filter(|d| d.aperture > 0.0)
            .map(|d| Lens {
                radius: d.aperture as f32,
                focal_distance: d.focal_distance as f32,
            });
        let shift = v(right * cx + up * cy);
        Camera {
            origin,
            forward: v(forward),
            right: v(right * half_w),
            up: v(up * half_h),
            shift,
            right_unit: v(right),
            up_unit: v(up),
            kind,
            eyes,
            lens,
            footprint,
            pinhole: kind == Kind::Perspective && eyes.is_none() && lens.is_none(),
            centre: v(forward) + shift,
        }
    }

    /// Texture footprint of primary rays as (width at the eye, growth per unit distance along
    /// the ray), for one pixel: (0, window height per pixel at unit distance) for perspective,
    /// (pixel size, 0) for orthographic, (0, radians per pixel) for fisheye and
    /// equirectangular; per eye image for stereo.
    pub fn footprint(&self) -> (f32, f32) {
        self.footprint
    }

    /// The ray through image position (`x`, `y`) in pixels from the top-left corner. A position
    /// outside a fisheye's image circle has no ray ([`Camera::primary`] says `None`); this
    /// returns a ray looking straight back there.
    #[inline]
    pub fn ray(&self, x: f32, y: f32, width: u32, height: u32, time: f32) -> Ray {
        self.primary(x, y, width, height, time)
            .unwrap_or_else(|| Ray::new(self.origin, -self.forward, time))
    }

    /// The ray through image position (`x`, `y`) in pixels from the top-left corner, or `None`
    /// outside a fisheye's image circle (Tachyon draws those pixels black).
    #[inline]
    pub fn primary(&self, x: f32, y: f32, width: u32, height: u32, time: f32) -> Option<Ray> {
        if self.pinhole {
            // Step 1 alone, the same operations in the same order as below.
            let sx = 2.0 * x / width as f32 - 1.0;
            let sy = 1.0 - 2.0 * y / height as f32;
            let d = (self.centre + sx * self.right + sy * self.up).normalize();
            return Some(Ray::new(self.origin, d, time));
        }
        self.primary_general(x, y, width, height, time)
    }

    /// The rays through the image points (`xs[i]`, `ys[i]`) at times `times[i]`, into `out`
    /// (as long as `xs`): [`Camera::primary`]'s, bit for bit. A pinhole camera makes them
    /// [`BATCH`] at a time, lane by lane the operations of `primary`, so that their divisions
    /// and square roots overlap: made one by one just before each is traced, every ray waits
    /// on its own chain of them.
    pub fn primaries(
        &self,
        xs: &[f32],
        ys: &[f32],
        times: &[f32],
        (width, height): (u32, u32),
        out: &mut [Option<Ray>],
    ) {
        debug_assert!(xs.len() == ys.len() && xs.len() == times.len() && xs.len() == out.len());
        if !self.pinhole {
            for (((o, &x), &y), &t) in out.iter_mut().zip(xs).zip(ys).zip(times) {
                *o = self.primary(x, y, width, height, t);
            }
            return;
        }
        let chunks = xs.chunks(BATCH).zip(ys.chunks(BATCH));
        for ((x, y), (t, o)) in chunks.zip(times.chunks(BATCH).zip(out.chunks_mut(BATCH))) {
            let mut bx = [0.0; BATCH];
            let mut by = [0.0; BATCH];
            bx[..x.len()].copy_from_slice(x);
            by[..y.len()].copy_from_slice(y);
            let dirs = self.pinhole_dirs(&bx, &by, width, height);
            for ((o, &d), &t) in o.iter_mut().zip(&dirs).zip(t) {
                *o = Some(Ray::new(self.origin, d, t));
            }
        }
    }

    /// A pinhole camera's ray directions through [`BATCH`] image points: `primary`'s
    /// arithmetic per lane, in its order (glam's `dot` adds `(x² + y²) + z²`; `normalize`
    /// divides by the length), so every lane is bit for bit `primary`'s direction. Written
    /// with SSE, four lanes at a time: left to itself the compiler vectorizes each ray's
    /// x, y, z instead, one square root at a time.
    #[cfg(target_arch = "x86_64")]
    #[inline]
    fn pinhole_dirs(
        &self,
        x: &[f32; BATCH],
        y: &[f32; BATCH],
        width: u32,
        height: u32,
    ) -> [Vec3A; BATCH] {
        use std::arch::x86_64::*;
        let (w, h) = (width as f32, height as f32);
        let (c, r, u) = (self.centre, self.right, self.up);
        let mut out = [Vec3A::ZERO; BATCH];
        for (k, out) in out.chunks_exact_mut(4).enumerate() {
            // SAFETY: SSE is part of the x86_64 baseline; `x` and `y` hold BATCH floats and
            // the four at `4 * k` are in bounds (k < BATCH / 4); `d` holds 3 × 4 floats.
            unsafe {
                let s = |v: f32| _mm_set1_ps(v);
                let (xs, ys) = (
                    _mm_loadu_ps(x.as_ptr().add(4 * k)),
                    _mm_loadu_ps(y.as_ptr().add(4 * k)),
                );
                let sx = _mm_sub_ps(_mm_div_ps(_mm_mul_ps(s(2.0), xs), s(w)), s(1.0));
                let sy = _mm_sub_ps(s(1.0), _mm_div_ps(_mm_mul_ps(s(2.0), ys), s(h)));
                let axis = |c: f32, r: f32, u: f32| {
                    _mm_add_ps(_mm_add_ps(s(c), _mm_mul_ps(sx, s(r))), _mm_mul_ps(sy, s(u)))
                };
                let (dx, dy, dz) = (
                    axis(c.x, r.x, u.x),
                    axis(c.y, r.y, u.y),
                    axis(c.z, r.z, u.z),
                );
                let sq = |v| _mm_mul_ps(v, v);
                let len = _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(sq(dx), sq(dy)), sq(dz)));
                let mut d = [[0.0f32; 4]; 3];
                _mm_storeu_ps(d[0].as_mut_ptr(), _mm_div_ps(dx, len));
                _mm_storeu_ps(d[1].as_mut_ptr(), _mm_div_ps(dy, len));
                _mm_storeu_ps(d[2].as_mut_ptr(), _mm_div_ps(dz, len));
                for (l, o) in out.iter_mut().enumerate() {
                    *o = Vec3A::new(d[0][l], d[1][l], d[2][l]);
                }
            }
        }
        out
    }

    /// The same, lane by lane, for other targets.
    #[cfg(not(target_arch = "x86_64"))]
    #[inline]
    fn pinhole_dirs(
        &self,
        x: &[f32; BATCH],
        y: &[f32; BATCH],
        width: u32,
        height: u32,
    ) -> [Vec3A; BATCH] {
        let (w, h) = (width as f32, height as f32);
        std::array::from_fn(|i| {
            let sx = 2.0 * x[i] / w - 1.0;
            let sy = 1.0 - 2.0 * y[i] / h;
            (self.centre + sx * self.right + sy * self.up).normalize()
        })
    }

    /// [`Camera::primary`] for every camera.
    #[inline(never)]
    fn primary_general(&self, x: f32, y: f32, width: u32, height: u32, time: f32) -> Option<Ray> {
        // Which eye, and the position in its half of the image.
        let (mut w, mut h) = (width as f32, height as f32);
        let (mut ex, mut ey, mut eye) = (x, y, 0.0);
        if let Some(e) = &self.eyes {
            match e.layout {
                StereoLayout::SideBySide => {
                    w *= 0.5;
                    eye = if x < w { -1.0 } else { 1.0 };
                    if x >= w {
                        ex -= w;
                    }
                }
                StereoLayout::OverUnder => {
                    h *= 0.5;
                    eye = if y < h { -1.0 } else { 1.0 };
                    if y >= h {
                        ey -= h;
                    }
                }
            }
        }
        let sx = 2.0 * ex / w - 1.0;
        let sy = 1.0 - 2.0 * ey / h;

        // 1. The mono ray; `flat`: focus and convergence on planes (else on spheres).
        let (mut o, mut d, flat, eye_axis) = match self.kind {
            Kind::Perspective => {
                let d = (self.forward + self.shift + sx * self.right + sy * self.up).normalize();
                (self.origin, d, true, self.right_unit)
            }
            Kind::Orthographic => {
                let o = self.origin + self.shift + sx * self.right + sy * self.up;
                (o, self.forward, true, self.right_unit)
            }
            Kind::Fisheye { half_angle, aspect } => {
                let (fx, fy) = (sx * aspect, sy);
                let r = (fx * fx + fy * fy).sqrt();
                if r > 1.0 {
                    return None;
                }
                let (sin_t, cos_t) = (r * half_angle).sin_cos();
                let radial = if r > 0.0 {
                    (fx * self.right_unit + fy * self.up_unit) / r
                } else {
                    Vec3A::ZERO
                };
                let d = (cos_t * self.forward + sin_t * radial).normalize();
                (self.origin, d, false, self.right_unit)
            }
            Kind::Equirectangular {
                lon,
                lat,
                half_lon,
                half_lat,
            } => {
                let (sin_lon, cos_lon) = (lon + sx * half_lon).sin_cos();
                let (sin_lat, cos_lat) = (lat + sy * half_lat).sin_cos();
                let horizontal = sin_lon * self.right_unit + cos_lon * self.forward;
                let d = (cos_lat * horizontal + sin_lat * self.up_unit).normalize();
                let axis = cos_lon * self.right_unit - sin_lon * self.forward;
                (self.origin, d, false, axis)
            }
        };
        // Distance along `d` from `o` to the plane at depth `depth`, or to the sphere.
        let reach = |d: Vec3A, depth: f32| {
            if flat {
                depth / d.dot(self.forward)
            } else {
                depth
            }
        };

        // 2. The eye: shifted sideways, aimed at the mono ray's convergence point.
        if let Some(e) = &self.eyes {
            let target = o + d * reach(d, e.convergence);
            o += eye * e.half_separation * eye_axis;
            d = (target - o).normalize();
        }

        // 3. The lens: from a point of the aperture through the focal point.
        if let Some(lens) = &self.lens {
            let focus = o + d * reach(d, lens.focal_distance);
            let (a, b) = if flat {
                (self.right_unit, self.up_unit)
            } else {
                basis(d)
            };
            let u1 = to_unit(hash(x.to_bits(), y.to_bits(), time.to_bits(), 7));
            let u2 = to_unit(hash(x.to_bits(), y.to_bits(), time.to_bits(), 8));
            let (lx, ly) = concentric_disk(u1, u2);
            o += lens.radius * (lx * a + ly * b);
            d = (focus - o).normalize();
        }
        Some(Ray::new(o, d, time))
    }
}

/// [0, 1)² onto the unit disk, keeping strata compact (Shirley & Chiu's concentric mapping).
fn concentric_disk(u1: f32, u2: f32) -> (f32, f32) {
    let (a, b) = (2.0 * u1 - 1.0, 2.0 * u2 - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, phi) = if a.abs() > b.abs() {
        (a, FRAC_PI_4 * (b / a))
    } else {
        (b, FRAC_PI_2 - FRAC_PI_4 * (a / b))
    };
    let (s, c) = phi.sin_cos();
    (r * c, r * s)
}

/// Two unit vectors perpendicular to unit `n` and to each other (Duff et al. 2017).
fn basis(n: Vec3A) -> (Vec3A, Vec3A) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3A::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3A::new(b, sign + n.y * n.y * a, -n.y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use luxon_formats::{DepthOfField, Frustum, Stereo};
    use std::f32::consts::PI;

    const EPS: f32 = 1e-5;

    /// At the origin looking down −z, up +y: right is +x.
    fn desc(projection: Projection) -> CameraDesc {
        CameraDesc {
            position: [0.0, 0.0, 0.0],
            look_at: [0.0, 0.0, -1.0],
            up: [0.0, 1.0, 0.0],
            projection,
            aspect: None,
            frustum: None,
            depth_of_field: None,
            stereo: None,
        }
    }

    #[track_caller]
    fn close(a: Vec3A, b: Vec3A) {
        assert!((a - b).length() < EPS, "{a} != {b}");
    }

    #[test]
    fn centre_pixel_looks_forward_and_corners_span_the_fov() {
        let cam = Camera::new(
            &desc(Projection::Perspective { fov_deg: 90.0 }),
            Vec3A::ZERO,
            200,
            100,
        );
        let c = cam.ray(100.0, 50.0, 200, 100, 0.0);
        close(c.dir, Vec3A::new(0.0, 0.0, -1.0));
        // Top edge: 45 degrees up. Right edge: atan(2) to the right (aspect 2).
        let top = cam.ray(100.0, 0.0, 200, 100, 0.0);
        assert!((top.dir.y - (0.5f32).sqrt()).abs() < 1e-6);
        let right = cam.ray(200.0, 50.0, 200, 100, 0.0);
        assert!(right.dir.x > 0.0 && (right.dir.x / -right.dir.z - 2.0).abs() < 1e-5);
        // `up` is the window's half-height at unit distance (the scene's pixel spread).
        assert!((cam.up.length() - 1.0).abs() < EPS);
        assert_eq!(cam.footprint(), (0.0, 2.0 / 100.0));
    }

    #[test]
    fn pinhole_rays_are_the_general_formula_bit_for_bit() {
        let mut d = desc(Projection::PerspectiveZoom { zoom: 0.7 });
        d.position = [1.0, 2.0, -3.0];
        d.look_at = [0.3, -0.2, 0.9];
        d.up = [0.1, 1.0, 0.0];
        let plain = Camera::new(&d, Vec3A::new(0.5, -0.25, 2.0), 37, 23);
        d.frustum = Some(Frustum {
            left: -0.3,
            right: 0.7,
            bottom: -0.2,
            top: 0.45,
        });
        let off_centre = Camera::new(&d, Vec3A::ZERO, 37, 23);
        for cam in [plain, off_centre] {
            assert!(cam.pinhole);
            for y in 0..23 {
                for x in 0..37 {
                    let (px, py) = (x as f32 + 0.5, y as f32 + 0.25 * (x % 4) as f32);
                    let a = cam.primary(px, py, 37, 23, 0.5).unwrap();
                    let b = cam.primary_general(px, py, 37, 23, 0.5).unwrap();
                    assert_eq!(
                        a.origin.to_array().map(f32::to_bits),
                        b.origin.to_array().map(f32::to_bits)
                    );
                    assert_eq!(
                        a.dir.to_array().map(f32::to_bits),
                        b.dir.to_array().map(f32::to_bits)
                    );
                    assert_eq!(a.time.to_bits(), b.time.to_bits());
                }
            }
        }
        // Stereo, a lens and the other projections take the general path.
        let s = stereo(
            Projection::Perspective { fov_deg: 60.0 },
            StereoLayout::SideBySide,
        );
        assert!(!Camera::new(&s, Vec3A::ZERO, 20, 10).pinhole);
        let o = desc(Projection::Orthographic { height: 2.0 });
        assert!(!Camera::new(&o, Vec3A::ZERO, 20, 10).pinhole);
    }

    #[test]
    fn batched_rays_are_primary_bit_for_bit() {
        let mut d = desc(Projection::PerspectiveZoom { zoom: 0.7 });
        d.position = [1.0, 2.0, -3.0];
        d.look_at = [0.3, -0.2, 0.9];
        d.up = [0.1, 1.0, 0.0];
        let pinhole = Camera::new(&d, Vec3A::new(0.5, -0.25, 2.0), 37, 23);
        let fisheye = Camera::new(
            &desc(Projection::Fisheye { fov_deg: 180.0 }),
            Vec3A::ZERO,
            37,
            23,
        );
        let lens = {
            let mut l = desc(Projection::Perspective { fov_deg: 50.0 });
            l.depth_of_field = Some(DepthOfField {
                aperture: 0.1,
                focal_distance: 3.0,
            });
            Camera::new(&l, Vec3A::ZERO, 37, 23)
        };
        assert!(pinhole.pinhole && !fisheye.pinhole && !lens.pinhole);
        // Jittered points, the image's edges and beyond it, in counts that do and do not fill
        // the last batch.
        let points: Vec<(f32, f32, f32)> = (0..37 * 23 + 3)
            .map(|k| {
                let (x, y) = ((k % 41) as f32 - 2.0, (k / 41) as f32 - 1.0);
                let j = (k as f32 * 0.618_034).fract();
                (x + j, y + 1.0 - j, 0.25 * (k % 3) as f32)
            })
            .collect();
        for cam in [pinhole, fisheye, lens] {
            for n in [1, 7, 8, 9, 16, points.len()] {
                let p = &points[..n];
                let xs: Vec<f32> = p.iter().map(|q| q.0).collect();
                let ys: Vec<f32> = p.iter().map(|q| q.1).collect();
                let ts: Vec<f32> = p.iter().map(|q| q.2).collect();
                let mut out = vec![None; n];
                cam.primaries(&xs, &ys, &ts, (37, 23), &mut out);
                let bits = |r: Option<Ray>| {
                    r.map(|r| {
                        let (o, d) = (r.origin.to_array(), r.dir.to_array());
                        (o.map(f32::to_bits), d.map(f32::to_bits), r.time.to_bits())
                    })
                };
                for (q, ray) in p.iter().zip(&out) {
                    let want = cam.primary(q.0, q.1, 37, 23, q.2);
                    assert_eq!(bits(*ray), bits(want), "{q:?} of {n}");
                }
            }
        }
    }

    #[test]
    fn perspective_frustum_sets_an_off_centre_window_at_unit_distance() {
        let mut d = desc(Projection::Perspective { fov_deg: 45.0 });
        d.frustum = Some(Frustum {
            left: 0.0,
            right: 1.0,
            bottom: -0.25,
            top: 0.5,
        });
        let cam = Camera::new(&d, Vec3A::ZERO, 100, 50);
        // Top-left corner: (left, top) at unit distance; bottom-right: (right, bottom).
        let tl = cam.ray(0.0, 0.0, 100, 50, 0.0);
        close(tl.dir, Vec3A::new(0.0, 0.5, -1.0).normalize());
        let br = cam.ray(100.0, 50.0, 100, 50, 0.0);
        close(br.dir, Vec3A::new(1.0, -0.25, -1.0).normalize());
        let centre = cam.ray(50.0, 25.0, 100, 50, 0.0);
        close(centre.dir, Vec3A::new(0.5, 0.125, -1.0).normalize());
        assert!((cam.up.length() - 0.375).abs() < EPS);
    }

    #[test]
    fn orthographic_rays_are_parallel_and_spread_over_the_window() {
        let cam = Camera::new(
            &desc(Projection::Orthographic { height: 4.0 }),
            Vec3A::ZERO,
            200,
            100,
        );
        let forward = Vec3A::new(0.0, 0.0, -1.0);
        for (x, y, ox, oy) in [
            (100.0, 50.0, 0.0, 0.0),
            (0.0, 0.0, -4.0, 2.0),
            (200.0, 100.0, 4.0, -2.0),
            (150.0, 25.0, 2.0, 1.0),
        ] {
            let r = cam.ray(x, y, 200, 100, 0.0);
            close(r.dir, forward);
            close(r.origin, Vec3A::new(ox, oy, 0.0));
        }
        assert_eq!(cam.footprint(), (4.0 / 100.0, 0.0));
    }

    #[test]
    fn orthographic_frustum_is_in_world_units() {
        let mut d = desc(Projection::Orthographic { height: 4.0 });
        d.frustum = Some(Frustum {
            left: -1.0,
            right: 3.0,
            bottom: 0.0,
            top: 2.0,
        });
        let cam = Camera::new(&d, Vec3A::new(0.0, 0.0, 1.0), 100, 100);
        close(
            cam.ray(0.0, 0.0, 100, 100, 0.0).origin,
            Vec3A::new(-1.0, 2.0, 1.0),
        );
        close(
            cam.ray(100.0, 100.0, 100, 100, 0.0).origin,
            Vec3A::new(3.0, 0.0, 1.0),
        );
    }

    #[test]
    fn fisheye_centre_is_forward_and_circle_edge_is_half_the_fov() {
        let cam = Camera::new(
            &desc(Projection::Fisheye { fov_deg: 180.0 }),
            Vec3A::ZERO,
            200,
            100,
        );
        close(
            cam.ray(100.0, 50.0, 200, 100, 0.0).dir,
            Vec3A::new(0.0, 0.0, -1.0),
        );
        // The circle's radius is half the image height: 90° there.
        close(
            cam.ray(100.0, 0.0, 200, 100, 0.0).dir,
            Vec3A::new(0.0, 1.0, 0.0),
        );
        close(
            cam.ray(150.0, 50.0, 200, 100, 0.0).dir,
            Vec3A::new(1.0, 0.0, 0.0),
        );
        // Halfway to the edge: 45° (equidistant), along the diagonal too.
        let h = 25.0 / 2f32.sqrt();
        let r = cam.ray(100.0 - h, 50.0 + h, 200, 100, 0.0);
        close(r.dir, Vec3A::new(-0.5, -0.5, -(0.5f32).sqrt()));
        // Outside the circle: no ray.
        assert!(cam.primary(160.0, 50.0, 200, 100, 0.0).is_none());
        assert!(cam.primary(0.0, 0.0, 200, 100, 0.0).is_none());
        close(
            cam.ray(0.0, 0.0, 200, 100, 0.0).dir,
            Vec3A::new(0.0, 0.0, 1.0),
        );
        assert!((cam.footprint().1 - PI / 100.0).abs() < EPS);
    }

    #[test]
    fn fisheye_360_edge_looks_back() {
        let cam = Camera::new(
            &desc(Projection::Fisheye { fov_deg: 360.0 }),
            Vec3A::ZERO,
            100,
            100,
        );
        let r = cam.primary(50.0, 0.0, 100, 100, 0.0).unwrap();
        close(r.dir, Vec3A::new(0.0, 0.0, 1.0));
        let r = cam.primary(75.0, 50.0, 100, 100, 0.0).unwrap();
        close(r.dir, Vec3A::new(1.0, 0.0, 0.0));
    }

    #[test]
    fn equirectangular_spans_the_sphere() {
        let cam = Camera::new(&desc(Projection::Equirectangular), Vec3A::ZERO, 360, 180);
        let at = |x: f32, y: f32| cam.ray(x, y, 360, 180, 0.0).dir;
        close(at(180.0, 90.0), Vec3A::new(0.0, 0.0, -1.0));
        // Left edge: −180° (behind); a quarter in: −90° (left); right edge: +180°.
        close(at(0.0, 90.0), Vec3A::new(0.0, 0.0, 1.0));
        close(at(90.0, 90.0), Vec3A::new(-1.0, 0.0, 0.0));
        close(at(270.0, 90.0), Vec3A::new(1.0, 0.0, 0.0));
        close(at(360.0, 90.0), Vec3A::new(0.0, 0.0, 1.0));
        // Top: straight up; bottom: straight down; 45° up ahead.
        close(at(123.0, 0.0), Vec3A::new(0.0, 1.0, 0.0));
        close(at(17.0, 180.0), Vec3A::new(0.0, -1.0, 0.0));
        close(at(180.0, 45.0), Vec3A::new(0.0, 1.0, -1.0).normalize());
        assert!((cam.footprint().1 - PI / 180.0).abs() < EPS);
    }

    #[test]
    fn equirectangular_frustum_is_a_window_in_degrees() {
        let mut d = desc(Projection::Equirectangular);
        d.frustum = Some(Frustum {
            left: -90.0,
            right: 30.0,
            bottom: -20.0,
            top: 40.0,
        });
        let cam = Camera::new(&d, Vec3A::ZERO, 120, 60);
        let at = |x: f32, y: f32| cam.ray(x, y, 120, 60, 0.0).dir;
        // Longitude `lon`, latitude `lat` (degrees) around −z, +x at +90°.
        let dir = |lon: f32, lat: f32| {
            let (lon, lat) = (lon.to_radians(), lat.to_radians());
            Vec3A::new(lat.cos() * lon.sin(), lat.sin(), -lat.cos() * lon.cos())
        };
        close(at(0.0, 60.0), dir(-90.0, -20.0));
        close(at(120.0, 0.0), dir(30.0, 40.0));
        close(at(60.0, 30.0), dir(-30.0, 10.0));
        close(at(90.0, 60.0), dir(0.0, -20.0));
        // One degree per pixel.
        assert!((cam.footprint().1 - 1f32.to_radians()).abs() < EPS);
        // The whole sphere as a frustum is the plain panorama, ray for ray.
        d.frustum = Some(Frustum {
            left: -180.0,
            right: 180.0,
            bottom: -90.0,
            top: 90.0,
        });
        let window = Camera::new(&d, Vec3A::ZERO, 36, 18);
        let plain = Camera::new(&desc(Projection::Equirectangular), Vec3A::ZERO, 36, 18);
        for (x, y) in [(0.5, 0.5), (7.25, 3.0), (35.5, 17.5)] {
            let (a, b) = (window.ray(x, y, 36, 18, 0.0), plain.ray(x, y, 36, 18, 0.0));
            assert_eq!((a.origin, a.dir), (b.origin, b.dir));
        }
    }

    fn stereo(projection: Projection, layout: StereoLayout) -> CameraDesc {
        let mut d = desc(projection);
        d.stereo = Some(Stereo {
            layout,
            eye_separation: 0.2,
            convergence: 5.0,
        });
        d
    }

    #[test]
    fn stereo_side_by_side_left_half_is_the_left_eye() {
        let d = stereo(
            Projection::Perspective { fov_deg: 90.0 },
            StereoLayout::SideBySide,
        );
        // Each eye is 100 × 100: aspect 1.
        let cam = Camera::new(&d, Vec3A::ZERO, 200, 100);
        let left = cam.ray(50.0, 50.0, 200, 100, 0.0);
        let right = cam.ray(150.0, 50.0, 200, 100, 0.0);
        close(left.origin, Vec3A::new(-0.1, 0.0, 0.0));
        close(right.origin, Vec3A::new(0.1, 0.0, 0.0));
        // Both centre rays meet on the convergence plane, 5 ahead.
        let converge = Vec3A::new(0.0, 0.0, -5.0);
        close(left.dir, (converge - left.origin).normalize());
        close(right.dir, (converge - right.origin).normalize());
        // The same pixel of each eye meets the convergence plane at one point, which the mono
        // camera sees at that pixel (off-axis frusta: zero parallax there).
        let mono = Camera::new(
            &desc(Projection::Perspective { fov_deg: 90.0 }),
            Vec3A::ZERO,
            100,
            100,
        );
        let m = mono.ray(80.0, 10.0, 100, 100, 0.0);
        let p = m.at(5.0 / -m.dir.z);
        for r in [
            cam.ray(80.0, 10.0, 200, 100, 0.0),
            cam.ray(180.0, 10.0, 200, 100, 0.0),
        ] {
            close(r.at((p.z - r.origin.z) / r.dir.z), p);
        }
        assert!((cam.up.length() - 1.0).abs() < EPS);
        assert!((cam.right.length() - 1.0).abs() < EPS);
    }

    #[test]
    fn stereo_over_under_top_half_is_the_left_eye() {
        let d = stereo(
            Projection::Orthographic { height: 2.0 },
            StereoLayout::OverUnder,
        );
        let cam = Camera::new(&d, Vec3A::ZERO, 100, 200);
        let top = cam.ray(50.0, 50.0, 100, 200, 0.0);
        let bottom = cam.ray(50.0, 150.0, 100, 200, 0.0);
        close(top.origin, Vec3A::new(-0.1, 0.0, 0.0));
        close(bottom.origin, Vec3A::new(0.1, 0.0, 0.0));
        close(top.dir, Vec3A::new(0.1, 0.0, -5.0).normalize());
        close(bottom.dir, Vec3A::new(-0.1, 0.0, -5.0).normalize());
        // Each eye's window is 2 × 2 (aspect 1): the top-left corner of the bottom half.
        let r = cam.ray(0.0, 100.0, 100, 200, 0.0);
        close(r.origin, Vec3A::new(-1.0 + 0.1, 1.0, 0.0));
        assert_eq!(cam.footprint(), (2.0 / 100.0, 0.0));
    }

    #[test]
    fn stereo_equirectangular_shifts_eyes_across_each_direction() {
        let d = stereo(Projection::Equirectangular, StereoLayout::OverUnder);
        let cam = Camera::new(&d, Vec3A::ZERO, 360, 360);
        // Top half: left eye. Each eye sits half the separation along the right of the
        // direction it looks in (view × up), and aims at the convergence sphere.
        for (x, y, eye) in [(270.0, 90.0, -1.0), (270.0, 270.0, 1.0), (90.0, 90.0, -1.0)] {
            let r = cam.ray(x, y, 360, 360, 0.0);
            let (sin_lon, cos_lon) = ((x / 180.0 - 1.0) * PI).sin_cos();
            let view = Vec3A::new(sin_lon, 0.0, -cos_lon);
            let right_of_view = view.cross(Vec3A::Y);
            close(r.origin, eye * 0.1 * right_of_view);
            close(r.dir, (5.0 * view - r.origin).normalize());
        }
    }

    #[test]
    fn depth_of_field_rays_meet_on_the_focal_plane() {
        let mut d = desc(Projection::Perspective { fov_deg: 60.0 });
        d.depth_of_field = Some(DepthOfField {
            aperture: 0.5,
            focal_distance: 4.0,
        });
        let cam = Camera::new(&d, Vec3A::ZERO, 64, 48);
        let pin = Camera::new(
            &desc(Projection::Perspective { fov_deg: 60.0 }),
            Vec3A::ZERO,
            64,
            48,
        );
        let (px, py) = (20.25f32, 7.5f32);
        let p = pin.ray(px, py, 64, 48, 0.0);
        let focus = p.at(4.0 / -p.dir.z);
        let mut origins = Vec::new();
        for i in 0..16 {
            // Sub-pixel offsets and times give different lens points for the same pixel.
            let r = cam.ray(px, py, 64, 48, i as f32 * 0.01);
            close(r.at((focus.z - r.origin.z) / r.dir.z), focus);
            assert!(r.origin.z == 0.0 && r.origin.length() <= 0.5 + EPS);
            origins.push(r.origin);
        }
        assert!(origins.windows(2).all(|w| w[0] != w[1]));
        // Deterministic: the same sample gives the same ray.
        let (a, b) = (
            cam.ray(3.3, 4.4, 64, 48, 0.5),
            cam.ray(3.3, 4.4, 64, 48, 0.5),
        );
        assert_eq!((a.origin, a.dir), (b.origin, b.dir));
    }

    #[test]
    fn depth_of_field_on_a_fisheye_focuses_on_a_sphere() {
        let mut d = desc(Projection::Fisheye { fov_deg: 180.0 });
        d.depth_of_field = Some(DepthOfField {
            aperture: 0.3,
            focal_distance: 2.0,
        });
        let cam = Camera::new(&d, Vec3A::ZERO, 100, 100);
        let pin = Camera::new(
            &desc(Projection::Fisheye { fov_deg: 180.0 }),
            Vec3A::ZERO,
            100,
            100,
        );
        let p = pin.ray(80.0, 30.0, 100, 100, 0.0);
        let focus = p.at(2.0);
        for i in 0..8 {
            let r = cam.ray(80.0, 30.0, 100, 100, i as f32);
            // The lens lies across the pinhole ray.
            assert!(r.origin.dot(p.dir).abs() < EPS && r.origin.length() <= 0.3 + EPS);
            let t = (focus - r.origin).dot(r.dir);
            close(r.at(t), focus);
        }
    }

    #[test]
    fn zero_aperture_is_the_pinhole_camera() {
        let mut d = desc(Projection::Perspective { fov_deg: 50.0 });
        d.depth_of_field = Some(DepthOfField {
            aperture: 0.0,
            focal_distance: 3.0,
        });
        let cam = Camera::new(&d, Vec3A::ZERO, 40, 30);
        let pin = Camera::new(
            &desc(Projection::Perspective { fov_deg: 50.0 }),
            Vec3A::ZERO,
            40,
            30,
        );
        for (x, y) in [(0.0, 0.0), (12.3, 4.5), (39.9, 29.9)] {
            let (a, b) = (cam.ray(x, y, 40, 30, 0.0), pin.ray(x, y, 40, 30, 0.0));
            assert_eq!((a.origin, a.dir), (b.origin, b.dir));
        }
    }

    #[test]
    fn concentric_disk_stays_inside_and_reaches_the_rim() {
        for i in 0..=20 {
            for j in 0..=20 {
                let (x, y) = concentric_disk(i as f32 / 20.0, j as f32 / 20.0);
                assert!(x * x + y * y <= 1.0 + 1e-6);
            }
        }
        let (x, y) = concentric_disk(1.0, 0.5);
        assert!((x - 1.0).abs() < 1e-6 && y.abs() < 1e-6);
        assert_eq!(concentric_disk(0.5, 0.5), (0.0, 0.0));
    }

    #[test]
    fn basis_is_orthonormal() {
        for n in [
            Vec3A::X,
            Vec3A::Y,
            Vec3A::Z,
            -Vec3A::Z,
            Vec3A::new(1.0, -2.0, 0.5).normalize(),
        ] {
            let (a, b) = basis(n);
            assert!(a.dot(b).abs() < EPS && a.dot(n).abs() < EPS && b.dot(n).abs() < EPS);
            assert!((a.length() - 1.0).abs() < EPS && (b.length() - 1.0).abs() < EPS);
        }
    }
}
