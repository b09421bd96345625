//! Command-line errors as one line: clap's several lines (message, tip, usage, "for more
//! information") folded into the message, its tip and where to look.

/// The end of `luxon help new-plugin`: what is written, and the two commands that follow.
pub const NEW_PLUGIN: &str = "\
Writes DIR/Cargo.toml (a cdylib named luxon_NAME, so the library is libluxon_NAME.so, in a
workspace of its own), DIR/src/lib.rs (the plugin and its parameter table), DIR/scene.ron (a
scene that uses it) and DIR/README.md. Then, in DIR:

  cargo build --release
  LUXON_PLUGIN_PATH=target/release luxon render scene.ron -o x.png

(a writer plugin: -o x.pfm). The plugin SDK's documentation says how to write each kind:
cargo doc -p luxon-plugin --open, or plugins/README.md in Luxon's repository.

Examples:
  luxon new-plugin stripes --kind texture
  luxon new-plugin blob --kind primitive --dir ~/src/blob --sdk ~/src/luxon/plugins/sdk";

/// The one-line form of clap's error text `text`; `subcommand`: the subcommand given, if any.
pub fn one_line(text: &str, subcommand: Option<&str>) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut tip = None;
    for line in text.lines() {
        let line = line.trim();
        if line.starts_with("Usage:") {
            break;
        }
        if line.is_empty() || line.starts_with("For more information") {
            continue;
        }
        if let Some(t) = line.strip_prefix("tip: ") {
            tip = Some(t.to_string());
            continue;
        }
        parts.push(line.strip_prefix("error: ").unwrap_or(line).to_string());
    }
    let mut m = parts.join(" ");
    if let Some(t) = tip {
        // "a similar subcommand exists: 'render'" (or "…argument exists: '--res'").
        match t.split_once(" exists: ") {
            Some((_, name)) => {
                m.push_str(&format!("; did you mean `{}`?", name.trim_matches('\'')))
            }
            None => m.push_str(&format!("; {t}")),
        }
    }
    let help = match subcommand {
        Some(s) => format!("luxon help {s}"),
        None => "luxon --help".into(),
    };
    format!("{m} (see `{help}`)")
}

#[cfg(test)]
mod tests {
    use super::one_line;

    #[test]
    fn clap_errors_fold_into_one_line() {
        let text = "error: unrecognized subcommand 'rendr'\n\n  tip: a similar subcommand exists: \
                    'render'\n\nUsage: luxon <COMMAND>\n\nFor more information, try '--help'.\n";
        assert_eq!(
            one_line(text, None),
            "unrecognized subcommand 'rendr'; did you mean `render`? (see `luxon --help`)"
        );
        let text = "error: invalid value 'x' for '--samples <SAMPLES>': invalid digit found in \
                    string\n\nFor more information, try '--help'.\n";
        assert_eq!(
            one_line(text, Some("render")),
            "invalid value 'x' for '--samples <SAMPLES>': invalid digit found in string (see \
             `luxon help render`)"
        );
        let text = "error: the following required arguments were not provided:\n  <SCENE>\n\n\
                    Usage: luxon render <SCENE>\n\nFor more information, try '--help'.\n";
        assert_eq!(
            one_line(text, Some("render")),
            "the following required arguments were not provided: <SCENE> (see `luxon help render`)"
        );
    }
}
