//! The README's Rust snippets are this crate's code: every line of every ```rust block of the
//! README (and of `docs/generated-code.md`), in order, is a line of `build.rs` followed by
//! `src/lib.rs` (leading whitespace aside).
//! The crate itself compiles (it is a workspace member), so the README's snippets do.

use std::path::Path;

/// The ```rust blocks of a Markdown text, as lists of lines.
fn rust_blocks(markdown: &str) -> Vec<Vec<String>> {
    let mut blocks = Vec::new();
    let mut current: Option<Vec<String>> = None;
    for line in markdown.lines() {
        match (&mut current, line.trim_start()) {
            (None, l) if l.starts_with("```rust") => current = Some(Vec::new()),
            (Some(_), l) if l.starts_with("```") => blocks.extend(current.take()),
            (Some(b), _) => b.push(line.to_owned()),
            (None, _) => {}
        }
    }
    blocks
}

/// The position after the lines of `block` found in order in `code`, from `from`.
fn find_in_order(code: &[&str], from: usize, block: &[String]) -> Result<usize, String> {
    let mut at = from;
    for line in block.iter().map(|l| l.trim()).filter(|l| !l.is_empty()) {
        match code[at..].iter().position(|c| c.trim() == line) {
            Some(k) => at += k + 1,
            None => return Err(line.to_owned()),
        }
    }
    Ok(at)
}

#[test]
fn the_readme_shows_this_crates_code() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let code = std::fs::read_to_string(here.join("build.rs")).unwrap()
        + &std::fs::read_to_string(here.join("src/lib.rs")).unwrap();
    let lines: Vec<&str> = code.lines().collect();
    // The README's tour and the guide's page on generated code show the same crate.
    for page in ["README.md", "docs/generated-code.md"] {
        let text = std::fs::read_to_string(here.join("../..").join(page)).unwrap();
        let blocks = rust_blocks(&text);
        assert!(
            blocks.len() >= 3,
            "the Rust snippets of {page} were not found"
        );
        let mut at = 0;
        for block in &blocks {
            at = find_in_order(&lines, at, block).unwrap_or_else(|line| {
                panic!("{page} line `{line}` is not in examples/readme (build.rs, src/lib.rs)")
            });
        }
    }
}

#[test]
fn a_changed_snippet_is_found() {
    let code = ["fn main() {", "    a();", "}"];
    let block = |s: &str| s.lines().map(str::to_owned).collect::<Vec<_>>();
    assert!(find_in_order(&code, 0, &block("fn main() {\n  a();\n}")).is_ok());
    assert_eq!(
        find_in_order(&code, 0, &block("fn main() {\n  b();\n}")),
        Err("b();".to_owned())
    );
    let md = "x\n```rust,ignore\nlet a = 1;\n```\n```sh\nls\n```\n";
    assert_eq!(rust_blocks(md), vec![vec!["let a = 1;".to_owned()]]);
}

/// The README's dependency lines named only a version (`trocar-check = "0.1"`) of crates that are
/// not on crates.io: every `trocar` crate a TOML block of the README depends on is given by
/// `path` or `git` (docs/RELIABILITY.md F26).
#[test]
fn the_readmes_dependency_lines_work_today() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(here.join("../../README.md")).unwrap();
    let mut in_toml = false;
    let mut seen = 0;
    for line in readme.lines() {
        if line.starts_with("```") {
            in_toml = line.trim() == "```toml";
            continue;
        }
        let inline = line.contains("trocar = {") || line.contains("trocar-");
        let dependency = line.split_once(" = ").is_some_and(|(name, _)| {
            name.trim().starts_with("trocar") && !name.contains(' ') && !name.contains('`')
        });
        if (in_toml && dependency) || (!in_toml && inline && line.contains("version = \"0.")) {
            seen += usize::from(in_toml);
            assert!(
                line.contains("path = ") || line.contains("git = "),
                "README: `{line}` names a crate not on crates.io; give it by path or git"
            );
        }
    }
    assert!(seen >= 3, "the README's dependency lines were not found");
}

/// The documents the examples' crate documentation points to exist (`examples/cpp/src/lib.rs`
/// pointed to an `examples/cpp/README.md` that was not there).
#[test]
fn the_documents_the_examples_point_to_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut checked = 0;
    for dir in std::fs::read_dir(root.join("examples")).unwrap() {
        let lib = dir.unwrap().path().join("src/lib.rs");
        let Ok(text) = std::fs::read_to_string(&lib) else {
            continue;
        };
        for quoted in text.split('`').skip(1).step_by(2) {
            if quoted.starts_with("examples/") && quoted.ends_with(".md") {
                assert!(
                    root.join(quoted).is_file(),
                    "{} points to {quoted}, which does not exist",
                    lib.display()
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 1, "no document pointed to was found");
}
