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

/// The dot files in `dir` (the temporaries of a running command).
fn hidden(dir: &Path) -> Vec<String> {
    entries(dir)
        .into_iter()
        .filter(|n| n.starts_with('.'))
        .collect()
}

/// Starts `trocar args…` in `dir` and waits (up to 60 s) until `count` temporaries exist there.
fn start_with_temporaries(args: &[&str], dir: &Path, count: usize) -> std::process::Child {
    let child = Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args(args)
        .current_dir(dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("the trocar binary runs");
    let start = std::time::Instant::now();
    while hidden(dir).len() < count {
        assert!(
            start.elapsed().as_secs() < 60,
            "no temporaries before the run: {:?}",
            entries(dir)
        );
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    child
}

/// Issue 27, item 1: the temporaries are made up front (which checks that the directory is
/// writable), exclusively, under unpredictable names that keep the extension (they were
/// `.<name>.partial-<pid>.<ext>`, made by a plain create that followed links, only when the
/// output was written), and SIGTERM or SIGINT removes them: the process exits with 143 or 130
/// and leaves nothing.
#[cfg(unix)]
#[test]
fn an_interrupted_command_leaves_nothing() {
    for (signal, code) in [("-TERM", 143), ("-INT", 130)] {
        let dir = scratch(&format!("signal{code}"));
        let mut child = start_with_temporaries(
            &["simulate", "1", "--csv", "t.csv", "--plot", "f.svg"],
            &dir,
            2,
        );
        let temps = hidden(&dir);
        for (t, ext) in temps.iter().zip([".svg", ".csv"]) {
            assert!(!t.contains("partial"), "{t}");
            // `.f.` or `.t.`, six random characters, the extension.
            assert!(
                t.ends_with(ext) && t.len() == 3 + 6 + ext.len(),
                "{temps:?}"
            );
        }
        let killed = Command::new("kill")
            .args([signal, &child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let status = child.wait().unwrap();
        assert_eq!(status.code(), Some(code), "{status:?}");
        assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
    }
}

/// Issue 27, item 1: a replaced file keeps its permission mode (the temporary's, 0644, replaced
/// it).
#[cfg(unix)]
#[test]
fn a_replaced_file_keeps_its_mode() {
    use std::os::unix::fs::PermissionsExt;
    let dir = scratch("mode");
    std::fs::write(dir.join("m.rs"), "old").unwrap();
    std::fs::set_permissions(dir.join("m.rs"), std::fs::Permissions::from_mode(0o600)).unwrap();
    let out = trocar(&["generate", "unidirectional", "-o", "m.rs"], &dir);
    assert!(out.status.success(), "{out:?}");
    let meta = std::fs::metadata(dir.join("m.rs")).unwrap();
    assert_eq!(meta.permissions().mode() & 0o7777, 0o600);
    assert!(std::fs::read_to_string(dir.join("m.rs"))
        .unwrap()
        .contains("pub fn constrained_jacobian"));
}

/// Issue 27, item 2: `generate X.toml -o X.toml` replaced the description by the module, and
/// `-o` the URDF it reads replaced the URDF; also through a symbolic link.
#[cfg(unix)]
#[test]
fn an_output_cannot_be_an_input() {
    let dir = scratch("input");
    let robots = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../runtime/model/robots");
    std::fs::create_dir(dir.join("urdf")).unwrap();
    for f in [
        "panda-laparoscope.toml",
        "urdf/panda.urdf",
        "unidirectional.toml",
    ] {
        std::fs::copy(robots.join(f), dir.join(f)).unwrap();
    }
    std::os::unix::fs::symlink("urdf/panda.urdf", dir.join("link.rs")).unwrap();
    let before = |f: &str| std::fs::read(dir.join(f)).unwrap();
    let (toml, urdf, uni) = (
        before("panda-laparoscope.toml"),
        before("urdf/panda.urdf"),
        before("unidirectional.toml"),
    );
    for (robot, out) in [
        ("unidirectional.toml", "unidirectional.toml"),
        ("unidirectional.toml", "./unidirectional.toml"),
        ("panda-laparoscope.toml", "panda-laparoscope.toml"),
        ("panda-laparoscope.toml", "urdf/panda.urdf"),
        ("panda-laparoscope.toml", "link.rs"),
    ] {
        let err = failure(&trocar(&["generate", robot, "-o", out], &dir));
        assert!(
            err.contains(&format!("-o {out}")) && err.contains("reads"),
            "{err}"
        );
    }
    // `simulate --trajectory` reads the trajectory.
    std::fs::write(dir.join("path.csv"), "t,x,y,z\n0,0,0,0\n").unwrap();
    let err = failure(&trocar(
        &[
            "simulate",
            "panda-laparoscope.toml",
            "--trajectory",
            "path.csv",
            "--csv",
            "path.csv",
        ],
        &dir,
    ));
    assert!(
        err.contains("--csv path.csv") && err.contains("reads"),
        "{err}"
    );
    assert_eq!(before("path.csv"), b"t,x,y,z\n0,0,0,0\n");
    std::fs::remove_file(dir.join("path.csv")).unwrap();
    assert_eq!(before("panda-laparoscope.toml"), toml);
    assert_eq!(before("urdf/panda.urdf"), urdf);
    assert_eq!(before("unidirectional.toml"), uni);
    assert_eq!(
        entries(&dir),
        [
            "link.rs",
            "panda-laparoscope.toml",
            "unidirectional.toml",
            "urdf"
        ]
    );
}

/// Issue 27, item 3: a CSV through a dangling symbolic link was written in place as soon as
/// the run ended and stayed after a later failure; a rename that fails at the commit (here: a
/// directory put where the figure goes while the simulation runs) now puts back what was
/// already replaced: all outputs or none.
#[cfg(unix)]
#[test]
fn outputs_are_committed_all_or_none() {
    let dir = scratch("rollback");
    std::os::unix::fs::symlink("real.csv", dir.join("link.csv")).unwrap();
    std::fs::write(dir.join("old.svg"), "old figure").unwrap();
    let child = start_with_temporaries(
        &[
            "simulate",
            "3",
            "--csv",
            "link.csv",
            "--plot",
            "old.svg",
            "--snapshot",
            "fig.svg",
        ],
        &dir,
        3,
    );
    std::fs::create_dir_all(dir.join("fig.svg/in-the-way")).unwrap();
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    assert!(!dir.join("real.csv").exists(), "the CSV was written");
    assert!(dir.join("link.csv").is_symlink());
    assert_eq!(
        std::fs::read_to_string(dir.join("old.svg")).unwrap(),
        "old figure"
    );
    assert_eq!(entries(&dir), ["fig.svg", "link.csv", "old.svg"]);
}

/// Issue 27, item 3: two dangling links to one file are one output.
#[cfg(unix)]
#[test]
fn two_dangling_links_to_one_file_are_one_output() {
    let dir = scratch("two-links");
    std::os::unix::fs::symlink("t.out", dir.join("a.csv")).unwrap();
    std::os::unix::fs::symlink("t.out", dir.join("b.svg")).unwrap();
    let err = failure(&trocar(
        &["simulate", "four-bar", "--csv", "a.csv", "--plot", "b.svg"],
        &dir,
    ));
    assert!(err.contains("same file"), "{err}");
    assert_eq!(entries(&dir), ["a.csv", "b.svg"]);
}

/// Issue 27, item 3: a 243-byte file name failed after the work (its temporary's name was too
/// long); a name longer than 255 bytes is refused before any work (the robot, unknown here, is
/// not even read).
#[test]
fn long_file_names() {
    let dir = scratch("long-name");
    let name = format!("{}.rs", "m".repeat(240));
    let out = trocar(&["generate", "unidirectional", "-o", &name], &dir);
    assert!(out.status.success(), "{out:?}");
    assert_eq!(entries(&dir), [name]);
    let name = format!("{}.rs", "m".repeat(253));
    let err = failure(&trocar(&["generate", "no-such-robot", "-o", &name], &dir));
    assert!(err.contains("file name is 256 bytes"), "{err}");
}

/// Issue 27, item 3: a directory that cannot be written was found only after the work.
#[cfg(target_os = "linux")]
#[test]
fn an_unwritable_directory_is_refused_before_the_work() {
    let dir = scratch("unwritable");
    // /proc takes no new files, not even root's.
    let err = failure(&trocar(
        &["generate", "no-such-robot", "-o", "/proc/m.rs"],
        &dir,
    ));
    assert!(
        err.contains("-o /proc/m.rs: cannot write in the directory /proc"),
        "{err}"
    );
    assert!(!err.contains("at path"), "{err}");
}

/// Issue 27, item 3: `--plot fig.svg` with `fig.svg -> data.txt` was accepted and failed after
/// the run (the temporary took the extension `.txt`); the figure's format follows the name
/// given.
#[cfg(unix)]
#[test]
fn a_figure_through_a_link_has_the_format_of_its_name() {
    let dir = scratch("figure-link");
    std::fs::write(dir.join("data.txt"), "old").unwrap();
    std::os::unix::fs::symlink("data.txt", dir.join("fig.svg")).unwrap();
    let out = trocar(&["simulate", "exp421", "--plot", "fig.svg"], &dir);
    assert!(out.status.success(), "{out:?}");
    let svg = std::fs::read_to_string(dir.join("data.txt")).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..svg.len().min(40)]);
    // A closed chain's figure came out as SVG whatever the name.
    std::os::unix::fs::symlink("data.bin", dir.join("fig.png")).unwrap();
    let out = trocar(&["simulate", "four-bar", "--plot", "fig.png"], &dir);
    assert!(out.status.success(), "{out:?}");
    let png = std::fs::read(dir.join("data.bin")).unwrap();
    assert!(
        png.starts_with(b"\x89PNG"),
        "{:?}",
        &png[..png.len().min(8)]
    );
    assert_eq!(
        entries(&dir),
        ["data.bin", "data.txt", "fig.png", "fig.svg"]
    );
}

/// Issue 27, item 4: `trocar simulate four-bar 2>&1 | head -1` exited with 101 (`eprintln!`
/// panicked on the broken pipe), and so did any write of stderr to a full device.
#[cfg(target_os = "linux")]
#[test]
fn a_lost_stderr_ends_quietly() {
    let dir = scratch("stderr");
    let run = |args: &[&str], stderr: std::process::Stdio| {
        Command::new(env!("CARGO_BIN_EXE_trocar"))
            .args(args)
            .current_dir(&dir)
            .stdout(std::process::Stdio::null())
            .stderr(stderr)
            .status()
            .unwrap()
            .code()
    };
    let full = || {
        std::fs::File::options()
            .write(true)
            .open("/dev/full")
            .unwrap()
    };
    assert_eq!(run(&["simulate", "four-bar"], full().into()), Some(0));
    assert_eq!(
        run(&["eval", "no-such-robot", "--q", "0"], full().into()),
        Some(1)
    );
    assert_eq!(
        run(
            &[
                "eval",
                "planar-stewart",
                "--q=0,0,0,0,0,0,0,0,0",
                "--what",
                "det"
            ],
            full().into()
        ),
        Some(0)
    );
    // A pipe whose reader has gone.
    let mut child = Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args(["simulate", "four-bar"])
        .current_dir(&dir)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stderr.take());
    assert_eq!(child.wait().unwrap().code(), Some(0));
}
