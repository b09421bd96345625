//! Every relative link in the repository's Markdown files leads somewhere: the file or folder
//! exists, and a `#anchor` names a heading of the Markdown file it points into (GitHub's
//! heading ids). Links inside code blocks and code spans are not links, and web addresses are
//! not checked.

use std::path::{Path, PathBuf};

/// The Markdown files under `dir`, skipping build output, hidden folders and fuzz corpora.
fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if path.is_dir() {
            let skipped =
                name.starts_with('.') || ["target", "corpus", "artifacts"].contains(&name.as_str());
            if !skipped {
                markdown_files(&path, out);
            }
        } else if name.ends_with(".md") {
            out.push(path);
        }
    }
}

/// The lines of `markdown` outside fenced code blocks, with their 1-based numbers.
fn prose_lines(markdown: &str) -> Vec<(usize, &str)> {
    let mut fenced = false;
    let mut lines = Vec::new();
    for (i, line) in markdown.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        } else if !fenced {
            lines.push((i + 1, line));
        }
    }
    lines
}

/// `line` without its code spans (a run of backticks up to the next run of the same length).
fn without_code_spans(line: &str) -> String {
    let mut out = String::new();
    let mut rest = line;
    while let Some(start) = rest.find('`') {
        out.push_str(&rest[..start]);
        let run = rest[start..].len() - rest[start..].trim_start_matches('`').len();
        let after = &rest[start + run..];
        let fence = "`".repeat(run);
        match find_run(after, &fence) {
            Some(end) => rest = &after[end + run..],
            None => {
                out.push_str(&rest[start..start + run]);
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// Where a run of exactly `fence` backticks starts in `text`.
fn find_run(text: &str, fence: &str) -> Option<usize> {
    let mut from = 0;
    while let Some(at) = text[from..].find(fence) {
        let at = from + at;
        let end = at + fence.len();
        let longer = text[end..].starts_with('`') || text[..at].ends_with('`');
        if !longer {
            return Some(at);
        }
        from = end + text[end..].len() - text[end..].trim_start_matches('`').len();
    }
    None
}

/// The destinations of the inline links and images of a line: `[text](dest)`.
fn link_targets(line: &str) -> Vec<String> {
    let line = without_code_spans(line);
    let mut targets = Vec::new();
    let mut rest = line.as_str();
    while let Some(at) = rest.find("](") {
        let after = &rest[at + 2..];
        match after.find(')') {
            Some(end) => {
                targets.push(after[..end].trim().to_string());
                rest = &after[end..];
            }
            None => break,
        }
    }
    targets
}

/// GitHub's id of a heading: lower case, punctuation dropped, spaces to hyphens.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The ids of every heading of a Markdown text; repeated ones get `-1`, `-2`... as on GitHub.
fn anchors(markdown: &str) -> Vec<String> {
    let mut ids: Vec<String> = Vec::new();
    for (_, line) in prose_lines(markdown) {
        let hashes = line.len() - line.trim_start_matches('#').len();
        if (1..=6).contains(&hashes) && line[hashes..].starts_with(' ') {
            let base = slug(&line[hashes..]);
            let mut id = base.clone();
            let mut n = 0;
            while ids.contains(&id) {
                n += 1;
                id = format!("{base}-{n}");
            }
            ids.push(id);
        }
    }
    ids
}

/// The broken links of one Markdown file, as `file:line: link: why`.
fn broken_links(file: &Path, shown: &str) -> Vec<String> {
    let text = std::fs::read_to_string(file).unwrap();
    let mut broken = Vec::new();
    for (number, line) in prose_lines(&text) {
        for target in link_targets(line) {
            if target.contains("://") || target.starts_with("mailto:") {
                continue;
            }
            let (path, anchor) = match target.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (target.as_str(), None),
            };
            let resolved = if path.is_empty() {
                file.to_path_buf()
            } else {
                file.parent().unwrap().join(path)
            };
            let why = if !resolved.exists() {
                Some("no such file or folder".to_string())
            } else if let Some(anchor) = anchor {
                let is_markdown = resolved.extension().is_some_and(|e| e == "md");
                let text = std::fs::read_to_string(&resolved).unwrap_or_default();
                (is_markdown && !anchors(&text).iter().any(|a| a == anchor))
                    .then(|| format!("no heading with the id `{anchor}`"))
            } else {
                None
            };
            if let Some(why) = why {
                broken.push(format!("{shown}:{number}: ({target}): {why}"));
            }
        }
    }
    broken
}

#[test]
fn every_relative_link_of_the_markdown_files_resolves() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    markdown_files(root, &mut files);
    files.sort();
    assert!(
        files.len() >= 8,
        "only {} Markdown files found",
        files.len()
    );
    let mut broken = Vec::new();
    for file in &files {
        let shown = file.strip_prefix(root).unwrap().display().to_string();
        broken.extend(broken_links(file, &shown));
    }
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn a_missing_file_or_heading_is_reported() {
    let dir = std::env::temp_dir().join(format!("luxon-doc-links-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(
        dir.join("sub/b.md"),
        "# B\n\n## Some `code`: here\n## Twice\n## Twice\n",
    )
    .unwrap();
    let a = "# A\n\n[ok](sub/b.md#some-code-here), [ok](sub/b.md#twice-1), [ok](#a), \
             [ok](https://example.com/x)\n[gone](sub/c.md) and [bad anchor](sub/b.md#nope)\n\
             `[not a link](nowhere)` and\n```text\n[not a link](nowhere)\n```\n";
    std::fs::write(dir.join("a.md"), a).unwrap();
    let broken = broken_links(&dir.join("a.md"), "a.md");
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(
        broken,
        [
            "a.md:4: (sub/c.md): no such file or folder",
            "a.md:4: (sub/b.md#nope): no heading with the id `nope`",
        ]
    );
}

#[test]
fn headings_become_github_ids() {
    assert_eq!(
        slug("SPD benchmark: Luxon, Tachyon and POV-Ray"),
        "spd-benchmark-luxon-tachyon-and-pov-ray"
    );
    assert_eq!(slug("`include`"), "include");
    assert_eq!(
        slug("What accuracy costs in time"),
        "what-accuracy-costs-in-time"
    );
    assert_eq!(
        link_targets("[`a`](x.md) `[b](y)` ![c](z.png)"),
        ["x.md", "z.png"]
    );
}
