//! Golden output of every shipped robot, closed mechanism and generated-code fixture, in `f32` and
//! `f64` (`tests/snapshots/shipped/<file>_<real>.rs`). Any change in emitted code shows here as a
//! diff: the test rewrites the file and fails, so re-running after review blesses it.

use std::path::{Path, PathBuf};
use trocar_codegen::{Builder, Scalar};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// `(file stem, path of the description, is a mechanism)`.
fn sources() -> Vec<(String, PathBuf, bool)> {
    let mut out = Vec::new();
    for dir in [
        "runtime/model/robots",
        "tests/generated/robots",
        "examples/robots",
    ] {
        let mut files: Vec<PathBuf> = std::fs::read_dir(root().join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "toml"))
            .collect();
        files.sort();
        for f in files {
            out.push((
                f.file_stem().unwrap().to_string_lossy().into_owned(),
                f,
                false,
            ));
        }
    }
    // The cooperative arms have a non-square J_Cp: no closed form (tested elsewhere).
    for m in ["four-bar", "planar-stewart"] {
        let p = root().join(format!("runtime/model/robots/mechanisms/{m}.toml"));
        out.push((m.to_string(), p, true));
    }
    out
}

#[test]
fn every_shipped_module_matches_its_golden_file() {
    let mut changed = Vec::new();
    for (stem, path, mechanism) in sources() {
        for (real, tag) in [(Scalar::F32, "f32"), (Scalar::F64, "f64")] {
            let mut b = Builder::new();
            if mechanism {
                b.mechanism(&path);
            } else {
                b.robot(&path);
            }
            let modules = b
                .real(real)
                .emit_rerun_if_changed(false)
                .generate()
                .unwrap();
            assert_eq!(modules.len(), 1, "{}", path.display());
            let text = modules.into_values().next().unwrap();
            let golden = Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("tests/snapshots/shipped/{stem}_{tag}.rs"));
            let old = std::fs::read_to_string(&golden).unwrap_or_default();
            if old != text {
                std::fs::write(&golden, &text).unwrap();
                changed.push(golden.display().to_string());
            }
        }
    }
    assert!(
        changed.is_empty(),
        "rewritten — review the diff and re-run: {changed:#?}"
    );
}
