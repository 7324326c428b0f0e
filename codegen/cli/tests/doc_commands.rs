//! Every `trocar` command the documents show still runs: the README and every page under `docs/`.
//!
//! The commands are the lines of their ```sh blocks that start with `cargo run --release --bin
//! trocar -- ` or `trocar ` (a line ending in `\` continues on the next; a ` # ` starts a
//! comment). Each runs against this build's `trocar` binary, in a fresh temporary directory, and
//! must exit with 0 and write the files it names:
//!
//! - an output (the value of `-o`, `--output`, `--csv`, `--plot`, `--animate`, `--snapshot`,
//!   `--c-header`) is written into the temporary directory under its file name, so the documents'
//!   own figures are never rewritten;
//! - an input path that exists relative to the repository's root (`examples/robots/ur5_trocar.toml`)
//!   is given as that file;
//! - a command shown twice runs once.
//!
//! Nothing is shortened. A command that must not run here is listed in [`SKIPPED`] with the
//! reason. Any other `cargo run` line of an ```sh block is an error: a misspelled prefix would
//! otherwise never run. Commands in running text (`trocar simulate 3 --method all`) are not run.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// Commands (by a part of their text) that are not run, and why. Empty today.
const SKIPPED: &[(&str, &str)] = &[];

/// The prefixes of a `trocar` command in the documents.
const PREFIXES: [&str; 2] = ["cargo run --release --bin trocar -- ", "trocar "];

/// The options whose value is a file the command writes.
const OUTPUTS: [&str; 7] = [
    "-o",
    "--output",
    "--csv",
    "--plot",
    "--animate",
    "--snapshot",
    "--c-header",
];

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

/// The documents whose commands run.
fn documents() -> Vec<PathBuf> {
    let root = root();
    let mut out = vec![root.join("README.md")];
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
    out.sort();
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
    for (k, arg) in command.args.iter().enumerate() {
        let after_output = k > 0 && OUTPUTS.contains(&command.args[k - 1].as_str());
        if after_output {
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
