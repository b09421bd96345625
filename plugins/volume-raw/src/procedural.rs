//! Volumes computed from formulas, for tests, examples and scenes that ship no data:
//! `phantom` (a CT head phantom of ellipsoids) and `vortex` (the vorticity of two vortex rings).

use luxon_plugin::{invalid, Context, Describe, Error, GridInfo, VolumeOut, VolumeReader};
use serde::Deserialize;

/// The grid shared by both: `size`³ voxels filling the cube [-1, 1]³ (voxel centres half a
/// voxel inside its faces), filled by `f(x, y, z)` in world coordinates.
fn fill(
    size: u64,
    name: &str,
    out: &mut VolumeOut,
    f: impl Fn(f64, f64, f64) -> f32,
) -> Result<(), Error> {
    if !(2..=512).contains(&size) {
        return Err(invalid(format!(
            "parameter `size` is {size}; expected 2 to 512 voxels per axis"
        )));
    }
    let h = 2.0 / size as f64;
    let o = -1.0 + 0.5 * h;
    let n = size as i64 - 1;
    out.begin(&GridInfo {
        world_from_index: [h, 0.0, 0.0, o, 0.0, h, 0.0, o, 0.0, 0.0, h, o],
        background: 0.0,
        index_min: [0; 3],
        index_max: [n; 3],
        name: name.to_string(),
    })?;
    // One slab of 8 z-slices at a time (whole bricks).
    let mut values = Vec::new();
    for z0 in (0..size).step_by(8) {
        let dz = 8.min(size - z0);
        values.clear();
        for z in z0..z0 + dz {
            for y in 0..size {
                for x in 0..size {
                    let p = |i: u64| o + i as f64 * h;
                    values.push(f(p(x), p(y), p(z)));
                }
            }
        }
        out.dense([0, 0, z0 as i64], [size, size, dz], &values)?;
    }
    Ok(())
}

fn default_size() -> u64 {
    64
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct SizeParams {
    #[serde(default = "default_size")]
    size: u64,
}

/// A 3-D head phantom after Shepp and Logan: ellipsoids whose densities add (Toft's modified
/// intensities for contrast): skull 1, brain 0.2, ventricles 0, small features 0.3.
pub struct Phantom;

/// (centre, semi-axes, rotation about z in degrees, added density).
#[allow(clippy::type_complexity)]
const ELLIPSOIDS: [([f64; 3], [f64; 3], f64, f64); 10] = [
    ([0.0, 0.0, 0.0], [0.69, 0.92, 0.81], 0.0, 1.0),
    ([0.0, -0.0184, 0.0], [0.6624, 0.874, 0.78], 0.0, -0.8),
    ([0.22, 0.0, 0.0], [0.11, 0.31, 0.22], -18.0, -0.2),
    ([-0.22, 0.0, 0.0], [0.16, 0.41, 0.28], 18.0, -0.2),
    ([0.0, 0.35, -0.15], [0.21, 0.25, 0.41], 0.0, 0.1),
    ([0.0, 0.1, 0.25], [0.046, 0.046, 0.05], 0.0, 0.1),
    ([0.0, -0.1, 0.25], [0.046, 0.046, 0.05], 0.0, 0.1),
    ([-0.08, -0.605, 0.0], [0.046, 0.023, 0.05], 0.0, 0.1),
    ([0.0, -0.606, 0.0], [0.023, 0.023, 0.02], 0.0, 0.1),
    ([0.06, -0.605, 0.0], [0.023, 0.046, 0.02], 0.0, 0.1),
];

/// The phantom's density at (x, y, z).
pub fn phantom_density(x: f64, y: f64, z: f64) -> f32 {
    let mut d = 0.0;
    for (c, a, deg, rho) in ELLIPSOIDS {
        let (s, co) = deg.to_radians().sin_cos();
        let (px, py, pz) = (x - c[0], y - c[1], z - c[2]);
        let (u, v) = (co * px + s * py, -s * px + co * py);
        if (u / a[0]).powi(2) + (v / a[1]).powi(2) + (pz / a[2]).powi(2) <= 1.0 {
            d += rho;
        }
    }
    d as f32
}

impl Describe for Phantom {
    const NAME: &'static str = "phantom";
    const DESCRIPTION: &'static str =
        "A 3-D Shepp-Logan-like CT head phantom (ellipsoids) filling [-1, 1]^3.";
    const PARAMS: &'static str = "size: u64 = 64  voxels per axis (2 to 512)";
}

impl VolumeReader for Phantom {
    type Params = SizeParams;

    fn read(p: SizeParams, _ctx: &Context, out: &mut VolumeOut) -> Result<(), Error> {
        fill(p.size, "phantom", out, phantom_density)
    }
}

/// Vorticity magnitude of two coaxial vortex rings with Gaussian cores (a wavy one below, a
/// smaller one above, as in leapfrogging rings), normalised to at most 1.
pub struct Vortex;

/// The vortex field at (x, y, z).
pub fn vortex_vorticity(x: f64, y: f64, z: f64) -> f32 {
    let ring = |radius: f64, height: f64, core: f64, waves: f64| {
        let r = (x * x + y * y).sqrt();
        let theta = y.atan2(x);
        // A ring whose radius and height ripple around it (a Widnall-type instability).
        let rr = radius * (1.0 + 0.06 * (waves * theta).sin());
        let hh = height + 0.05 * (waves * theta).cos();
        let d2 = (r - rr).powi(2) + (z - hh).powi(2);
        (-d2 / (core * core)).exp()
    };
    let w = ring(0.55, -0.25, 0.13, 5.0) + 0.8 * ring(0.38, 0.3, 0.1, 4.0);
    w.min(1.0) as f32
}

impl Describe for Vortex {
    const NAME: &'static str = "vortex";
    const DESCRIPTION: &'static str =
        "Vorticity magnitude of two coaxial vortex rings (Gaussian cores) filling [-1, 1]^3.";
    const PARAMS: &'static str = "size: u64 = 64  voxels per axis (2 to 512)";
}

impl VolumeReader for Vortex {
    type Params = SizeParams;

    fn read(p: SizeParams, _ctx: &Context, out: &mut VolumeOut) -> Result<(), Error> {
        fill(p.size, "vortex", out, vortex_vorticity)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phantom_layers() {
        // Centre of the brain between the ventricles, inside the skull, outside.
        assert!((phantom_density(0.0, -0.3, 0.0) - 0.2).abs() < 1e-6);
        assert!((phantom_density(0.0, 0.9, 0.0) - 1.0).abs() < 1e-6);
        assert_eq!(phantom_density(0.0, 0.99, 0.0), 0.0);
        assert!((phantom_density(0.22, 0.0, 0.0) - 0.0).abs() < 1e-6);
    }

    #[test]
    fn vortex_peaks_on_the_cores() {
        assert!(vortex_vorticity(0.55, 0.0, -0.25 + 0.05) > 0.9);
        assert!(vortex_vorticity(0.0, 0.0, 0.0) < 1e-3);
    }
}
