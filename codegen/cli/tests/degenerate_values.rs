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
        (
            "1e-320",
            "`l_a` = 1e-320",
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
