//! Every relative link of the documents resolves: the README, the changelog, the benchmarks and
//! every page under `docs/`. A link's file must exist, and a `#anchor` into a Markdown file must
//! name one of its headings (GitHub's rule: lower case, punctuation dropped, spaces as hyphens,
//! `-1`, `-2`, ... for repeats). Links inside code (fenced blocks and `inline spans`) are text,
//! not links; `http`, `https` and `mailto` links are not followed.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The documents whose links are checked.
fn documents() -> Vec<PathBuf> {
    let root = root();
    let mut out: Vec<PathBuf> = ["README.md", "CHANGELOG.md", "BENCHMARKS.md"]
        .iter()
        .map(|f| root.join(f))
        .collect();
    let mut dirs = vec![root.join("docs")];
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    out
}

/// The lines of a Markdown text outside fenced code blocks, with inline code spans blanked.
fn prose_lines(markdown: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    for (k, line) in markdown.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            continue;
        }
        let mut text = String::with_capacity(line.len());
        for (i, part) in line.split('`').enumerate() {
            if i % 2 == 0 {
                text.push_str(part);
            } else {
                text.push_str(&" ".repeat(part.len() + 2));
            }
        }
        out.push((k + 1, text));
    }
    out
}

/// The targets of the inline links `[text](target)` and images `![alt](target)` of a line.
fn link_targets(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = line;
    while let Some(at) = rest.find("](") {
        let after = &rest[at + 2..];
        let Some(end) = after.find(')') else {
            break;
        };
        let target = after[..end].trim();
        // A title (`(file "title")`) is not part of the target.
        let target = target.split_whitespace().next().unwrap_or("");
        if !target.is_empty() {
            out.push(target.to_owned());
        }
        rest = &after[end..];
    }
    out
}

/// GitHub's anchor of a heading's text.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of a Markdown text's headings (outside fenced code), repeats numbered.
fn anchors(markdown: &str) -> HashSet<String> {
    let mut out = HashSet::new();
    let mut fenced = false;
    for line in markdown.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced || !line.starts_with('#') {
            continue;
        }
        let text = line.trim_start_matches('#');
        if !text.starts_with(' ') {
            continue;
        }
        let base = slug(text.trim_end_matches('#'));
        let mut anchor = base.clone();
        let mut n = 0;
        while out.contains(&anchor) {
            n += 1;
            anchor = format!("{base}-{n}");
        }
        out.insert(anchor);
    }
    out
}

/// What is wrong with the links of `markdown`, the text of the file `file`: one line per link
/// whose file does not exist or whose anchor names no heading.
fn problems(file: &Path, markdown: &str) -> Vec<String> {
    let dir = file.parent().unwrap();
    let mut out = Vec::new();
    for (line, text) in prose_lines(markdown) {
        for target in link_targets(&text) {
            if ["http://", "https://", "mailto:"]
                .iter()
                .any(|p| target.starts_with(p))
            {
                continue;
            }
            let (path, anchor) = match target.split_once('#') {
                Some((p, a)) => (p, Some(a)),
                None => (target.as_str(), None),
            };
            let resolved = if path.is_empty() {
                file.to_path_buf()
            } else {
                dir.join(path)
            };
            let here = format!("{}:{line}: `{target}`", file.display());
            if !resolved.exists() {
                out.push(format!("{here}: {} does not exist", resolved.display()));
                continue;
            }
            let Some(anchor) = anchor else {
                continue;
            };
            if resolved.extension().is_none_or(|e| e != "md") {
                continue;
            }
            let heading_text = std::fs::read_to_string(&resolved).unwrap();
            if !anchors(&heading_text).contains(anchor) {
                out.push(format!(
                    "{here}: no heading of {} has the anchor #{anchor}",
                    resolved.display()
                ));
            }
        }
    }
    out
}

#[test]
fn every_link_of_the_documents_resolves() {
    let docs = documents();
    assert!(docs.len() >= 10, "the documents were not found: {docs:?}");
    let mut all = Vec::new();
    let mut links = 0;
    for doc in &docs {
        let text = std::fs::read_to_string(doc).unwrap();
        links += prose_lines(&text)
            .iter()
            .map(|(_, l)| link_targets(l).len())
            .sum::<usize>();
        all.extend(problems(doc, &text));
    }
    assert!(
        links >= 30,
        "only {links} links were found in the documents"
    );
    assert!(all.is_empty(), "broken links:\n{}", all.join("\n"));
}

#[test]
fn a_broken_link_or_anchor_is_found() {
    let file = root().join("x.md");
    let text = "\
[fine](README.md) and ![fine](docs/figures/panda-laparoscope.png), [fine](BENCHMARKS.md#machines),
[gone](docs/no-such-page.md), [wrong anchor](BENCHMARKS.md#no-such-section) and [web](https://example.com).
`[in code](nowhere.md)`

```sh
[in a block](nowhere.md)
```
";
    let found = problems(&file, text);
    assert_eq!(found.len(), 2, "{found:#?}");
    assert!(found[0].contains("docs/no-such-page.md"), "{}", found[0]);
    assert!(found[1].contains("#no-such-section"), "{}", found[1]);
}

#[test]
fn anchors_follow_githubs_rule() {
    let text =
        "# The QP solver against Clarabel\n## One LU in the core: nalgebra's fixed-size `LU`\n\
                ## Trigonometry: why trocar has its own `sin_cos`\n## Reading\n### Reading\n\
                ```sh\n# not a heading\n```\n";
    let found = anchors(text);
    for a in [
        "the-qp-solver-against-clarabel",
        "one-lu-in-the-core-nalgebras-fixed-size-lu",
        "trigonometry-why-trocar-has-its-own-sin_cos",
        "reading",
        "reading-1",
    ] {
        assert!(found.contains(a), "{a} not in {found:?}");
    }
    assert_eq!(found.len(), 5);
}
