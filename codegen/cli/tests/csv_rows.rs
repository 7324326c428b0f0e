//! `trocar simulate --csv F --every N` / `--dt SECONDS`: which rows the CSV gets, and the
//! errors for bad values.

mod common;

use common::trocar;
use std::path::PathBuf;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("trocar-csv-rows-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// The first column (`t`) of every data row of a CSV file.
fn times(path: &PathBuf) -> Vec<f64> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect()
}

fn run(args: &[&str]) {
    let (code, _, err) = trocar(args);
    assert_eq!(code, 0, "{args:?}: {err}");
}

#[test]
fn every_n_keeps_every_nth_row_and_the_last() {
    let all = scratch("all.csv");
    let thin = scratch("every.csv");
    run(&["simulate", "four-bar", "--csv", all.to_str().unwrap()]);
    run(&[
        "simulate",
        "four-bar",
        "--csv",
        thin.to_str().unwrap(),
        "--every",
        "7",
    ]);
    let (all, thin) = (times(&all), times(&thin));
    let mut expected: Vec<f64> = all.iter().copied().step_by(7).collect();
    if (all.len() - 1) % 7 != 0 {
        expected.push(*all.last().unwrap());
    }
    assert_eq!(thin, expected);
    assert_eq!(thin.first(), Some(&0.0));
    assert_eq!(thin.last(), all.last());
    assert!(
        thin.len() < all.len() / 6,
        "{} of {}",
        thin.len(),
        all.len()
    );
}

#[test]
fn dt_writes_rows_at_that_sample_time() {
    let path = scratch("dt.csv");
    run(&[
        "simulate",
        "4",
        "--csv",
        path.to_str().unwrap(),
        "--dt",
        "0.5",
    ]);
    let t = times(&path);
    // Scenario 4 runs 200 s: 0, 0.5, ..., 200.
    assert_eq!(t.len(), 401, "{:?}", &t[..5.min(t.len())]);
    for (k, &tk) in t.iter().enumerate() {
        assert!((tk - 0.5 * k as f64).abs() < 1e-9, "row {k}: t = {tk}");
    }
    let header = std::fs::read_to_string(&path).unwrap();
    assert!(header.starts_with("t,ep_norm,"), "{header:.40}");
}

#[test]
fn bad_values_name_the_option() {
    let path = scratch("bad.csv");
    let p = path.to_str().unwrap();
    for (args, option) in [
        (vec!["--csv", p, "--every", "0"], "--every"),
        (vec!["--csv", p, "--every", "-3"], "--every"),
        (vec!["--csv", p, "--every", "2.5"], "--every"),
        (vec!["--csv", p, "--dt", "0"], "--dt"),
        (vec!["--csv", p, "--dt", "-0.1"], "--dt"),
        (vec!["--csv", p, "--dt", "nan"], "--dt"),
        (vec!["--csv", p, "--dt", "inf"], "--dt"),
        (vec!["--csv", p, "--dt", "fast"], "--dt"),
        (vec!["--csv", p, "--every", "2", "--dt", "0.1"], "--every"),
        (vec!["--every", "2"], "--csv"),
        (vec!["--dt", "0.1"], "--csv"),
    ] {
        let mut all = vec!["simulate", "four-bar"];
        all.extend(&args);
        let (code, _, err) = trocar(&all);
        assert_eq!(code, 2, "{all:?}: {err}");
        assert!(err.contains(option), "{all:?}: {err}");
    }
    assert!(!path.exists(), "a refused command wrote {}", path.display());
}
