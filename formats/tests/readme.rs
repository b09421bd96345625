//! Every ```` ```ron ```` block of `formats/README.md` loads. rustdoc runs only Rust blocks, so
//! this test is what keeps the scene-format reference true.
//!
//! - ```` ```ron ````: a whole scene, loaded as it stands;
//! - ```` ```ron fragment ````: fields of a `Scene(...)`, loaded wrapped in one (with a camera
//!   when the fragment gives none).
//!
//! Any other marker after `ron` fails the test, so no block is skipped unnoticed. Relative
//! paths in the blocks resolve against `scenes/`, as the README says.

use std::path::{Path, PathBuf};

/// One fenced code block: the line its fence opens on (1-based), its info string and its text.
struct Block {
    line: usize,
    info: String,
    text: String,
}

/// The fenced code blocks of a Markdown text (fences may be indented, as in list items).
fn code_blocks(markdown: &str) -> Vec<Block> {
    let mut blocks = Vec::new();
    let mut open: Option<Block> = None;
    for (i, line) in markdown.lines().enumerate() {
        let trimmed = line.trim_start();
        match open.as_mut() {
            None => {
                if let Some(info) = trimmed.strip_prefix("```") {
                    open = Some(Block {
                        line: i + 1,
                        info: info.trim().to_string(),
                        text: String::new(),
                    });
                }
            }
            Some(block) => {
                if trimmed.trim_end() == "```" {
                    blocks.extend(open.take());
                } else {
                    block.text.push_str(line);
                    block.text.push('\n');
                }
            }
        }
    }
    assert!(open.is_none(), "a code block is never closed");
    blocks
}

/// How a `ron` block is checked, from its info string.
enum Kind {
    Scene,
    Fragment,
}

fn kind(info: &str) -> Option<Result<Kind, String>> {
    let mut words = info.split_whitespace();
    if words.next() != Some("ron") {
        return None;
    }
    Some(match words.collect::<Vec<_>>().as_slice() {
        [] => Ok(Kind::Scene),
        ["fragment"] => Ok(Kind::Fragment),
        other => Err(format!(
            "unknown marker `{}`: use ```ron or ```ron fragment",
            other.join(" ")
        )),
    })
}

/// A fragment's fields inside a scene; a camera is added when the fragment has none.
fn wrap(fragment: &str) -> String {
    let has_camera = fragment.lines().any(|l| l.starts_with("camera:"));
    let camera = if has_camera {
        ""
    } else {
        "camera: (position: (0, 0, -5), look_at: (0, 0, 0)),\n"
    };
    format!("Scene(\n{camera}{fragment})\n")
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// Loads every `ron` block of `markdown`; returns the failures, one line each.
fn check(markdown: &str, name: &str) -> (usize, Vec<String>) {
    let mut checked = 0;
    let mut failures = Vec::new();
    for block in code_blocks(markdown) {
        let text = match kind(&block.info) {
            None => continue,
            Some(Err(why)) => {
                failures.push(format!("{name}:{}: {why}", block.line));
                continue;
            }
            Some(Ok(Kind::Scene)) => block.text.clone(),
            Some(Ok(Kind::Fragment)) => wrap(&block.text),
        };
        // A file beside the shipped scenes, so `include` and mesh paths resolve as documented.
        let path = root().join(format!("scenes/readme-line-{}.ron", block.line));
        if let Err(e) = luxon_formats::load_ron_str(&text, &path) {
            failures.push(format!("{name}:{}: {e}", block.line));
        }
        checked += 1;
    }
    (checked, failures)
}

#[test]
fn every_ron_block_of_the_formats_readme_loads() {
    let readme = std::fs::read_to_string(root().join("formats/README.md")).unwrap();
    let (checked, failures) = check(&readme, "formats/README.md");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(checked >= 8, "only {checked} ron blocks found");
}

#[test]
fn a_broken_block_or_an_unknown_marker_fails() {
    let markdown = "text\n\n```ron fragment\nlights: [Point(position: (0, 5))],\n```\n\n\
                    ```ron\nScene(camera: (position: (0, 0, -5), look_at: (0, 0, 0)))\n```\n\n\
                    ```ron example\nScene()\n```\n\n```sh\nnot ron\n```\n";
    let (checked, failures) = check(markdown, "test.md");
    assert_eq!(checked, 2);
    assert_eq!(failures.len(), 2, "{failures:?}");
    assert!(failures[0].starts_with("test.md:3: "), "{}", failures[0]);
    assert!(
        failures[1].contains("unknown marker `example`"),
        "{}",
        failures[1]
    );
}

#[test]
fn fragments_get_a_camera_only_when_they_have_none() {
    assert!(wrap("lights: [],\n").contains("camera: (position"));
    let own = "camera: (position: (1, 2, 3), look_at: (0, 0, 0)),\n";
    assert_eq!(wrap(own), format!("Scene(\n{own})\n"));
}
