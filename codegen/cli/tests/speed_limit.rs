//! `trocar simulate --max-joint-speed`: the default limit keeps experiment 4.2.1 within 0.1 mm
//! of the trocar (5.7 mm with the pseudo-inverse before the limit existed), `none` gives the
//! thesis's unlimited controller back, and values that are not a positive speed are refused.

use std::process::Command;

fn simulate(args: &[&str]) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_trocar"))
        .arg("simulate")
        .args(args)
        .output()
        .expect("the trocar binary runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The "max RCM drift" figure of the summary.
fn max_drift(summary: &str) -> f64 {
    let rest = summary
        .split("max RCM drift ")
        .nth(1)
        .unwrap_or_else(|| panic!("no drift in {summary}"));
    rest.split_whitespace().next().unwrap().parse().unwrap()
}

#[test]
fn the_default_limit_keeps_the_link_on_the_trocar() {
    let (code, limited) = simulate(&["exp421", "--method", "pinv"]);
    assert_eq!(code, Some(0), "{limited}");
    assert!(limited.contains("joint speed limit 2 rad/s"), "{limited}");
    assert!(max_drift(&limited) <= 1e-4, "{limited}");
    let (code, free) = simulate(&["exp421", "--method", "pinv", "--max-joint-speed", "none"]);
    assert_eq!(code, Some(0), "{free}");
    assert!(free.contains("joint speed limit none"), "{free}");
    assert!(max_drift(&free) > 1e-4, "{free}");
}

#[test]
fn a_limit_must_be_a_positive_speed() {
    for (value, says) in [
        ("=-1", "must be positive"),
        ("=0", "must be positive"),
        ("=fast", "is not a number"),
        ("=1e300", "1e6"),
        ("=NaN", "not finite"),
    ] {
        let arg = format!("--max-joint-speed{value}");
        let (code, err) = simulate(&["exp421", &arg]);
        assert_eq!(code, Some(2), "{arg}: {err}");
        assert!(err.contains(says), "{arg}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
    let (code, err) = simulate(&["four-bar", "--max-joint-speed", "3"]);
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.contains("the joint speed limit apply to the RCM scenarios only"),
        "{err}"
    );
}
