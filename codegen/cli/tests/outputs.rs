//! Output files: every path is checked before any work (a directory that does not exist, a
//! figure that is neither `.svg` nor `.png`, two outputs naming one file), errors name the option
//! and the path, and files appear only whole, once the command has succeeded.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn trocar(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the trocar binary runs")
}

/// A fresh empty directory under the target directory.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("outputs-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn failure(out: &Output) -> String {
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// `simulate … --csv ok.csv --plot /nonexistent/y.svg` used to run the whole simulation, fail on
/// the plot and leave the CSV: now it stops before simulating and writes nothing.
#[test]
fn a_missing_directory_is_refused_before_the_run() {
    let dir = scratch("missing");
    let out = trocar(
        &[
            "simulate",
            "four-bar",
            "--csv",
            "ok.csv",
            "--plot",
            "no/such/dir/y.svg",
        ],
        &dir,
    );
    let err = failure(&out);
    assert!(
        err.contains("--plot no/such/dir/y.svg") && err.contains("does not exist"),
        "{err}"
    );
    assert!(!err.contains("column"), "the simulation ran: {err}");
    assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
    let out = trocar(&["generate", "dia10_like_zy", "-o", "nope/x.rs"], &dir);
    let err = failure(&out);
    assert!(err.contains("-o nope/x.rs"), "{err}");
}

/// `--plot x.bmp` used to write SVG into `x.bmp`.
#[test]
fn a_figure_must_be_svg_or_png() {
    let dir = scratch("bmp");
    let err = failure(&trocar(&["simulate", "four-bar", "--plot", "x.bmp"], &dir));
    assert!(
        err.contains("--plot x.bmp") && err.contains(".svg"),
        "{err}"
    );
    let err = failure(&trocar(&["simulate", "four-bar", "--plot", "noext"], &dir));
    assert!(err.contains("--plot noext"), "{err}");
    assert!(entries(&dir).is_empty());
}

/// `--csv same.svg --plot same.svg` used to overwrite one with the other silently.
#[test]
fn two_outputs_cannot_be_one_file() {
    let dir = scratch("same");
    let err = failure(&trocar(
        &[
            "simulate",
            "four-bar",
            "--csv",
            "same.svg",
            "--plot",
            "./same.svg",
        ],
        &dir,
    ));
    assert!(err.contains("same file"), "{err}");
    assert!(entries(&dir).is_empty());
}

/// A successful run leaves exactly the requested files, whole, and no temporary ones; an
/// existing file is replaced.
#[test]
fn outputs_appear_whole_and_alone() {
    let dir = scratch("ok");
    std::fs::write(dir.join("trace.csv"), "stale").unwrap();
    let out = trocar(
        &[
            "simulate",
            "four-bar",
            "--csv",
            "trace.csv",
            "--plot",
            "fig.svg",
        ],
        &dir,
    );
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    assert_eq!(entries(&dir), ["fig.svg", "trace.csv"]);
    let csv = std::fs::read_to_string(dir.join("trace.csv")).unwrap();
    assert!(
        csv.starts_with("t,") && csv.lines().count() > 100,
        "{}",
        &csv[..40.min(csv.len())]
    );
    let svg = std::fs::read_to_string(dir.join("fig.svg")).unwrap();
    assert!(svg.trim_end().ends_with("</svg>"));
    let out = trocar(&["generate", "unidirectional", "-o", "m.rs"], &dir);
    assert_eq!(out.status.code(), Some(0), "{out:?}");
    assert!(std::fs::read_to_string(dir.join("m.rs"))
        .unwrap()
        .contains("pub mod unidirectional"));
    assert_eq!(entries(&dir), ["fig.svg", "m.rs", "trace.csv"]);
}

/// A command that fails after the checks (here: an unknown robot) leaves no file either.
#[test]
fn a_failed_command_leaves_nothing() {
    let dir = scratch("failed");
    let err = failure(&trocar(&["generate", "no-such-robot", "-o", "m.rs"], &dir));
    assert!(!err.is_empty());
    let err = failure(&trocar(
        &[
            "simulate",
            "no-such-scenario",
            "--csv",
            "t.csv",
            "--plot",
            "f.png",
        ],
        &dir,
    ));
    assert!(err.contains("unknown scenario"), "{err}");
    assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
}
