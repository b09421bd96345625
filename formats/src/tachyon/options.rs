//! What Tachyon's command line changes in a scene (`luxon tachyon` passes these): each
//! option overrides the scene's own setting after the whole file is read, as Tachyon's
//! `postsceneoptions` does, and is then mapped like the statement it replaces (so a feature
//! Luxon does not render yet gets the same one warning as in a scene file).

use super::syntax::ShadeLevel;
use crate::origin::Origin;

/// The default of [`Options::max_text`].
pub(super) const MAX_TEXT: u64 = 1 << 30;

/// Tachyon's highlight formulas (`-shade_*`): a global choice in Tachyon.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Highlights {
    /// `-shade_phong`.
    Phong,
    /// `-shade_blinn` (Tachyon's default).
    Blinn,
    /// `-shade_blinn_fast`: Tachyon's cheaper approximation of Blinn's highlight.
    BlinnFast,
    /// `-shade_nullphong`: no highlights.
    None,
}

/// Ambient occlusion from the command line: `-auto_skylight f` or `-add_skylight f`, with
/// `-skylight_samples n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Skylight {
    /// The sky's grey level `f` (AO colour (f, f, f)).
    pub level: f64,
    pub samples: u32,
    /// `-auto_skylight`: direct light scaled by max(0, 1 − f) to compensate.
    pub rescale: bool,
}

/// Command-line overrides; `None` (or `false`): the scene's own setting.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// `-res x y`.
    pub resolution: Option<[u32; 2]>,
    /// `-aasamples n`: ANTIALIASING n (also turns the depth-of-field lens on or off).
    pub antialiasing: Option<u32>,
    /// `-raydepth n`.
    pub raydepth: Option<u32>,
    /// `-fullshade`, `-mediumshade`, `-lowshade`, `-lowestshade`.
    pub shade: Option<ShadeLevel>,
    /// `-trans_orig`, `-trans_raster3d`, `-trans_vmd`: the flags (vmd, raster3d) replacing the
    /// scene's (`-trans_orig` clears both, the others add theirs, as in Tachyon).
    pub transparency: Option<(bool, bool)>,
    /// `-trans_max_surfaces n`.
    pub max_surfaces: Option<u32>,
    /// `-shadow_filter_on` / `-shadow_filter_off`.
    pub shadow_filter: Option<bool>,
    /// `-fog_vmd` (true) / `-fog_radial`, `-fog_normal` (false).
    pub fog_vmd: Option<bool>,
    /// `-shade_phong`, `-shade_blinn`, `-shade_blinn_fast`, `-shade_nullphong`.
    pub highlights: Option<Highlights>,
    /// `-rescale_lights f`: the direct light scale (Tachyon uses factors below 1 only; it
    /// replaces a scene's RESCALE_DIRECT).
    pub light_scale: Option<f64>,
    /// `-auto_skylight` / `-add_skylight` (the first wins when both are given, as in Tachyon).
    pub skylight: Option<Skylight>,
    /// Bytes of text the scene's files may hold together (the scene, its INCLUDEs and
    /// `.tpoly` files): the syntax tree and the scene grow with it. Default: 1 GiB (VMD writes
    /// big scenes, but a gigabyte of text is far beyond any); the core sets it from the memory
    /// budget. It also stops a sparse file or a device from being read without end.
    pub max_text: u64,
    /// Where the options come from, for the warnings about them.
    pub at: Origin,
}

impl Options {
    /// No overrides; `at` names the command line in warnings.
    pub fn new(at: Origin) -> Options {
        Options {
            resolution: None,
            antialiasing: None,
            raydepth: None,
            shade: None,
            transparency: None,
            max_surfaces: None,
            shadow_filter: None,
            fog_vmd: None,
            highlights: None,
            light_scale: None,
            skylight: None,
            max_text: MAX_TEXT,
            at,
        }
    }
}
