//! Shared by the command-line tests: run the `trocar` binary from the workspace root, read its
//! JSON matrices.
#![allow(dead_code)]

use std::process::Command;

/// Runs `trocar ARGS` in the workspace root: `(exit code, stdout, stderr)`.
pub fn trocar(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args(args)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .output()
        .expect("the trocar binary runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A JSON matrix `{"rows": R, "cols": C, "data": [[row], ...]}` as `(R, C, rows)`.
pub fn json_matrix(text: &str) -> (usize, usize, Vec<Vec<f64>>) {
    let v: serde_json::Value = serde_json::from_str(text.trim()).expect("valid JSON");
    let rows = v["rows"].as_u64().unwrap() as usize;
    let cols = v["cols"].as_u64().unwrap() as usize;
    let data = v["data"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            r.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        })
        .collect();
    (rows, cols, data)
}

/// The Panda laparoscope's start configuration (`--q0`): the ready pose, the shaft pointing
/// down.
pub const PANDA_Q0: &str =
    "0,-0.7853981633974483,0,-2.356194490192345,0,1.5707963267948966,0.7853981633974483";

/// A fresh, empty directory `trocar-<test>-<pid>-<name>` under the system's temporary one.
pub fn fresh_dir(test: &str, name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("trocar-{test}-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The Panda laparoscope's tip at [`PANDA_Q0`], from `trocar eval`.
pub fn panda_tip() -> [f64; 3] {
    let (code, out, err) = trocar(&[
        "eval",
        "panda-laparoscope",
        "--q",
        PANDA_Q0,
        "--what",
        "fk",
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let (_, _, m) = json_matrix(&out);
    [m[0][3], m[1][3], m[2][3]]
}

/// The UR5 example's description with its `[simulation]` section replaced by `section`, written
/// in `d` as `arm.toml` beside a copy of its URDF (`urdf/ur5.urdf`, as the description names it)
/// and of its circle (`circle.csv`).
pub fn ur5_with_section(d: &std::path::Path, section: &str) -> std::path::PathBuf {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples");
    let text = std::fs::read_to_string(format!("{root}/robots/ur5_trocar.toml")).unwrap();
    let head = &text[..text.find("[simulation]").unwrap()];
    std::fs::create_dir_all(d.join("urdf")).unwrap();
    std::fs::copy(
        format!("{root}/robots/urdf/ur5.urdf"),
        d.join("urdf/ur5.urdf"),
    )
    .unwrap();
    std::fs::copy(
        format!("{root}/trajectories/ur5-circle.csv"),
        d.join("circle.csv"),
    )
    .unwrap();
    let path = d.join("arm.toml");
    std::fs::write(&path, format!("{head}[simulation]\n{section}")).unwrap();
    path
}
