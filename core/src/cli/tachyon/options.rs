//! What Luxon does with each of Tachyon's options: [`apply`] is the table. Options that change
//! the scene go into the importer's [`Options`] (it maps them as the scene statements they
//! stand for, and warns once where Luxon does not render a feature as Tachyon does yet);
//! the others set the render, the output or the run. An option Luxon cannot honour yet is
//! [`Support::Ignored`] here, and warned about once.

use super::args::{usage, Arg};
use luxon::Error;
use luxon_formats::tachyon::{Highlights, Options, ShadeLevel, Skylight};
use luxon_formats::Origin;
use std::ffi::OsString;
use std::path::PathBuf;

/// How well Luxon honours an option.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Support {
    /// As Tachyon does (or as the importer maps the scene statement it stands for).
    Yes,
    /// Accepted and ignored; the reason is printed once.
    Ignored(&'static str),
}

/// Tachyon's output formats (`-format`, any case); TARGA is the default.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Targa,
    Bmp,
    Ppm,
    Ppm48,
    Png,
    Jpeg,
}

/// The names `-format` accepts (PSD48 and RGB are Tachyon's too, but Luxon has no writer).
const FORMATS: &str = "TARGA, BMP, PPM, PPM48, PNG, JPEG";

impl Format {
    fn parse(name: &str) -> Result<Format, Error> {
        Ok(match name.to_ascii_uppercase().as_str() {
            "TARGA" => Format::Targa,
            "BMP" => Format::Bmp,
            "PPM" => Format::Ppm,
            "PPM48" => Format::Ppm48,
            "PNG" => Format::Png,
            "JPEG" => Format::Jpeg,
            "PSD48" | "RGB" => {
                return Err(usage(format!(
                    "-format {name}: Luxon cannot write this format; expected one of {FORMATS}"
                )))
            }
            _ => {
                return Err(usage(format!(
                    "-format {}: unknown format; expected one of {FORMATS}",
                    luxon_formats::shown(name)
                )))
            }
        })
    }

    /// The extension Tachyon gives its default names (`outfile.tga`).
    pub fn extension(self) -> &'static str {
        match self {
            Format::Targa => "tga",
            Format::Bmp => "bmp",
            Format::Ppm | Format::Ppm48 => "ppm",
            Format::Png => "png",
            Format::Jpeg => "jpg",
        }
    }

    /// The writer plugin and its parameters: chosen by format, never by the file's extension
    /// (`-o x.png` without `-format PNG` is a Targa called x.png, as in Tachyon). The values
    /// are written as Tachyon writes them: display values, clamped and truncated, without the
    /// sRGB curve (a Tachyon scene's colours are display values, imported as written); Targa
    /// files uncompressed, as Tachyon's are.
    pub fn writer(self) -> (&'static str, &'static str) {
        match self {
            Format::Targa => ("tga", "(rle: false, encoding: display)"),
            Format::Bmp => ("bmp", "(encoding: display)"),
            Format::Ppm => ("ppm", "(encoding: display)"),
            Format::Ppm48 => ("ppm", "(bits: 16, encoding: display)"),
            Format::Png => ("png", "(encoding: display)"),
            Format::Jpeg => ("jpeg", "(encoding: display)"),
        }
    }
}

/// What Tachyon does to the image before writing it (`-clamp`, `-normalize`, `-gamma g`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Post {
    Clamp,
    Normalize,
    /// Normalize, then c^(1/g).
    Gamma(f64),
}

/// Also Tachyon's: `-skylight_samples` without a value given.
const SKYLIGHT_SAMPLES: u32 = 128;

/// Everything the options ask for.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Scene overrides, for the importer.
    pub scene: Options,
    pub threads: Option<u32>,
    /// `-o`, verbatim.
    pub output: Option<OsString>,
    pub format: Format,
    pub camfile: Option<PathBuf>,
    pub nosave: bool,
    pub post: Post,
    /// `+V`: timings and counts of every stage.
    pub verbose: bool,
    auto_skylight: f64,
    add_skylight: f64,
    skylight_samples: u32,
}

impl Plan {
    pub fn new(at: Origin) -> Plan {
        Plan {
            scene: Options::new(at),
            threads: None,
            output: None,
            format: Format::Targa,
            camfile: None,
            nosave: false,
            post: Post::Clamp,
            verbose: false,
            auto_skylight: 0.0,
            add_skylight: 0.0,
            skylight_samples: SKYLIGHT_SAMPLES,
        }
    }

    /// The plan after every option: `-auto_skylight` wins over `-add_skylight` whatever
    /// their order, and `-skylight_samples` applies to either (Tachyon resolves them so).
    pub fn finish(mut self) -> Plan {
        let (level, rescale) = if self.auto_skylight > 0.0 {
            (self.auto_skylight, true)
        } else {
            (self.add_skylight, false)
        };
        if level > 0.0 {
            self.scene.skylight = Some(Skylight {
                level,
                samples: self.skylight_samples,
                rescale,
            });
        }
        self
    }
}

/// The table: applies option `arg` to `plan` and says how well Luxon honours it. Another
/// feature that Luxon learns to render turns its row into `Support::Yes` (or, for a scene
/// option, is mapped by the importer, and its warning goes away there).
pub fn apply(arg: &Arg, plan: &mut Plan) -> Result<Support, Error> {
    use Support::*;
    let s = &mut plan.scene;
    let whole = |min, max| arg.whole(0, min, max);
    Ok(match arg.name {
        // Output.
        "-o" => {
            plan.output = Some(arg.values[0].clone());
            Yes
        }
        "-format" => {
            plan.format = Format::parse(arg.text(0)?)?;
            Yes
        }
        "-nosave" => {
            plan.nosave = true;
            Yes
        }
        "-clamp" => {
            plan.post = Post::Clamp;
            Yes
        }
        "-normalize" => {
            plan.post = Post::Normalize;
            Yes
        }
        "-gamma" => {
            let g = arg.number(0, 0.0)?;
            if g == 0.0 {
                return Err(usage("-gamma 0: expected a gamma greater than 0".into()));
            }
            plan.post = Post::Gamma(g);
            Yes
        }
        // The image and the render.
        "-res" => {
            let w = arg.whole(0, 1, 65536)? as u32;
            let h = arg.whole(1, 1, 65536)? as u32;
            if u64::from(w) * u64::from(h) > 1 << 28 {
                return Err(usage(format!("-res {w} {h}: expected at most 2^28 pixels")));
            }
            s.resolution = Some([w, h]);
            Yes
        }
        "-aasamples" => {
            s.antialiasing = Some(whole(0, 65535)? as u32);
            Yes
        }
        "-raydepth" => {
            s.raydepth = Some(whole(0, 1025)? as u32);
            Yes
        }
        "-numthreads" => {
            plan.threads = Some(whole(1, 4096)? as u32);
            Yes
        }
        "-camfile" => {
            plan.camfile = Some(PathBuf::from(&arg.values[0]));
            Yes
        }
        // Shading: the importer maps these as the SHADER_MODE options they stand for.
        "-fullshade" => level(s, ShadeLevel::Full),
        "-mediumshade" => level(s, ShadeLevel::Medium),
        "-lowshade" => level(s, ShadeLevel::Low),
        "-lowestshade" => level(s, ShadeLevel::Lowest),
        "-trans_orig" => {
            s.transparency = Some((false, false));
            Yes
        }
        "-trans_raster3d" => {
            let (vmd, _) = s.transparency.unwrap_or((false, false));
            s.transparency = Some((vmd, true));
            Yes
        }
        "-trans_vmd" => {
            let (_, raster3d) = s.transparency.unwrap_or((false, false));
            s.transparency = Some((true, raster3d));
            Yes
        }
        "-trans_max_surfaces" => {
            s.max_surfaces = Some(whole(0, 1024)? as u32);
            Yes
        }
        "-shadow_filter_on" => {
            s.shadow_filter = Some(true);
            Yes
        }
        "-shadow_filter_off" => {
            s.shadow_filter = Some(false);
            Yes
        }
        "-fog_vmd" => {
            s.fog_vmd = Some(true);
            Yes
        }
        "-fog_radial" | "-fog_normal" => {
            s.fog_vmd = Some(false);
            Yes
        }
        "-shade_phong" => highlights(s, Highlights::Phong),
        "-shade_blinn" => highlights(s, Highlights::Blinn),
        "-shade_blinn_fast" => highlights(s, Highlights::BlinnFast),
        "-shade_nullphong" => highlights(s, Highlights::None),
        // Lighting.
        "-rescale_lights" => {
            let f = arg.number(0, 0.0)?;
            if f >= 1.0 {
                Ignored("Tachyon only scales lights down (factors below 1)")
            } else {
                s.light_scale = Some(f);
                Yes
            }
        }
        "-auto_skylight" => {
            plan.auto_skylight = arg.number(0, 0.0)?;
            Yes
        }
        "-add_skylight" => {
            plan.add_skylight = arg.number(0, 0.0)?;
            Yes
        }
        "-skylight_samples" => {
            plan.skylight_samples = whole(1, 4096)? as u32;
            Yes
        }
        "-normalfixup" => match arg.text(0)? {
            "off" => Yes,
            "flip" | "guess" => Ignored(
                "Luxon does not fix up the normals or windings of smooth triangles yet; they \
                 are used as the file gives them",
            ),
            other => {
                return Err(usage(format!(
                    "-normalfixup {}: expected off, flip or guess",
                    luxon_formats::shown(other)
                )))
            }
        },
        // Messages.
        "+V" => {
            plan.verbose = true;
            Yes
        }
        "-V" => {
            plan.verbose = false;
            Yes
        }
        // Tachyon's own machinery.
        "-nobounding" | "-boundthresh" => {
            if arg.name == "-boundthresh" {
                whole(1, i64::from(i32::MAX))?;
            }
            Ignored("Luxon always builds its own BVH; Tachyon's grid settings do not apply")
        }
        "-spaceball" | "-spaceballport" => {
            Ignored("interactive camera flight is not supported; the scene is rendered")
        }
        // Answered before any option is applied.
        "-help" | "-version" | "-banner" => Yes,
        other => {
            return Err(Error::Render(format!(
                "option {other} is read but has no row in the table"
            )))
        }
    })
}

fn level(s: &mut Options, l: ShadeLevel) -> Support {
    s.shade = Some(l);
    Support::Yes
}

fn highlights(s: &mut Options, h: Highlights) -> Support {
    s.highlights = Some(h);
    Support::Yes
}

/// The warning for an option Luxon does not fully honour, or `None`.
pub fn warning(name: &str, support: Support) -> Option<String> {
    match support {
        Support::Yes => None,
        Support::Ignored(why) => Some(format!("{name} is not supported ({why}); ignored")),
    }
}

#[cfg(test)]
mod tests {
    use super::super::args::{split, OPTIONS};
    use super::*;
    use std::sync::Arc;

    fn origin() -> Origin {
        Origin {
            file: Arc::new(PathBuf::from("<command line>")),
            line: 1,
            col: 1,
        }
    }

    /// The plan of the options in `s`, and the warnings.
    fn plan(s: &str) -> Result<(Plan, Vec<String>), Error> {
        let words: Vec<OsString> = s.split_whitespace().map(OsString::from).collect();
        let c = split(&words)?;
        let mut p = Plan::new(origin());
        let mut warnings = Vec::new();
        for a in &c.args {
            if let Some(w) = warning(a.name, apply(a, &mut p)?) {
                warnings.push(w);
            }
        }
        Ok((p.finish(), warnings))
    }

    #[test]
    fn vmd_command_lines_map_without_warnings() {
        let (p, w) =
            plan("-aasamples 4 -trans_vmd -mediumshade -format TARGA -o x.dat.tga").unwrap();
        assert!(w.is_empty(), "{w:?}");
        assert_eq!(p.scene.antialiasing, Some(4));
        assert_eq!(p.scene.transparency, Some((true, false)));
        assert_eq!(p.scene.shade, Some(ShadeLevel::Medium));
        assert_eq!(p.format, Format::Targa);
        assert_eq!(p.output, Some(OsString::from("x.dat.tga")));
        let (p, w) = plan(
            "-aasamples 12 -trans_max_surfaces 1 -res 800 600 -numthreads 2 -auto_skylight 0.7",
        )
        .unwrap();
        assert!(w.is_empty(), "{w:?}");
        assert_eq!(p.scene.resolution, Some([800, 600]));
        assert_eq!(p.scene.max_surfaces, Some(1));
        assert_eq!(p.threads, Some(2));
        assert_eq!(
            p.scene.skylight,
            Some(Skylight {
                level: 0.7,
                samples: 128,
                rescale: true
            })
        );
    }

    #[test]
    fn each_option_sets_its_part() {
        let (p, _) = plan("-raydepth 3 -fullshade -lowshade -shadow_filter_off -fog_vmd").unwrap();
        assert_eq!(p.scene.raydepth, Some(3));
        assert_eq!(p.scene.shade, Some(ShadeLevel::Low));
        assert_eq!(p.scene.shadow_filter, Some(false));
        assert_eq!(p.scene.fog_vmd, Some(true));
        let (p, _) = plan("-lowestshade -shadow_filter_on -fog_vmd -fog_normal").unwrap();
        assert_eq!(p.scene.shade, Some(ShadeLevel::Lowest));
        assert_eq!(
            (p.scene.shadow_filter, p.scene.fog_vmd),
            (Some(true), Some(false))
        );
        assert_eq!(plan("-fog_radial").unwrap().0.scene.fog_vmd, Some(false));
        // Transparency flags: raster3d and vmd add up, orig clears them.
        let t = |s| plan(s).unwrap().0.scene.transparency;
        assert_eq!(t("-trans_raster3d -trans_vmd"), Some((true, true)));
        assert_eq!(t("-trans_vmd -trans_orig"), Some((false, false)));
        assert_eq!(t("-trans_orig -trans_raster3d"), Some((false, true)));
        let h = |s| plan(s).unwrap().0.scene.highlights;
        assert_eq!(h("-shade_phong"), Some(Highlights::Phong));
        assert_eq!(h("-shade_blinn"), Some(Highlights::Blinn));
        assert_eq!(h("-shade_blinn_fast"), Some(Highlights::BlinnFast));
        assert_eq!(h("-shade_nullphong"), Some(Highlights::None));
        // Skylight: auto wins over add whatever the order; samples apply to either.
        let sky = |s| plan(s).unwrap().0.scene.skylight;
        let s = sky("-auto_skylight 0.5 -add_skylight 0.25 -skylight_samples 8").unwrap();
        assert_eq!((s.level, s.samples, s.rescale), (0.5, 8, true));
        let s = sky("-skylight_samples 8 -add_skylight 0.25").unwrap();
        assert_eq!((s.level, s.samples, s.rescale), (0.25, 8, false));
        assert_eq!(sky("-skylight_samples 8"), None);
        assert_eq!(
            plan("-rescale_lights 0.5").unwrap().0.scene.light_scale,
            Some(0.5)
        );
        let (p, w) = plan("-nosave -camfile a.cam +V -normalize").unwrap();
        assert!(p.nosave && p.verbose && w.is_empty());
        assert_eq!(p.camfile, Some(PathBuf::from("a.cam")));
        assert_eq!(p.post, Post::Normalize);
        assert!(!plan("+V -V").unwrap().0.verbose);
        assert_eq!(plan("-normalize -clamp").unwrap().0.post, Post::Clamp);
        assert_eq!(plan("-normalfixup off").unwrap().1.len(), 0);
    }

    #[test]
    fn formats_are_chosen_by_name_in_any_case() {
        for (name, f, ext, writer) in [
            ("TARGA", Format::Targa, "tga", "tga"),
            ("bmp", Format::Bmp, "bmp", "bmp"),
            ("Ppm", Format::Ppm, "ppm", "ppm"),
            ("PPM48", Format::Ppm48, "ppm", "ppm"),
            ("png", Format::Png, "png", "png"),
            ("JPEG", Format::Jpeg, "jpg", "jpeg"),
        ] {
            let p = plan(&format!("-format {name}")).unwrap().0;
            assert_eq!(p.format, f);
            assert_eq!((f.extension(), f.writer().0), (ext, writer));
        }
        assert_eq!(Format::Ppm48.writer().1, "(bits: 16, encoding: display)");
        let e = plan("-format PSD48").unwrap_err().to_string();
        assert!(
            e.contains("-format PSD48: Luxon cannot write this format; expected one of TARGA, BMP, PPM, PPM48, PNG, JPEG"),
            "{e}"
        );
        assert!(plan("-format RGB").is_err());
        assert!(plan("-format GIF")
            .unwrap_err()
            .to_string()
            .contains("unknown format"));
    }

    #[test]
    fn ignored_options_say_so() {
        for (line, fragment) in [
            (
                "-nobounding",
                "-nobounding is not supported (Luxon always builds its own BVH",
            ),
            ("-boundthresh 16", "-boundthresh is not supported"),
            (
                "-spaceball",
                "-spaceball is not supported (interactive camera flight",
            ),
            (
                "-spaceballport /dev/ttyS0",
                "-spaceballport is not supported",
            ),
            ("-normalfixup flip", "-normalfixup is not supported"),
            (
                "-rescale_lights 2",
                "-rescale_lights is not supported (Tachyon only scales lights down",
            ),
        ] {
            let (_, w) = plan(line).unwrap();
            assert_eq!(w.len(), 1, "{line}");
            assert!(w[0].contains(fragment), "{line}: {}", w[0]);
        }
        assert_eq!(plan("-rescale_lights 2").unwrap().0.scene.light_scale, None);
        assert!(plan("-gamma 2.2 -normalize").unwrap().1.is_empty());
    }

    #[test]
    fn bad_values_are_errors() {
        for (line, fragment) in [
            (
                "-aasamples -1",
                "-aasamples -1: expected a whole number from 0",
            ),
            ("-res 0 10", "-res 0: expected a whole number from 1"),
            ("-res 65536 65536", "expected at most 2^28 pixels"),
            (
                "-numthreads many",
                "-numthreads `many`: expected a whole number",
            ),
            ("-gamma 0", "-gamma 0: expected a gamma greater than 0"),
            (
                "-normalfixup sideways",
                "-normalfixup sideways: expected off, flip or guess",
            ),
            ("-auto_skylight x", "-auto_skylight `x`: expected a number"),
            (
                "-skylight_samples 0",
                "-skylight_samples 0: expected a whole number from 1",
            ),
            (
                "-trans_max_surfaces 2000",
                "expected a whole number from 0 to 1024",
            ),
        ] {
            let e = plan(line).unwrap_err().to_string();
            assert!(e.contains(fragment), "{line}: {e}");
        }
    }

    /// `name` with a valid example value for each of its values.
    fn example(name: &str, arity: usize) -> String {
        let value = match name {
            "-format" => "PNG",
            "-normalfixup" => "off",
            "-aasamples"
            | "-raydepth"
            | "-numthreads"
            | "-trans_max_surfaces"
            | "-skylight_samples"
            | "-boundthresh"
            | "-res" => "2",
            _ => "0.5",
        };
        format!("{name}{}", format!(" {value}").repeat(arity))
    }

    #[test]
    fn the_table_has_a_row_for_every_option() {
        for &(name, arity) in OPTIONS {
            let line = example(name, arity);
            assert!(plan(&line).is_ok(), "{line}: {:?}", plan(&line).err());
        }
    }

    /// formats/README.md's option table: every option has a row, and each row's *yes* or
    /// *scene* (honoured) and *ignored* (warned, no effect) is what [`apply`] returns.
    #[test]
    fn the_readme_table_is_the_code() {
        let readme = include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/formats/README.md"));
        let start = readme
            .find("| option | Luxon | notes |")
            .expect("the option table");
        let mut listed = std::collections::HashSet::new();
        for row in readme[start..].lines().skip(2) {
            let Some(row) = row.strip_prefix("| ") else {
                break;
            };
            let cells: Vec<&str> = row.split(" | ").collect();
            for item in cells[0].split(", ") {
                let item = item.trim_matches('`');
                let name = item.split(' ').next().unwrap();
                let &(_, arity) = OPTIONS
                    .iter()
                    .find(|(n, _)| *n == name)
                    .unwrap_or_else(|| panic!("`{name}` in the README is not an option"));
                listed.insert(name);
                // An option written with a value stands for that value.
                let line = match item.contains(' ') {
                    true => item.to_string(),
                    false => example(name, arity),
                };
                let (_, warnings) = plan(&line).unwrap();
                match cells[1] {
                    "yes" | "scene" => assert!(warnings.is_empty(), "{line}: {warnings:?}"),
                    "ignored" => assert_eq!(warnings.len(), 1, "{line}"),
                    other => panic!("{line}: `{other}` is not yes, scene or ignored"),
                }
            }
        }
        for (name, _) in OPTIONS {
            assert!(
                listed.contains(name),
                "{name} has no row in the README's table"
            );
        }
    }
}
