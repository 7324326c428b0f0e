//! `trocar simulate three-ports`: the scene of two instruments and an endoscope, each arm
//! through its own port. From the CSV: the shafts keep their safety distance at every row, every
//! port holds, every joint keeps its range and speed (the Panda's URDF, read here), and every
//! joint's rate changes by at most its acceleration limit a step; options that do not apply to
//! a scene are refused, and so is a still of one arm; `--animate` draws every arm.

mod common;

use common::{fresh_dir, trocar};
use std::path::Path;

/// Runs `trocar simulate SCENE --method qp --csv` and reads the CSV: its columns and rows.
fn run_csv(scene: &str) -> (Vec<String>, Vec<Vec<f64>>, String) {
    let dir = fresh_dir("scenes", scene);
    let csv = dir.join("run.csv");
    let (code, _, stderr) = trocar(&[
        "simulate",
        scene,
        "--method",
        "qp",
        "--csv",
        csv.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let mut lines = text.lines();
    let columns = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (columns, rows, stderr)
}

#[test]
fn three_ports_from_the_command_line() {
    let (columns, rows, stderr) = run_csv("three-ports");
    assert!(stderr.contains("min shaft distance"), "{stderr}");
    let col = |name: &str| {
        columns
            .iter()
            .position(|c| *c == name)
            .unwrap_or_else(|| panic!("{name}"))
    };
    assert_eq!(&columns[..3], &["t", "q1", "q2"]);
    assert_eq!(columns[22], "qd1");
    // The Panda's limits from its URDF.
    let urdf = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../runtime/model/robots/urdf/panda.urdf"),
    )
    .unwrap();
    let attr = |tag: &str, name: &str| -> f64 {
        let key = format!(" {name}=\"");
        let start = tag.find(&key).unwrap() + key.len();
        tag[start..start + tag[start..].find('"').unwrap()]
            .parse()
            .unwrap()
    };
    let limits: Vec<[f64; 4]> = urdf
        .lines()
        .filter(|l| l.trim_start().starts_with("<limit "))
        .map(|l| ["lower", "upper", "velocity", "acceleration"].map(|n| attr(l, n)))
        .collect();
    assert_eq!(limits.len(), 7);
    let dt = rows[1][0] - rows[0][0];
    for (i, row) in rows.iter().enumerate() {
        assert!(
            row[col("min_shaft_distance")] >= 0.010 * (1.0 - 1e-6),
            "row {i}"
        );
        for arm in ["left", "right", "endoscope"] {
            assert!(
                row[col(&format!("{arm}.rcm_drift"))] <= 1e-4,
                "row {i}: {arm}"
            );
        }
        for k in 0..21 {
            let [lo, hi, speed, acceleration] = limits[k % 7];
            let q = row[col(&format!("q{}", k + 1))];
            let qd = row[col(&format!("qd{}", k + 1))];
            assert!(q >= lo && q <= hi, "row {i}: q{} = {q}", k + 1);
            assert!(qd.abs() <= speed, "row {i}: qd{} = {qd}", k + 1);
            if i > 0 && i + 1 < rows.len() {
                let before = rows[i - 1][col(&format!("qd{}", k + 1))];
                assert!(
                    (qd - before).abs() <= acceleration * dt * (1.0 + 1e-9),
                    "row {i}: joint {} changes its rate by {}",
                    k + 1,
                    qd - before
                );
            }
        }
    }
}

/// `trocar simulate dia10-dual`: both drifts within 1e-4 m, the holding tip within 1e-4 m of
/// its start, the cutting tip within 1 mm of its path after 1 s, the shafts beyond the coupling's
/// influence; one torso (its rate in both arms is the one column `qd1`).
#[test]
fn dia10_dual_from_the_command_line() {
    let (columns, rows, _) = run_csv("dia10-dual");
    let col = |name: &str| columns.iter().position(|c| *c == name).unwrap();
    assert_eq!(
        columns.len(),
        36,
        "t, 15 joints, 15 rates, two columns per arm, min_shaft_distance"
    );
    for row in &rows {
        // The shafts stay beyond the coupling's influence (30 mm): the cut leads away.
        assert!(row[col("min_shaft_distance")] > 0.03, "t = {}", row[0]);
        assert!(row[col("left.rcm_drift")] <= 1e-4 && row[col("right.rcm_drift")] <= 1e-4);
        assert!(row[col("left.ep_norm")] <= 1e-4, "t = {}", row[0]);
        if row[0] >= 1.0 {
            assert!(row[col("right.ep_norm")] <= 1e-3, "t = {}", row[0]);
        }
    }
}

#[test]
fn what_does_not_apply_to_a_scene_is_refused() {
    let (code, _, stderr) = trocar(&["simulate", "three-ports", "--method", "dls"]);
    assert_eq!(code, 1);
    assert!(stderr.contains("is a scene of several arms"), "{stderr}");
    let png = std::env::temp_dir().join(format!("trocar-scenes-{}.png", std::process::id()));
    let (code, _, stderr) = trocar(&[
        "simulate",
        "three-ports",
        "--snapshot",
        png.to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert!(
        stderr.contains("is a scene of several arms: --animate draws it"),
        "{stderr}"
    );
    assert!(!png.exists());
}

/// `--animate` draws every arm of a scene: a GIF of the run's frames.
#[test]
fn a_scene_is_animated() {
    let dir = fresh_dir("scenes", "animate");
    for scene in ["three-ports", "dia10-dual"] {
        let gif = dir.join(format!("{scene}.gif"));
        let (code, _, stderr) = trocar(&["simulate", scene, "--animate", gif.to_str().unwrap()]);
        assert_eq!(code, 0, "{stderr}");
        let bytes = std::fs::read(&gif).unwrap();
        assert!(bytes.starts_with(b"GIF89a"), "{scene}");
        // Each frame has its graphic control extension (0x21 0xF9 0x04).
        let frames = bytes
            .windows(3)
            .filter(|w| *w == [0x21, 0xF9, 0x04])
            .count();
        assert!(frames >= 50, "{scene}: {frames} frames");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `trocar generate SCENE`: a shipped scene by name, and a scene file of one's own whose arms'
/// descriptions are files beside it; its errors name the file, line and field, write nothing,
/// and what applies to one robot only (the C header) is refused.
#[test]
fn a_scene_is_generated() {
    let dir = fresh_dir("scenes", "generate");
    let out = dir.join("three_ports.rs");
    let (code, _, stderr) = trocar(&["generate", "three-ports", "-o", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    let code_text = std::fs::read_to_string(&out).unwrap();
    assert!(code_text.starts_with("// This file is @generated by trocar-codegen."));
    assert!(code_text.contains("pub mod three_ports {"));
    assert!(code_text.contains("pub mod panda_laparoscope {"));
    assert!(code_text.contains("pub fn step<"));
    // One module for the three arms of one description.
    assert_eq!(code_text.matches("pub mod panda_laparoscope {").count(), 1);

    // A scene file of one's own: two reference arms facing each other, their tips coupled.
    let arm = trocar_model::description::preset("dia10_like_zy").unwrap();
    std::fs::write(dir.join("arm.toml"), arm).unwrap();
    let scene = dir.join("pair.toml");
    let text = "[scene]\nname = \"pair\"\n\n[[arms]]\nname = \"a\"\nrobot = \"arm.toml\"\nq0 = [0, -0.3, 0.9, 0.28, -0.62, 0.1, 0.5, 0.3]\n\n[[arms]]\nname = \"b\"\nrobot = \"arm.toml\"\nbase = { xyz = [0.05, 2.4, 0], rpy = [0, 0, 3.141592653589793] }\nq0 = [0, -0.3, 0.9, 0.28, -0.62, 0.1, 0.5, 0.3]\n\n[[couplings]]\nbetween = [\"a\", \"b\"]\nkind = \"tips\"\nsafety = 0.01\ninfluence = 0.03\n";
    std::fs::write(&scene, text).unwrap();
    let (code, stdout, stderr) = trocar(&["generate", scene.to_str().unwrap(), "--real", "f32"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("pub mod pair {") && stdout.contains("Between::Tips"));
    assert!(stdout.contains("pub mod dia10_like_zy {"));

    // An unknown arm in a coupling: located, and nothing written.
    std::fs::write(
        &scene,
        text.replace("between = [\"a\", \"b\"]", "between = [\"a\", \"c\"]"),
    )
    .unwrap();
    let bad = dir.join("bad.rs");
    let (code, _, stderr) = trocar(&[
        "generate",
        scene.to_str().unwrap(),
        "-o",
        bad.to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert!(
        stderr.contains("pair.toml:16:17:") && stderr.contains("couplings[0].between[1]"),
        "{stderr}"
    );
    assert!(!bad.exists());
    // The C header is for one robot.
    let (code, _, stderr) = trocar(&["generate", "dia10-dual", "--c-header", "-"]);
    assert_ne!(code, 0);
    assert!(stderr.contains("is a scene"), "{stderr}");
    // And a command for one robot refuses a scene file, saying what takes it.
    let shipped =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../runtime/model/scenes/three-ports.toml");
    let (code, _, stderr) = trocar(&["verify", shipped.to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(
        stderr.contains("a scene of several arms") && stderr.contains("trocar generate"),
        "{stderr}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
