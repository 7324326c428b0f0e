//! The shipped `bidirectional-zy` generated with checks in `f64` and `f32` (`arm_f64`, `arm_f32`),
//! and copies of both with one sign flipped in `constrained_jacobian` (`corrupted_f64`,
//! `corrupted_f32`; see `build.rs`), and `arm_feature`, generic, whose checks are behind the
//! feature `checks` (`tests/feature.rs`). The tests show the checks pass on the faithful modules, and
//! name the corrupted function, its worst configuration and the entry that differs.
#![no_std]
#![warn(missing_docs)]

include!(concat!(env!("OUT_DIR"), "/arm_f64.rs"));
include!(concat!(env!("OUT_DIR"), "/arm_f32.rs"));
include!(concat!(env!("OUT_DIR"), "/corrupted_f64.rs"));
include!(concat!(env!("OUT_DIR"), "/corrupted_f32.rs"));
include!(concat!(env!("OUT_DIR"), "/arm_feature.rs"));

#[cfg(test)]
mod tests {
    extern crate std;
    use std::string::{String, ToString};
    use std::vec::Vec;
    use std::{format, println};
    use trocar_check::{check, Function, GeneratedModule, SEED};

    const ROBOT: &str = "../../runtime/model/robots/bidirectional-zy.toml";

    #[test]
    fn the_faithful_modules_match_in_f64_and_f32() {
        trocar_check::assert_matches_numeric::<super::arm_f64::Checks>(ROBOT, 500);
        trocar_check::assert_matches_numeric::<super::arm_f32::Checks>(ROBOT, 500);
    }

    /// The panic message of `assert_matches_numeric` on `M`.
    fn failure<M: GeneratedModule>() -> String {
        let panic =
            std::panic::catch_unwind(|| trocar_check::assert_matches_numeric::<M>(ROBOT, 200))
                .expect_err("the corrupted module must fail the check");
        panic.downcast_ref::<String>().cloned().unwrap_or_default()
    }

    fn flipped_sign_is_reported<M: GeneratedModule>(tolerance: f64) {
        let report = check::<M>(ROBOT, 200, SEED).unwrap();
        let failed: Vec<_> = report.checks.iter().filter(|c| !c.passed()).collect();
        assert_eq!(failed.len(), 1, "{report}");
        let jr = failed[0];
        assert_eq!(jr.name, "jr: generated vs numeric");
        assert_eq!(jr.function, Some(Function::ConstrainedJacobian));
        assert_eq!(jr.tolerance, tolerance);
        assert_eq!((jr.worst_q.len(), jr.worst_params.len()), (8, 3));
        // Entry (0, 0) alone has its sign flipped: it is the one that differs, by twice its value.
        assert_eq!(jr.differences.len(), 1, "{}", report.failures());
        let d = jr.differences[0];
        assert_eq!((d.row, d.col), (0, 0));
        assert!((d.candidate + d.reference).abs() <= 1e-5 * d.reference.abs().max(1.0));

        let message = failure::<M>();
        println!("{message}");
        for expected in [
            "MISMATCH jr: generated vs numeric (`constrained_jacobian`)",
            &format!("tolerance {tolerance:.0e}"),
            &format!("worst q = {:?}", jr.worst_q),
            "parameters: l_a = ",
            "entry (0, 0): generated ",
        ] {
            assert!(
                message.contains(expected),
                "`{expected}` not in:\n{message}"
            );
        }
    }

    #[test]
    fn a_flipped_sign_is_reported_in_f64() {
        flipped_sign_is_reported::<super::corrupted_f64::Checks>(1e-12);
    }

    #[test]
    fn a_flipped_sign_is_reported_in_f32() {
        flipped_sign_is_reported::<super::corrupted_f32::Checks>(2e-6);
    }

    #[test]
    fn a_changed_description_makes_the_module_stale() {
        let dir = std::env::temp_dir().join(format!("trocar-stale-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let copy = dir.join("bidirectional-zy.toml");
        let text = std::fs::read_to_string(ROBOT).unwrap();
        std::fs::write(&copy, &text).unwrap();
        let path = copy.to_str().unwrap();
        // The same bytes: not stale.
        assert!(check::<super::arm_f64::Checks>(path, 5, SEED)
            .unwrap()
            .passed());
        // One length changed: the module was generated from another description.
        std::fs::write(&copy, text.replace("l_b = 0.18", "l_b = 0.19")).unwrap();
        let err = check::<super::arm_f64::Checks>(path, 5, SEED).unwrap_err();
        assert!(
            matches!(err, trocar_check::CheckError::Stale { .. }),
            "{err}"
        );
        assert!(err
            .to_string()
            .contains("has changed since the module was generated"));
        std::fs::remove_dir_all(&dir).ok();
    }
}
