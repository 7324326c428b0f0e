//! A URDF chain 20,000 links long: `trocar jacobian` answers for a tip next to the root and for
//! the last link, without overflowing the stack (it used to abort) and in time linear in the
//! file (locating every joint by searching the whole file made the import quadratic: 30 s for
//! this chain in a release build, 1.4 s now). The limit below is a hang detector, not a speed
//! target.

use std::process::Command;
use std::time::{Duration, Instant};

const LINKS: usize = 20_000;

fn deep_urdf() -> std::path::PathBuf {
    let mut text = String::from("<robot name=\"deep\">\n");
    for k in 0..=LINKS {
        text += &format!("<link name=\"l{k}\"/>\n");
    }
    for k in 1..=LINKS {
        text += &format!(
            "<joint name=\"j{k}\" type=\"revolute\"><parent link=\"l{}\"/><child link=\"l{k}\"/>\
             <origin xyz=\"0 0 0.001\" rpy=\"0 0 0\"/><axis xyz=\"{}\"/>\
             <limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/></joint>\n",
            k - 1,
            ["0 0 1", "0 1 0", "1 0 0"][k % 3]
        );
    }
    text += "</robot>\n";
    let path = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("deep.urdf");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_chain_of_twenty_thousand_links_is_read_in_linear_time() {
    let urdf = deep_urdf();
    let q_all = format!("--q={}", vec!["0.01"; LINKS].join(","));
    for (tip, q, columns) in [("l1", "--q=0.1", 1), ("l20000", q_all.as_str(), LINKS)] {
        let start = Instant::now();
        let out = Command::new(env!("CARGO_BIN_EXE_trocar"))
            .args([
                "jacobian",
                "--urdf",
                urdf.to_str().unwrap(),
                "--tip",
                tip,
                q,
                "--json",
            ])
            .output()
            .expect("the trocar binary runs");
        let elapsed = start.elapsed();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "tip {tip}: {stderr}");
        assert!(elapsed < Duration::from_secs(60), "tip {tip}: {elapsed:?}");
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(json["rows"], 6);
        assert_eq!(json["cols"], columns);
        let finite = json["data"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|row| row.as_array().unwrap())
            .all(|v| v.as_f64().is_some_and(f64::is_finite));
        assert!(finite, "tip {tip}");
    }
}
