//! # {{package}}: the `{{name}}` image writer
//!
//! Writes PFM (Portable FloatMap): linear RGB as 32-bit floats, what HDR tools read without a
//! library. Change `write` into your own format.
//!
//! ## `{{name}}` (`.pfm`)
//! ```text
//! exposure: f64 = 0  stops to brighten (> 0) or darken (< 0) the image by
//! ```
//!
//! ```text
//! render: (outputs: [(path: "image.pfm", plugin: "{{name}}", params: (exposure: 0))]),
//! ```
//! An output without `plugin` finds its writer by the file's extension (`.pfm` here).

#![forbid(unsafe_code)]

use luxon_plugin::{export, invalid, Context, Describe, Error, Image, Writer};
use serde::Deserialize;

/// The output's `params: (...)`. Fields left out take the defaults below; an unknown field is
/// an error that suggests the closest name.
#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct {{Name}}Params {
    pub exposure: f64,
}

/// The plugin entry: called once per image written.
pub struct {{Name}}Writer;

impl Describe for {{Name}}Writer {
    const NAME: &'static str = "{{name}}";
    const DESCRIPTION: &'static str = "PFM (Portable FloatMap): linear RGB floats.";
    const PARAMS: &'static str =
        "exposure: f64 = 0  stops to brighten (> 0) or darken (< 0) the image by";
}

impl Writer for {{Name}}Writer {
    /// The file extensions (without dots, comma-separated) this writer is chosen for.
    const EXTENSIONS: &'static str = "pfm";
    type Params = {{Name}}Params;

    /// `image` holds linear RGBA floats, rows from the top; what is written to `out` becomes
    /// the file (Luxon writes it whole or not at all).
    fn write(
        p: Self::Params,
        _ctx: &Context,
        image: &Image,
        out: &mut dyn std::io::Write,
    ) -> Result<(), Error> {
        let exposure = p.exposure;
        if !exposure.is_finite() {
            // "parameter `exposure`..." first: Luxon reports it at `exposure:` in the scene.
            let message =
                format!("parameter `exposure`: expected a finite number, found {exposure}");
            return Err(invalid(message));
        }
        let gain = 2f32.powf(exposure as f32);
        // "PF": RGB; a negative scale: little-endian floats.
        write!(out, "PF\n{} {}\n-1.0\n", image.width, image.height)?;
        let width = image.width as usize;
        let mut row = Vec::with_capacity(width * 12);
        // PFM stores the rows from the bottom up.
        for y in (0..image.height as usize).rev() {
            row.clear();
            for pixel in image.rgba[y * width * 4..(y + 1) * width * 4].chunks_exact(4) {
                for channel in &pixel[..3] {
                    row.extend_from_slice(&(channel * gain).to_le_bytes());
                }
            }
            out.write_all(&row)?;
        }
        Ok(())
    }
}

export!(library: "{{package}}", writers: [{{Name}}Writer]);
