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

/// An output path that exists as something other than a regular file (a FIFO here; `/dev/null`
/// in practice) is written in place. Writing it through a temporary and renaming that over the
/// path replaced the node with a plain file: `generate -o /dev/null` run as root turned the
/// machine's `/dev/null` into a regular file that later readers of `/dev/null` then read from.
#[cfg(unix)]
#[test]
fn a_device_or_fifo_is_written_in_place() {
    use std::os::unix::fs::FileTypeExt;
    let dir = scratch("fifo");
    let fifo = dir.join("pipe.rs");
    let made = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    // The reader, a child process so that it can be stopped if the FIFO is never written (it
    // blocks opening the FIFO until a writer opens it).
    let copy = dir.join("../outputs-fifo-read.rs");
    let mut reader = Command::new("cat")
        .arg(&fifo)
        .stdout(std::fs::File::create(&copy).unwrap())
        .spawn()
        .expect("cat runs");
    let out = trocar(&["generate", "unidirectional", "-o", "pipe.rs"], &dir);
    let waited = std::time::Instant::now();
    while reader.try_wait().unwrap().is_none() && waited.elapsed().as_secs() < 10 {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let _ = reader.kill();
    let _ = reader.wait();
    assert!(out.status.success(), "{out:?}");
    let code = std::fs::read_to_string(&copy).unwrap();
    assert!(
        code.contains("pub fn constrained_jacobian"),
        "nothing came through the FIFO: {code}"
    );
    let kind = std::fs::symlink_metadata(&fifo).unwrap().file_type();
    assert!(kind.is_fifo(), "the FIFO was replaced: {kind:?}");
    assert_eq!(entries(&dir), ["pipe.rs"]);
}

/// An output path that is a symbolic link to a file: the file is replaced, the link is kept.
#[cfg(unix)]
#[test]
fn a_symbolic_link_is_followed() {
    let dir = scratch("symlink");
    std::fs::create_dir(dir.join("real")).unwrap();
    std::fs::write(dir.join("real/arm.rs"), "old").unwrap();
    std::os::unix::fs::symlink("real/arm.rs", dir.join("arm.rs")).unwrap();
    let out = trocar(&["generate", "unidirectional", "-o", "arm.rs"], &dir);
    assert!(out.status.success(), "{out:?}");
    assert!(dir.join("arm.rs").is_symlink(), "the link was replaced");
    let code = std::fs::read_to_string(dir.join("real/arm.rs")).unwrap();
    assert!(code.contains("pub fn constrained_jacobian"), "{code}");
    assert_eq!(entries(&dir), ["arm.rs", "real"]);
    assert_eq!(entries(&dir.join("real")), ["arm.rs"]);
}
