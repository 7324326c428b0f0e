//! `trocar eval` where a closed form is not finite: the error says which parameter it divides by
//! and its value (it used to guess "a parameter that divides is zero?"), exit code 1, no output.

use std::process::Command;

const Q: &str = "--q=0,-0.3,0.9,0.2,-0.6,0.1,0.5,0.3";

fn eval(args: &[&str]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args(["eval", "bidirectional-zy", Q])
        .args(args)
        .output()
        .expect("the trocar binary runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn the_error_names_the_divisor_and_its_value() {
    // At 1e-300, J^r (1/l_a = 1e300) is finite and printed; w (1/l_a²) overflows.
    for (l_a, shown, kind, whats) in [
        (
            "0",
            "`l_a` = 0e0",
            "zero or subnormal",
            &["manip", "jr"][..],
        ),
        (
            "-0",
            "`l_a` = -0e0",
            "zero or subnormal",
            &["manip", "jr"][..],
        ),
        ("1e-300", "`l_a` = 1e-300", "overflowed", &["manip"][..]),
    ] {
        for &what in whats {
            let (code, stdout, stderr) = eval(&["--param", &format!("l_a={l_a}"), "--what", what]);
            assert_eq!(code, Some(1), "{l_a} {what}: {stderr}");
            assert!(stdout.is_empty(), "{stdout}");
            assert!(
                stderr.contains(shown) && stderr.contains(kind),
                "{l_a} {what}: {stderr}"
            );
            assert!(!stderr.contains('?'), "a guess: {stderr}");
        }
    }
}

/// One rule for every number ([`trocar_model::validity`]): a subnormal parameter, a joint value
/// beyond ±1e6 (it made the numeric forward kinematics print `null` with exit 0) and a NaN joint
/// of a mechanism (indexed from 1, as for serial robots) are refused, with the value.
#[test]
fn numbers_outside_the_rule_are_refused() {
    let (code, stdout, stderr) = eval(&["--param", "l_a=1e-320", "--what", "manip", "--numeric"]);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stdout.is_empty() && stderr.contains("1e-320 is subnormal"),
        "{stderr}"
    );
    for numeric in [false, true] {
        let mut args = vec!["--what", "fk", "--json"];
        if numeric {
            args.push("--numeric");
        }
        let out = Command::new(env!("CARGO_BIN_EXE_trocar"))
            .args([
                "eval",
                "bidirectional-zy",
                "--q=1e155,0,-0.3,0.9,0.2,-0.6,0.1,0.5",
            ])
            .args(&args)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(out.stdout.is_empty());
        assert!(
            stderr.contains("--q: value 1 (1e155) is beyond ±1e6"),
            "{stderr}"
        );
    }
    let out = Command::new(env!("CARGO_BIN_EXE_trocar"))
        .args(["eval", "four-bar", "--q=0,nan,0,0", "--what", "det"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("--q: value 2 ("), "{stderr}");
}
