//! Tachyon's command line, read by hand: single-dash long options (and `+V`), each taking a
//! fixed number of values, with the scene files anywhere among them. clap cannot express this
//! (`-res 640 480` would be six short flags), and VMD writes it, so it is read as Tachyon
//! reads it: a word starting with `-` or `+` is an option, any other word a scene file.

use luxon::Error;
use std::ffi::{OsStr, OsString};
use std::path::PathBuf;

/// Every option Tachyon 0.99 accepts, with the number of values it takes. `-fog_radial` is
/// what Tachyon's help says and `-fog_normal` what it actually parses: both are accepted.
pub const OPTIONS: &[(&str, usize)] = &[
    ("+V", 0),
    ("-V", 0),
    ("-raydepth", 1),
    ("-numthreads", 1),
    ("-nobounding", 0),
    ("-boundthresh", 1),
    ("-fullshade", 0),
    ("-mediumshade", 0),
    ("-lowshade", 0),
    ("-lowestshade", 0),
    ("-rescale_lights", 1),
    ("-auto_skylight", 1),
    ("-add_skylight", 1),
    ("-skylight_samples", 1),
    ("-shade_phong", 0),
    ("-shade_blinn", 0),
    ("-shade_blinn_fast", 0),
    ("-shade_nullphong", 0),
    ("-trans_max_surfaces", 1),
    ("-trans_orig", 0),
    ("-trans_raster3d", 0),
    ("-trans_vmd", 0),
    ("-shadow_filter_on", 0),
    ("-shadow_filter_off", 0),
    ("-fog_radial", 0),
    ("-fog_normal", 0),
    ("-fog_vmd", 0),
    ("-normalfixup", 1),
    ("-aasamples", 1),
    ("-res", 2),
    ("-o", 1),
    ("-clamp", 0),
    ("-normalize", 0),
    ("-gamma", 1),
    ("-format", 1),
    ("-camfile", 1),
    ("-nosave", 0),
    ("-spaceball", 0),
    ("-spaceballport", 1),
    ("-help", 0),
    ("-version", 0),
    ("-banner", 0),
];

/// An option as given: its name (from [`OPTIONS`]) and values.
#[derive(Clone, Debug, PartialEq)]
pub struct Arg {
    pub name: &'static str,
    pub values: Vec<OsString>,
}

impl Arg {
    /// Value `i` as text.
    pub fn text(&self, i: usize) -> Result<&str, Error> {
        self.values[i].to_str().ok_or_else(|| {
            usage(format!(
                "{} {}: expected text, got bytes that are not UTF-8",
                self.name,
                self.values[i].to_string_lossy()
            ))
        })
    }

    /// Value `i` as a whole number in `min..=max` (Tachyon reads these with `%d`).
    pub fn whole(&self, i: usize, min: i64, max: i64) -> Result<i64, Error> {
        let t = self.text(i)?;
        match t.parse::<i64>() {
            Ok(n) if (min..=max).contains(&n) => Ok(n),
            Ok(n) => Err(usage(format!(
                "{} {n}: expected a whole number from {min} to {max}",
                self.name
            ))),
            Err(_) => Err(usage(format!(
                "{} `{t}`: expected a whole number",
                self.name
            ))),
        }
    }

    /// Value `i` as a finite number of at least `min` (Tachyon reads these with `%f`).
    pub fn number(&self, i: usize, min: f64) -> Result<f64, Error> {
        let t = self.text(i)?;
        match t.parse::<f64>() {
            Ok(x) if x.is_finite() && x >= min => Ok(x),
            Ok(x) => Err(usage(format!(
                "{} {x}: expected a number of at least {min}",
                self.name
            ))),
            Err(_) => Err(usage(format!("{} `{t}`: expected a number", self.name))),
        }
    }
}

/// The command line taken apart: scene files in order, options in order.
#[derive(Debug, Default, PartialEq)]
pub struct CommandLine {
    pub scenes: Vec<PathBuf>,
    pub args: Vec<Arg>,
}

/// A command-line error, one line like every other (`luxon: error: ...`, status 1).
pub fn usage(message: String) -> Error {
    Error::Usage(format!("{message} (see `luxon tachyon -help`)"))
}

/// Splits the words after `luxon tachyon`. `-help`, `-version` and `-banner` end the reading
/// (what follows them is not looked at), as in Tachyon.
pub fn split(words: &[OsString]) -> Result<CommandLine, Error> {
    let mut out = CommandLine::default();
    let mut i = 0;
    while i < words.len() {
        let word = &words[i];
        let is_option = word
            .as_encoded_bytes()
            .first()
            .is_some_and(|b| *b == b'-' || *b == b'+');
        if !is_option {
            out.scenes.push(PathBuf::from(word));
            i += 1;
            continue;
        }
        let (name, arity) = find(word)?;
        let values: Vec<OsString> = words[i + 1..].iter().take(arity).cloned().collect();
        if values.len() < arity {
            let what = match (name, arity) {
                ("-res", _) => "two values (width height)".to_string(),
                ("-o", _) => "an output file name".to_string(),
                ("-format", _) => "an image format".to_string(),
                ("-camfile", _) => "a camera file".to_string(),
                _ => "a value".to_string(),
            };
            return Err(usage(format!(
                "{name} expects {what}, but the command line ends"
            )));
        }
        out.args.push(Arg { name, values });
        i += 1 + arity;
        if matches!(name, "-help" | "-version" | "-banner") {
            break;
        }
    }
    Ok(out)
}

/// The option named `word`, or an error that suggests the closest name.
fn find(word: &OsStr) -> Result<(&'static str, usize), Error> {
    let text = word.to_string_lossy();
    if let Some(&(name, arity)) = OPTIONS.iter().find(|(n, _)| *n == text) {
        return Ok((name, arity));
    }
    let names = OPTIONS.iter().map(|(n, _)| *n);
    let hint = match luxon_formats::suggest(&text, names) {
        Some(s) => format!("; did you mean `{s}`?"),
        None => String::new(),
    };
    Err(usage(format!(
        "unknown option `{}`{hint}",
        luxon_formats::shown(&text)
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(s: &str) -> Vec<OsString> {
        s.split_whitespace().map(OsString::from).collect()
    }

    fn err(s: &str) -> String {
        split(&words(s)).unwrap_err().to_string()
    }

    #[test]
    fn options_and_scenes_in_any_order() {
        let c = split(&words(
            "-aasamples 12 scene.dat -format TARGA -o scene.dat.tga -res 640 480 +V",
        ))
        .unwrap();
        assert_eq!(c.scenes, vec![PathBuf::from("scene.dat")]);
        let names: Vec<&str> = c.args.iter().map(|a| a.name).collect();
        assert_eq!(names, ["-aasamples", "-format", "-o", "-res", "+V"]);
        assert_eq!(c.args[3].values, words("640 480"));
        // A value is taken as it stands, even when it starts with a dash.
        let c = split(&words("-o -weird.tga a.dat")).unwrap();
        assert_eq!(c.args[0].values, words("-weird.tga"));
        assert_eq!(c.scenes.len(), 1);
    }

    #[test]
    fn every_option_is_read_with_its_values() {
        for &(name, arity) in OPTIONS {
            let mut w = vec![OsString::from(name)];
            w.extend((0..arity).map(|k| OsString::from(format!("{k}"))));
            w.push("s.dat".into());
            let c = split(&w).unwrap();
            assert_eq!(c.args[0].name, name);
            assert_eq!(c.args[0].values.len(), arity);
            let ends = matches!(name, "-help" | "-version" | "-banner");
            assert_eq!(c.scenes.len(), usize::from(!ends), "{name}");
        }
    }

    #[test]
    fn errors_are_one_line_and_say_what_is_wrong() {
        assert_eq!(
            err("-aasampels 4 a.dat"),
            "unknown option `-aasampels`; did you mean `-aasamples`? (see `luxon tachyon -help`)"
        );
        assert!(err("a.dat -res 640").contains("-res expects two values (width height)"));
        assert!(err("a.dat -o").contains("-o expects an output file name"));
        assert!(err("--res 4 4").contains("unknown option `--res`"));
        let c = split(&words("-aasamples x -gamma -1 -numthreads 0")).unwrap();
        assert!(c.args[0]
            .whole(0, 0, 10)
            .unwrap_err()
            .to_string()
            .contains("-aasamples `x`: expected a whole number"));
        assert!(c.args[1]
            .number(0, 0.0)
            .unwrap_err()
            .to_string()
            .contains("expected a number of at least 0"));
        assert!(c.args[2]
            .whole(0, 1, 4096)
            .unwrap_err()
            .to_string()
            .contains("-numthreads 0: expected a whole number from 1 to 4096"));
    }

    #[test]
    fn help_version_and_banner_end_the_reading() {
        let c = split(&words("-version -bogus")).unwrap();
        assert_eq!(c.args.len(), 1);
    }
}
