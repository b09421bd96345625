//! # {{package}}: the `{{name}}` volume reader
//!
//! Computes a soft ball of density: 1 at the centre of the cube [-1, 1]³, falling to 0 at
//! distance 1. Change `read` into a reader of your own format: open `ctx.resolve(file)` and
//! hand its voxels over the same way.
//!
//! ## `{{name}}`
//! ```text
//! size: u64 = 32  voxels along each axis, 2 to 256
//! ```
//!
//! ```text
//! volumes: [(plugin: "{{name}}", params: (size: 32), render: (transfer: (preset: "hot", range: (0, 1), opacity: 8)))],
//! ```

#![forbid(unsafe_code)]

use luxon_plugin::{export, invalid, Context, Describe, Error, GridInfo, VolumeOut, VolumeReader};
use serde::Deserialize;

/// The volume's `params: (...)`. Fields left out take the defaults below; an unknown field is
/// an error that suggests the closest name.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct {{Name}}Params {
    pub size: u64,
}

impl Default for {{Name}}Params {
    fn default() -> Self {
        Self { size: 32 }
    }
}

/// The plugin entry: `read` is called once per volume of a scene.
pub struct {{Name}}Volume;

impl Describe for {{Name}}Volume {
    const NAME: &'static str = "{{name}}";
    const DESCRIPTION: &'static str = "A soft ball of density in the cube [-1, 1]³.";
    const PARAMS: &'static str = "size: u64 = 32  voxels along each axis, 2 to 256";
}

impl VolumeReader for {{Name}}Volume {
    type Params = {{Name}}Params;

    /// Describes the grid (`begin`), then streams its voxels as blocks, here one z-slice at a
    /// time. An error stops the scene from loading, with the message.
    fn read(p: Self::Params, ctx: &Context, out: &mut VolumeOut) -> Result<(), Error> {
        if !(2..=256).contains(&p.size) {
            // "parameter `size`..." first: Luxon reports it at `size:` in the scene.
            let message = format!("parameter `size`: expected 2 to 256, found {}", p.size);
            return Err(invalid(message));
        }
        let n = p.size;
        // Voxel (i, j, k) sits at -1 + i * step (and so on): the index box fills [-1, 1]³.
        let step = 2.0 / (n - 1) as f64;
        out.begin(&GridInfo {
            world_from_index: [
                step, 0.0, 0.0, -1.0, //
                0.0, step, 0.0, -1.0, //
                0.0, 0.0, step, -1.0,
            ],
            background: 0.0,
            index_min: [0; 3],
            index_max: [n as i64 - 1; 3],
            name: "{{name}}".into(),
        })?;
        // Big buffers come from `alloc_vec`: it keeps to the memory budget Luxon gives the call.
        let mut slice = ctx.alloc_vec((n * n) as usize, 0f32, "a slice of the volume")?;
        let at = |i: u64| -1.0 + i as f64 * step;
        for k in 0..n {
            for (index, value) in slice.iter_mut().enumerate() {
                let (i, j) = (index as u64 % n, index as u64 / n);
                let r = (at(i).powi(2) + at(j).powi(2) + at(k).powi(2)).sqrt();
                *value = (1.0 - r).clamp(0.0, 1.0) as f32;
            }
            // x fastest, then y: the layout of every dense block.
            out.dense([0, 0, k as i64], [n, n, 1], &slice)?;
        }
        Ok(())
    }
}

export!(library: "{{package}}", volume_readers: [{{Name}}Volume]);
