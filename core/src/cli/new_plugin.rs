//! `luxon new-plugin NAME --kind KIND`: a plugin crate to start from, which builds wherever it
//! is put: a manifest with a workspace of its own and the SDK by path (this checkout's, found
//! beside the executable, or `--sdk`) or by version, a minimal complete plugin of that kind with
//! its parameter table, a scene that uses it, and a README with the commands to build and
//! render. The files are the templates in `plugins/templates/`, compiled in.

use luxon::Error;
use std::path::{Path, PathBuf};

/// The kinds of plugin a template exists for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Kind {
    Primitive,
    Texture,
    Writer,
    Volume,
}

impl Kind {
    #[cfg(test)]
    const ALL: [Kind; 4] = [Kind::Primitive, Kind::Texture, Kind::Writer, Kind::Volume];

    fn name(self) -> &'static str {
        match self {
            Kind::Primitive => "primitive",
            Kind::Texture => "texture",
            Kind::Writer => "writer",
            Kind::Volume => "volume",
        }
    }

    /// `src/lib.rs` and `scene.ron` of the kind's template.
    fn files(self) -> (&'static str, &'static str) {
        macro_rules! template {
            ($kind:literal) => {
                (
                    include_str!(concat!("../../../plugins/templates/", $kind, "/lib.rs")),
                    include_str!(concat!("../../../plugins/templates/", $kind, "/scene.ron")),
                )
            };
        }
        match self {
            Kind::Primitive => template!("primitive"),
            Kind::Texture => template!("texture"),
            Kind::Writer => template!("writer"),
            Kind::Volume => template!("volume"),
        }
    }

    /// The image file the README's render command writes.
    fn output(self) -> &'static str {
        match self {
            Kind::Writer => "x.pfm",
            _ => "x.png",
        }
    }
}

const CARGO_TOML: &str = include_str!("../../../plugins/templates/Cargo.toml.in");
const README: &str = include_str!("../../../plugins/templates/README.md.in");

/// Where the generated crate gets `luxon-plugin` from.
#[derive(Clone, Debug, PartialEq)]
pub enum Sdk {
    /// The SDK crate's directory (its `Cargo.toml` names `luxon-plugin`).
    Path(PathBuf),
    /// A version requirement, fetched from the registry.
    Version(String),
}

impl Sdk {
    /// The dependency line of the manifest.
    fn dependency(&self) -> Result<String, Error> {
        match self {
            Sdk::Path(p) => {
                let p = p.to_str().ok_or_else(|| {
                    Error::Usage(format!(
                        "--sdk {}: the path is not UTF-8, which Cargo.toml cannot hold",
                        p.display()
                    ))
                })?;
                Ok(format!("luxon-plugin = {{ path = {} }}", toml_string(p)))
            }
            Sdk::Version(v) => Ok(format!("luxon-plugin = {}", toml_string(v))),
        }
    }
}

/// `s` as a TOML basic string.
fn toml_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The version requirement that matches this build's SDK: "0.4" for 0.4.x (its ABI).
fn sdk_version_req() -> String {
    let v = luxon_plugin::SDK_VERSION;
    let mut parts = v.split('.');
    match (parts.next(), parts.next()) {
        (Some(major), Some(minor)) => format!("{major}.{minor}"),
        _ => v.to_string(),
    }
}

/// The version in the `[package]` table of the manifest `text` if its name is `luxon-plugin`.
fn sdk_manifest_version(text: &str) -> Option<String> {
    let mut in_package = false;
    let (mut name, mut version) = (None, None);
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with('[') {
            in_package = line == "[package]";
            continue;
        }
        if !in_package {
            continue;
        }
        if let Some((key, value)) = line.split_once('=') {
            let value = value.trim().trim_matches('"').to_string();
            match key.trim() {
                "name" => name = Some(value),
                "version" => version = Some(value),
                _ => {}
            }
        }
    }
    (name.as_deref() == Some("luxon-plugin")).then_some(version?)
}

/// `dir` if it holds the SDK crate this build was made with (the same version, so what is
/// built against it loads here).
fn sdk_at(dir: &Path) -> Option<PathBuf> {
    let text = std::fs::read_to_string(dir.join("Cargo.toml")).ok()?;
    (sdk_manifest_version(&text)? == luxon_plugin::SDK_VERSION).then(|| dir.to_path_buf())
}

/// This checkout's SDK, seen from the executable: `plugins/sdk` of a directory above it
/// (`target/release/luxon` is two levels below the checkout).
pub fn find_sdk(exe: &Path) -> Option<PathBuf> {
    exe.ancestors()
        .skip(1)
        .find_map(|dir| sdk_at(&dir.join("plugins").join("sdk")))
}

/// `--sdk`: a directory holding the SDK crate, or a version requirement of `luxon-plugin`.
fn parse_sdk(arg: &str) -> Result<Sdk, Error> {
    let path = Path::new(arg);
    if path.is_dir() {
        let text = std::fs::read_to_string(path.join("Cargo.toml")).unwrap_or_default();
        if sdk_manifest_version(&text).is_none() {
            return Err(Error::Usage(format!(
                "--sdk {arg}: the directory holds no `luxon-plugin` crate (its Cargo.toml); \
                 give the SDK's directory, `plugins/sdk` of a Luxon checkout"
            )));
        }
        let abs = std::path::absolute(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        return Ok(Sdk::Path(abs));
    }
    let version = arg.strip_prefix(['=', '^', '~']).unwrap_or(arg);
    let numeric = !version.is_empty()
        && version.split('.').count() <= 3
        && version
            .split('.')
            .all(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()));
    if !numeric {
        return Err(Error::Usage(format!(
            "--sdk {arg}: expected the SDK's directory (no such directory) or a version of \
             luxon-plugin such as {}",
            sdk_version_req()
        )));
    }
    Ok(Sdk::Version(arg.to_string()))
}

/// An error unless `name` can name a plugin, a crate and a library: lowercase ASCII letters,
/// digits, `_` and `-`, starting with a letter.
pub fn check_name(name: &str) -> Result<(), Error> {
    let bad = |why: &str| {
        Err(Error::Usage(format!(
            "plugin name `{name}` {why}: use lowercase letters, digits, `_` and `-`, starting \
             with a letter (for example `my_stripes`)"
        )))
    };
    let Some(first) = name.chars().next() else {
        return bad("is empty");
    };
    if !first.is_ascii_lowercase() {
        return bad("does not start with a lowercase letter");
    }
    if let Some(c) = name
        .chars()
        .find(|&c| !(c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_' || c == '-'))
    {
        return bad(&format!("holds `{}`", c.escape_default()));
    }
    if name.len() > 64 {
        return bad("is longer than 64 characters");
    }
    if name == "plugin" {
        // The package would be `luxon-plugin`, the SDK it depends on.
        return bad("would name the crate `luxon-plugin`, the SDK's own name");
    }
    Ok(())
}

/// `my-dots` -> `MyDots`.
fn camel(name: &str) -> String {
    name.split(['-', '_'])
        .map(|part| {
            let mut c = part.chars();
            match c.next() {
                Some(first) => first.to_ascii_uppercase().to_string() + c.as_str(),
                None => String::new(),
            }
        })
        .collect()
}

/// The files of a new plugin crate: (path inside the crate, contents).
pub fn files(name: &str, kind: Kind, sdk: &Sdk) -> Result<Vec<(&'static str, String)>, Error> {
    check_name(name)?;
    let package = format!("luxon-{name}");
    let lib = format!("luxon_{}", name.replace('-', "_"));
    let sdk = sdk.dependency()?;
    let fill = |template: &str| {
        template
            .replace("{{name}}", name)
            .replace("{{Name}}", &camel(name))
            .replace("{{package}}", &package)
            .replace("{{lib}}", &lib)
            .replace("{{kind}}", kind.name())
            .replace("{{sdk}}", &sdk)
            .replace("{{output}}", kind.output())
    };
    let (lib_rs, scene) = kind.files();
    Ok(vec![
        ("Cargo.toml", fill(CARGO_TOML)),
        ("src/lib.rs", fill(lib_rs)),
        ("scene.ron", fill(scene)),
        ("README.md", fill(README)),
    ])
}

/// Writes the crate into `dir`, which must not exist or be empty.
fn write(dir: &Path, files: &[(&str, String)]) -> Result<(), Error> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| Error::Io { path, source }
    };
    if dir.exists() && !dir.is_dir() {
        return Err(Error::Usage(format!(
            "{}: exists and is not a directory; nothing was written",
            dir.display()
        )));
    }
    match std::fs::read_dir(dir) {
        Ok(mut entries) => {
            if entries.next().is_some() {
                return Err(Error::Usage(format!(
                    "{}: the directory exists and is not empty; nothing was written (choose \
                     another with --dir)",
                    dir.display()
                )));
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => return Err(io(dir)(e)),
    }
    for (path, text) in files {
        let path = dir.join(path);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(io(parent))?;
        }
        std::fs::write(&path, text).map_err(io(&path))?;
    }
    Ok(())
}

pub fn run(name: &str, kind: Kind, dir: Option<&Path>, sdk: Option<&str>) -> Result<(), Error> {
    check_name(name)?;
    let sdk = match sdk {
        Some(arg) => parse_sdk(arg)?,
        None => match std::env::current_exe().ok().and_then(|e| find_sdk(&e)) {
            Some(path) => Sdk::Path(path),
            None => {
                luxon::error::print_warning(&format!(
                    "no Luxon checkout around this executable: the crate takes the SDK from \
                     the registry (luxon-plugin = \"{}\"); give --sdk DIR to build against a \
                     checkout's plugins/sdk",
                    sdk_version_req()
                ));
                Sdk::Version(sdk_version_req())
            }
        },
    };
    let dir = dir.map_or_else(|| PathBuf::from(name), Path::to_path_buf);
    let files = files(name, kind, &sdk)?;
    write(&dir, &files)?;
    let from = match &sdk {
        Sdk::Path(p) => format!("the SDK at {}", p.display()),
        Sdk::Version(v) => format!("luxon-plugin {v}"),
    };
    eprintln!(
        "luxon: wrote the {} plugin `{name}` into {} (built against {from}); to build it and \
         render its scene:\n  cd {}\n  cargo build --release\n  LUXON_PLUGIN_PATH=target/release \
         luxon render scene.ron -o {}",
        kind.name(),
        dir.display(),
        dir.display(),
        kind.output()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_checked() {
        for good in ["stripes", "my_dots", "my-dots", "a1"] {
            assert!(check_name(good).is_ok(), "{good}");
        }
        for (bad, why) in [
            ("", "is empty"),
            ("1up", "does not start with a lowercase letter"),
            ("Stripes", "does not start with a lowercase letter"),
            ("my dots", "holds ` `"),
            ("dots.so", "holds `.`"),
            ("plugin", "the SDK's own name"),
        ] {
            let e = check_name(bad).unwrap_err().to_string();
            assert!(
                e.contains(why) && e.contains(&format!("`{bad}`")),
                "{bad}: {e}"
            );
        }
    }

    #[test]
    fn every_placeholder_is_filled() {
        let sdk = Sdk::Path(PathBuf::from("/opt/luxon/plugins/sdk"));
        for kind in Kind::ALL {
            let files = files("my-dots", kind, &sdk).unwrap();
            for (path, text) in &files {
                assert!(!text.contains("{{"), "{kind:?} {path}: {text}");
            }
            let manifest = &files[0].1;
            assert!(manifest.contains("name = \"luxon-my-dots\""), "{manifest}");
            assert!(manifest.contains("name = \"luxon_my_dots\""), "{manifest}");
            assert!(manifest.contains("crate-type = [\"cdylib\"]"), "{manifest}");
            assert!(manifest.contains("\n[workspace]\n"), "{manifest}");
            assert!(
                manifest.contains("luxon-plugin = { path = \"/opt/luxon/plugins/sdk\" }"),
                "{manifest}"
            );
            assert!(files[1]
                .1
                .contains("const NAME: &'static str = \"my-dots\";"));
            assert!(files[1].1.contains("MyDots"));
            assert!(files[2].1.contains("plugin: \"my-dots\""));
        }
        let by_version = files("dots", Kind::Texture, &Sdk::Version("0.2".into())).unwrap();
        assert!(by_version[0].1.contains("\nluxon-plugin = \"0.2\"\n"));
    }

    #[test]
    fn the_sdk_version_requirement_is_this_builds() {
        assert_eq!(sdk_version_req(), "0.4");
        assert_eq!(parse_sdk("0.2").unwrap(), Sdk::Version("0.2".into()));
        assert_eq!(parse_sdk("=0.2.0").unwrap(), Sdk::Version("=0.2.0".into()));
        let e = parse_sdk("/no/such/dir").unwrap_err().to_string();
        assert!(e.contains("no such directory"), "{e}");
    }

    #[test]
    fn toml_strings_are_escaped() {
        assert_eq!(toml_string(r#"C:\a "b""#), r#""C:\\a \"b\"""#);
    }

    /// A directory with a fake checkout: `plugins/sdk/Cargo.toml` and `target/release/luxon`.
    fn fake_checkout(name: &str, sdk_version: &str) -> PathBuf {
        let root =
            std::env::temp_dir().join(format!("luxon-new-plugin-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(root.join("plugins/sdk")).unwrap();
        std::fs::create_dir_all(root.join("target/release")).unwrap();
        std::fs::write(
            root.join("plugins/sdk/Cargo.toml"),
            format!("[package]\nname = \"luxon-plugin\"\nversion = \"{sdk_version}\"\n"),
        )
        .unwrap();
        root
    }

    #[test]
    fn the_sdk_is_found_above_the_executable() {
        let root = fake_checkout("found", luxon_plugin::SDK_VERSION);
        let exe = root.join("target/release/luxon");
        assert_eq!(find_sdk(&exe), Some(root.join("plugins/sdk")));
        assert_eq!(
            parse_sdk(root.join("plugins/sdk").to_str().unwrap()).unwrap(),
            Sdk::Path(root.join("plugins/sdk"))
        );
        assert!(parse_sdk(root.join("target").to_str().unwrap()).is_err());
        // Another checkout's SDK of another version would build plugins this build skips.
        let other = fake_checkout("other", "0.1.0");
        assert_eq!(find_sdk(&other.join("target/release/luxon")), None);
        let _ = std::fs::remove_dir_all(root);
        let _ = std::fs::remove_dir_all(other);
    }

    #[test]
    fn a_non_empty_directory_is_left_alone() {
        let dir =
            std::env::temp_dir().join(format!("luxon-new-plugin-{}-full", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("notes.txt"), "mine").unwrap();
        let files = files("dots", Kind::Texture, &Sdk::Version("0.2".into())).unwrap();
        let e = write(&dir, &files).unwrap_err().to_string();
        assert!(
            e.contains(&dir.display().to_string()) && e.contains("not empty"),
            "{e}"
        );
        assert!(!dir.join("Cargo.toml").exists());
        // An empty one is used.
        std::fs::remove_file(dir.join("notes.txt")).unwrap();
        write(&dir, &files).unwrap();
        assert!(dir.join("src/lib.rs").is_file() && dir.join("scene.ron").is_file());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
