//! `trocar simulate SCENARIO --method all --plot F`: one figure comparing pinv, DLS and FI, and
//! the usage error for the outputs of one run.

mod common;

use common::trocar;

#[test]
fn method_all_writes_one_comparison_figure() {
    let dir = std::env::temp_dir().join(format!("trocar-method-all-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("x.svg");
    let (code, _, err) = trocar(&[
        "simulate",
        "1",
        "--method",
        "all",
        "--plot",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg"));
    assert!(svg.contains("pinv vs DLS vs FI"), "title");
    for name in ["pinv", "DLS", "FI"] {
        // One legend entry a panel: the text element is the name alone.
        assert_eq!(
            svg.matches(&format!(
                ">
{name}
</text>"
            ))
            .count(),
            4,
            "legend {name}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn method_all_refuses_csv() {
    let dir = std::env::temp_dir().join(format!("trocar-method-all-csv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("f.csv");
    let (code, _, err) = trocar(&[
        "simulate",
        "1",
        "--method",
        "all",
        "--csv",
        path.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--csv") && err.contains("--method all"),
        "{err}"
    );
    assert!(!path.exists());
    std::fs::remove_dir_all(&dir).ok();
}
