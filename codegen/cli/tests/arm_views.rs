//! `trocar simulate --animate / --snapshot`: the 3-D views of a serial arm. Their paths are
//! checked with the other outputs before the simulation runs (errors name the option and the
//! path), closed mechanisms refuse them, and a serial scenario writes a GIF and a PNG.

mod common;

use common::trocar;
use std::path::PathBuf;

/// A fresh empty directory under the target directory.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("arm-views-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn entries(dir: &std::path::Path) -> usize {
    std::fs::read_dir(dir).unwrap().count()
}

/// A scenario that does not exist would fail in the run: the wrong extensions are reported
/// instead, so they were checked first.
#[test]
fn wrong_extensions_are_refused_before_the_run() {
    let dir = scratch("extensions");
    let png = dir.join("arm.png");
    let (code, _, err) = trocar(&["simulate", "no-such", "--animate", png.to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!("--animate {}", png.display())) && err.contains("GIF"),
        "{err}"
    );
    let gif = dir.join("arm.gif");
    let (code, _, err) = trocar(&["simulate", "no-such", "--snapshot", gif.to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains(&format!("--snapshot {}", gif.display())) && err.contains("SVG or PNG"),
        "{err}"
    );
    assert!(!err.contains("unknown scenario"), "{err}");
    assert_eq!(entries(&dir), 0);
}

#[test]
fn a_mechanism_refuses_the_views_before_the_run() {
    let dir = scratch("mechanism");
    let gif = dir.join("four-bar.gif");
    let csv = dir.join("four-bar.csv");
    let (code, _, err) = trocar(&[
        "simulate",
        "four-bar",
        "--csv",
        csv.to_str().unwrap(),
        "--animate",
        gif.to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("--animate") && err.contains("closed-chain") && err.contains("serial arms"),
        "{err}"
    );
    // No summary: the mechanism did not run.
    assert!(!err.contains("column"), "{err}");
    assert_eq!(entries(&dir), 0);
}

#[test]
fn snapshot_times_outside_the_scenario_are_refused_before_the_run() {
    let dir = scratch("times");
    let png = dir.join("s.png");
    let (code, _, err) = trocar(&[
        "simulate",
        "exp421",
        "--snapshot",
        png.to_str().unwrap(),
        "--snapshot-times",
        "0,50",
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("--snapshot-times 50") && err.contains("0 to 10 s"),
        "{err}"
    );
    assert!(!err.contains("max RCM drift"), "{err}");
    assert_eq!(entries(&dir), 0);
}

#[test]
fn a_serial_scenario_writes_the_animation_and_the_snapshot() {
    let dir = scratch("written");
    let gif = dir.join("exp421.gif");
    let png = dir.join("exp421.png");
    let (code, _, err) = trocar(&[
        "simulate",
        "exp421",
        "--animate",
        gif.to_str().unwrap(),
        "--snapshot",
        png.to_str().unwrap(),
        "--snapshot-times",
        "0,5,10",
    ]);
    assert_eq!(code, 0, "{err}");
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::Indexed);
    let mut decoder = options
        .read_info(std::fs::File::open(&gif).unwrap())
        .unwrap();
    let mut frames = 0;
    while decoder.read_next_frame().unwrap().is_some() {
        frames += 1;
    }
    assert_eq!(frames, 50);
    let p = std::fs::read(&png).unwrap();
    assert_eq!(&p[1..4], b"PNG");
    // Only the two files: no temporaries left.
    assert_eq!(entries(&dir), 2);
}
