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
