//! The documents hold what they say: the README, the changelog, the benchmarks and every page
//! under `docs/`.
//!
//! **Every relative link resolves.** A link's file must exist, and a `#anchor` into a Markdown
//! file must name one of its headings (GitHub's rule: lower case, punctuation dropped, spaces as
//! hyphens, `-1`, `-2`, ... for repeats). Links inside code (fenced blocks and `inline spans`) are
//! text, not links; `http`, `https` and `mailto` links are not followed.
//!
//! **Every `trocar` command runs.** The commands are the lines of the ```sh blocks that start
//! with `cargo run --release --bin trocar -- ` or `trocar ` (a line ending in `\` continues on the
//! next; a ` # ` starts a comment). Each runs against this build's `trocar` binary, in a fresh
//! temporary directory, and must exit with 0 and write the files it names:
//!
//! - an output (the value of `-o`, `--output`, `--csv`, `--plot`, `--animate`, `--snapshot`,
//!   `--c-header`, `--cpp-header`, and the directory of `--cmake`) is written into the temporary
//!   directory under its file name, so the documents' own figures are never rewritten;
//! - an input path that exists relative to the repository's root (`examples/robots/ur5_trocar.toml`)
//!   is given as that file;
//! - a command shown twice runs once.
//!
//! Nothing is shortened. A command that must not run here is listed in [`SKIPPED`] with the
//! reason. Any other `cargo run` line of an ```sh block is an error: a misspelled prefix would
//! otherwise never run. Commands in running text (`trocar simulate 3 --method all`) are not run.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Commands (by a part of their text) that are not run, and why. Empty today.
const SKIPPED: &[(&str, &str)] = &[];

/// The prefixes of a `trocar` command in the documents.
const PREFIXES: [&str; 2] = ["cargo run --release --bin trocar -- ", "trocar "];

/// The options whose value is a file the command writes.
const OUTPUTS: [&str; 8] = [
    "-o",
    "--output",
    "--csv",
    "--plot",
    "--animate",
    "--snapshot",
    "--c-header",
    "--cpp-header",
];
/// The options whose value is a directory the command writes (its package must hold a CMake
/// package file).
const OUTPUT_DIRS: [&str; 1] = ["--cmake"];

/// One command found in a document.
#[derive(Debug, Clone, PartialEq)]
struct DocCommand {
    /// `file:line` of its first line.
    place: String,
    /// Its arguments after the prefix.
    args: Vec<String>,
}

/// The repository's root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The documents: the README, the changelog, the benchmarks and every page under `docs/`.
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

/// Splits a command line into words: whitespace separates, single and double quotes group.
fn words(line: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut word = String::new();
    let mut quote = None;
    let mut any = false;
    for c in line.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), c) => word.push(c),
            (None, '\'' | '"') => {
                quote = Some(c);
                any = true;
            }
            (None, c) if c.is_whitespace() => {
                if any || !word.is_empty() {
                    out.push(std::mem::take(&mut word));
                }
                any = false;
            }
            (None, c) => word.push(c),
        }
    }
    if any || !word.is_empty() {
        out.push(word);
    }
    out
}

/// The `trocar` commands of the ```sh blocks of `markdown` (the text of `name`), or the places of
/// `cargo run` lines that are not `trocar` commands.
fn commands(name: &str, markdown: &str) -> Result<Vec<DocCommand>, Vec<String>> {
    let mut found = Vec::new();
    let mut wrong = Vec::new();
    let mut in_sh = false;
    let mut pending: Option<(usize, String)> = None;
    for (k, raw) in markdown.lines().enumerate() {
        let trimmed = raw.trim();
        if trimmed.starts_with("```") {
            in_sh = !in_sh && trimmed == "```sh";
            continue;
        }
        if !in_sh {
            continue;
        }
        let line = match trimmed.find(" # ") {
            Some(at) => trimmed[..at].trim_end(),
            None => trimmed,
        };
        let (first, text) = match pending.take() {
            Some((first, text)) => (first, format!("{text} {line}")),
            None => (k + 1, line.to_owned()),
        };
        if let Some(continued) = text.strip_suffix('\\') {
            pending = Some((first, continued.trim_end().to_owned()));
            continue;
        }
        let place = format!("{name}:{first}");
        if let Some(rest) = PREFIXES.iter().find_map(|p| text.strip_prefix(p)) {
            found.push(DocCommand {
                place,
                args: words(rest),
            });
        } else if text.starts_with("cargo run") {
            wrong.push(format!(
                "{place}: `{text}` is not a `trocar` command ({PREFIXES:?})"
            ));
        }
    }
    if wrong.is_empty() {
        Ok(found)
    } else {
        Err(wrong)
    }
}

/// A fresh, empty temporary directory.
fn fresh_dir() -> PathBuf {
    static COUNT: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "trocar-doc-commands-{}-{}",
        std::process::id(),
        COUNT.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs one command as the documents show it: outputs into a fresh directory, inputs from the
/// repository. `Err` with the place, the command and the end of its stderr if it failed or did
/// not write an output it names.
fn run(binary: &Path, command: &DocCommand) -> Result<(), String> {
    let dir = fresh_dir();
    let root = root();
    let mut args = Vec::new();
    let mut outputs = Vec::new();
    let mut output_dirs = Vec::new();
    for (k, arg) in command.args.iter().enumerate() {
        let after_output = k > 0 && OUTPUTS.contains(&command.args[k - 1].as_str());
        let after_output_dir = k > 0 && OUTPUT_DIRS.contains(&command.args[k - 1].as_str());
        if after_output_dir {
            let sub = dir.join(Path::new(arg).file_name().unwrap_or(arg.as_ref()));
            output_dirs.push(sub.clone());
            args.push(sub.into_os_string());
        } else if after_output {
            let file = dir.join(Path::new(arg).file_name().unwrap_or(arg.as_ref()));
            outputs.push(file.clone());
            args.push(file.into_os_string());
        } else if !arg.starts_with('-') && arg.contains(['/', '.']) && root.join(arg).exists() {
            args.push(root.join(arg).into_os_string());
        } else {
            args.push(arg.into());
        }
    }
    let shown = format!("{}: trocar {}", command.place, command.args.join(" "));
    let out = Command::new(binary)
        .args(&args)
        .current_dir(&dir)
        // The packages of `--cmake` share one cargo target directory: the runtime built once.
        .env(
            "CARGO_TARGET_DIR",
            Path::new(env!("CARGO_TARGET_TMPDIR")).join("documents-cmake"),
        )
        .output()
        .map_err(|e| format!("{shown}: {e}"))?;
    let result = if !out.status.success() {
        let stderr = String::from_utf8_lossy(&out.stderr);
        let tail: Vec<&str> = stderr.lines().rev().take(5).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        Err(format!(
            "{shown}: {}\n    {}",
            out.status,
            tail.join("\n    ")
        ))
    } else if let Some(missing) = outputs.iter().find(|f| !f.is_file()) {
        Err(format!("{shown}: {} was not written", missing.display()))
    } else if let Some(missing) = output_dirs
        .iter()
        .find(|d| !d.join("lib").join("cmake").is_dir())
    {
        Err(format!(
            "{shown}: {} holds no CMake package",
            missing.display()
        ))
    } else {
        Ok(())
    };
    let _ = std::fs::remove_dir_all(&dir);
    result
}

#[test]
fn every_command_of_the_documents_runs() {
    let mut all: Vec<DocCommand> = Vec::new();
    let mut wrong = Vec::new();
    for doc in documents() {
        let text = std::fs::read_to_string(&doc).unwrap();
        let name = doc
            .strip_prefix(root())
            .unwrap_or(&doc)
            .display()
            .to_string();
        match commands(&name, &text) {
            Ok(found) => {
                for c in found {
                    if !all.iter().any(|a| a.args == c.args) {
                        all.push(c);
                    }
                }
            }
            Err(w) => wrong.extend(w),
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    let to_run: Vec<DocCommand> = all
        .into_iter()
        .filter(|c| {
            let text = c.args.join(" ");
            !SKIPPED.iter().any(|(part, _)| text.contains(part))
        })
        .collect();
    assert!(
        to_run.len() >= 20,
        "only {} commands were found in the documents",
        to_run.len()
    );
    // Two at a time: the longest run a few seconds each.
    let binary = Path::new(env!("CARGO_BIN_EXE_trocar"));
    let next = AtomicUsize::new(0);
    let failures = Mutex::new(Vec::new());
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(command) = to_run.get(k) else {
                    break;
                };
                if let Err(e) = run(binary, command) {
                    failures.lock().unwrap().push(e);
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap();
    assert!(
        failures.is_empty(),
        "commands of the documents that fail:\n{}",
        failures.join("\n")
    );
}

#[test]
fn the_commands_are_found_as_a_shell_reads_them() {
    let md = "\
text `trocar list` in prose is not run
```sh
cargo run --release --bin trocar -- verify dia10_like_zy --samples 20   # a comment
trocar simulate examples/robots/ur5_trocar.toml --trajectory examples/trajectories/ur5-circle.csv \\
    --csv ur5.csv
pip install ./codegen/python
python -c \"import trocar\"
```
```text
trocar generate ROBOT.toml [-o OUT.rs]
```
";
    let found = commands("x.md", md).unwrap();
    assert_eq!(found.len(), 2, "{found:?}");
    assert_eq!(found[0].place, "x.md:3");
    assert_eq!(
        found[0].args,
        ["verify", "dia10_like_zy", "--samples", "20"]
    );
    assert_eq!(found[1].place, "x.md:4");
    assert_eq!(found[1].args.len(), 6);
    assert_eq!(found[1].args[5], "ur5.csv");
    assert_eq!(words("a 'b c' \"d\" ''"), ["a", "b c", "d", ""]);
}

#[test]
fn a_misspelled_command_is_found() {
    // A prefix that is not the binary's is refused where it is written...
    let md = "```sh\ncargo run --release --bin trocr -- list\n```\n";
    let wrong = commands("x.md", md).unwrap_err();
    assert!(wrong[0].starts_with("x.md:2:"), "{wrong:?}");
    // ...and a command the binary does not have, or an output it cannot write, fails its run.
    let binary = Path::new(env!("CARGO_BIN_EXE_trocar"));
    let bad = |text: &str| DocCommand {
        place: "x.md:1".into(),
        args: words(text),
    };
    let err = run(binary, &bad("verfy dia10_like_zy")).unwrap_err();
    assert!(err.contains("x.md:1: trocar verfy dia10_like_zy"), "{err}");
    assert!(run(binary, &bad("eval no-such-robot --q 0")).is_err());
    assert!(run(binary, &bad("list")).is_ok());
    // An output goes into the temporary directory, not where the document names it.
    assert!(run(
        binary,
        &bad("generate unidirectional -o docs/figures/never.rs")
    )
    .is_ok());
    assert!(!root().join("docs/figures/never.rs").exists());
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
