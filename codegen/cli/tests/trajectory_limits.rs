//! The trajectory reader's limits from the command line (docs/RELIABILITY.md F19): a trajectory that
//! never ends (a device, a pipe, named by `--trajectory` or by a description's `[simulation]`
//! section) is refused after `trocar_api::MAX_TRAJECTORY_BYTES` bytes, and a path longer than
//! `trocar_api::MAX_TRAJECTORY_STEPS` control steps before the run (no output is written); each
//! with the limit in the message.

mod common;
use common::{trocar, ur5_with_section};
use std::io::Write;
use std::process::{Command, Stdio};

const Q0: &str =
    "0,-0.7853981633974483,0,-2.356194490192345,0,1.5707963267948966,0.7853981633974483";
const UR5_Q0: &str =
    "0,-1.5707963267948966,1.5707963267948966,-1.5707963267948966,-1.5707963267948966,0";
const TOO_LARGE: &str = "the trajectory is larger than the 67108864 bytes (64 MiB) read";

fn dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!(
        "trocar-trajectory-limits-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn dev_zero_as_a_trajectory_is_refused_after_the_cap() {
    let (code, _, err) = trocar(&[
        "simulate",
        "panda-laparoscope",
        "--trajectory",
        "/dev/zero",
        "--q0",
        Q0,
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains(&format!("/dev/zero: {TOO_LARGE}")), "{err}");

    // Named by a description's [simulation] section.
    let d = dir("section");
    let q0 = UR5_Q0.replace(',', ", ");
    let arm = ur5_with_section(&d, &format!("trajectory = \"/dev/zero\"\nq0 = [{q0}]\n"));
    let (code, _, err) = trocar(&["simulate", arm.to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains(TOO_LARGE), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

/// A pipe that does not end (a writer that keeps writing rows) is refused after the cap too.
#[test]
fn an_endless_pipe_as_a_trajectory_is_refused_after_the_cap() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args([
            "simulate",
            "panda-laparoscope",
            "--trajectory",
            "/dev/stdin",
            "--q0",
            Q0,
        ])
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        let _ = stdin.write_all(b"t,x,y,z,roll\n");
        let row = b"0,0,0,0,0\n".repeat(10_000);
        // Until the reader closes the pipe (or 1 GB, which would be the defect).
        for _ in 0..10_000 {
            if stdin.write_all(&row).is_err() {
                return true;
            }
        }
        false
    });
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains(TOO_LARGE), "{err}");
    assert!(writer.join().unwrap(), "the whole of 1 GB was read");
}

/// A two-row path to t = 2001 s: 1 000 500 steps of 2 ms, more than the cap of 10⁶ (which bounds
/// the trace's memory and the CSV's size), refused at once with the row and the limit; a
/// `--csv` asked for is not written.
#[test]
fn a_path_beyond_the_step_cap_is_refused_before_the_run() {
    let (code, out, err) = trocar(&[
        "eval",
        "panda-laparoscope",
        "--q",
        Q0,
        "--what",
        "fk",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let (_, _, m) = common::json_matrix(&out);
    let tip = [m[0][3], m[1][3], m[2][3]];
    let d = dir("long");
    let path = d.join("long.csv");
    std::fs::write(
        &path,
        format!(
            "t,x,y,z,roll\n0,{0},{1},{2},0\n2001,{0},{1},{2},0\n",
            tip[0], tip[1], tip[2]
        ),
    )
    .unwrap();
    let csv = d.join("out.csv");
    let (code, _, err) = trocar(&[
        "simulate",
        "panda-laparoscope",
        "--trajectory",
        path.to_str().unwrap(),
        "--q0",
        Q0,
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("long.csv:3: column `t`: the path ends at t = 2001 s, 1000500 control steps of 0.002 s; a run takes at most 1000000 steps (2000 s)"),
        "{err}"
    );
    assert!(!csv.exists());
    let _ = std::fs::remove_dir_all(&d);
}
