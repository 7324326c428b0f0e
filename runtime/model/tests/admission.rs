//! The admission rules of the method, written once (`admission_problems`), as validation, the
//! numeric robot and the basis rule use them.

use trocar_model::description::{
    admission_problems, admit, AdmissionError, NullSpaceBasis, RobotDescription, Wrist,
};
use trocar_model::numeric::{NumericModel as Robot, RobotError};

#[test]
fn the_rules_in_order() {
    // Without a task (t = 6): the thesis's n − r ≥ 6 and m = 6 − r + n − i ≥ 6.
    assert_eq!(admit(8, 6, 2, 6), Ok(()));
    assert_eq!(admit(8, 7, 1, 6), Ok(()));
    // The last link (i = n) is a link of the robot; with the whole twist as the task J^r is short.
    assert_eq!(
        admission_problems(8, 8, 1, 6),
        vec![AdmissionError::TooFewColumns {
            m: 5,
            after: 0,
            r: 1,
            t: 6
        }]
    );
    assert_eq!(
        admission_problems(8, 9, 1, 6),
        vec![AdmissionError::LinkOutOfRange { link: 9, n: 8 }]
    );
    assert_eq!(
        admission_problems(8, 0, 0, 6),
        vec![
            AdmissionError::LinkOutOfRange { link: 0, n: 8 },
            AdmissionError::NoRows
        ]
    );
    assert_eq!(
        admission_problems(6, 7, 2, 6),
        vec![
            AdmissionError::LinkOutOfRange { link: 7, n: 6 },
            AdmissionError::TooFewJoints { n: 6, r: 2, t: 6 }
        ]
    );
    // `n − r ≥ t` is reported first by `admit`.
    assert_eq!(
        admit(6, 7, 2, 6),
        Err(AdmissionError::TooFewJoints { n: 6, r: 2, t: 6 })
    );
    assert_eq!(
        admission_problems(11, 1, 6, 6),
        vec![
            AdmissionError::TooManyRows { r: 6 },
            AdmissionError::TooFewJoints { n: 11, r: 6, t: 6 }
        ]
    );
    // J^r needs m = 6 − r + n − i ≥ t columns.
    let e = admit(8, 7, 2, 6).unwrap_err();
    assert_eq!(
        e,
        AdmissionError::TooFewColumns {
            m: 5,
            after: 1,
            r: 2,
            t: 6
        }
    );
    assert_eq!(e.field(), "constraint.link");
    // A task of t rows: n − r ≥ t and m ≥ t, reported on the task.
    assert_eq!(admit(7, 7, 2, 4), Ok(()));
    assert_eq!(admit(8, 7, 2, 5), Ok(()));
    let e = admit(7, 7, 2, 5).unwrap_err();
    assert_eq!(e.field(), "task.select");
    assert!(e.to_string().contains("= 4 columns"), "{e}");
}

#[test]
fn every_builder_applies_them() {
    // link 7 of 8 with r = 2: m = 5.
    let mut d = RobotDescription::preset("bidirectional-zy").unwrap();
    let c = d.constraint.as_mut().unwrap();
    c.link = 7;
    c.wrist = None;
    let e = d.validate().unwrap_err();
    assert_eq!(e.field, "constraint.link");
    assert!(e.message.contains("m = (6 − r) + (n − i) = 5"), "{e}");
    assert!(matches!(
        Robot::<f64>::from_description(&d, &[]).unwrap_err(),
        RobotError::NotAdmitted(AdmissionError::TooFewColumns { m: 5, .. })
    ));
}

#[test]
fn the_basis_rule() {
    let d = RobotDescription::preset("unidirectional").unwrap();
    assert_eq!(
        d.constraint.unwrap().basis(),
        NullSpaceBasis::Unidirectional
    );
    for name in ["bidirectional-zy", "bidirectional-zx", "dia10_like_zx"] {
        let mut d = RobotDescription::preset(name).unwrap();
        let c = d.constraint.as_mut().unwrap();
        assert_eq!(c.basis(), NullSpaceBasis::Bidirectional, "{name}");
        c.wrist = None;
        assert_eq!(c.basis(), NullSpaceBasis::Computed, "{name}");
    }
    assert_eq!(Wrist::Zx.basis(), Wrist::Zy.basis());
    assert_eq!(
        NullSpaceBasis::thesis(1),
        Some(Wrist::Unidirectional.basis())
    );
    assert!(Wrist::Unidirectional.basis().fits_rows(1));
    assert!(!Wrist::Zy.basis().fits_rows(1));
    assert!(NullSpaceBasis::Computed.fits_rows(4));
}

/// The controller resolves the constrained link's twist through `J^B_0i` (6 × i): fewer than six
/// joints before the constraint cannot give it every twist, whatever the task.
#[test]
fn six_joints_before_the_constraint() {
    assert_eq!(
        admission_problems(9, 5, 2, 6),
        vec![AdmissionError::TooFewJointsBefore { link: 5 }]
    );
    // With a small task too, and reported on the constrained link with its number.
    let e = admit(9, 3, 2, 3).unwrap_err();
    assert_eq!(e, AdmissionError::TooFewJointsBefore { link: 3 });
    assert_eq!(e.field(), "constraint.link");
    assert!(
        e.to_string().contains("i ≥ 6") && e.to_string().contains("i = 3"),
        "{e}"
    );
    assert_eq!(admit(9, 6, 2, 6), Ok(()));
    assert_eq!(admit(7, 7, 2, 4), Ok(()));
}

/// The panda-laparoscope description with `from` replaced by `to`, read as the shipped one is.
fn panda_with(
    from: &str,
    to: &str,
) -> Result<RobotDescription, trocar_model::description::DescriptionError> {
    let text = trocar_model::description::preset("panda-laparoscope").unwrap();
    assert!(text.contains(from), "{from}");
    RobotDescription::from_toml_str(
        &text.replace(from, to),
        Some(std::path::Path::new("<preset panda-laparoscope>")),
    )
}

/// Tasks that are singular at every configuration are refused on the task's line, with the rank:
/// through a trocar that fixes x and y of the shaft, a task that asks for `x` and the rotation
/// about `y` at the tip (x_e moves only with the pivot about y), the four rows x, y, rx, ry, or,
/// with `H = z` (no motion along the shaft at the trocar), the tip's motion along the shaft.
#[test]
fn tasks_singular_everywhere_are_refused() {
    const SELECT: &str = "select = [\"x\", \"y\", \"z\", \"rz\"]";
    for (select, rank, t) in [
        ("select = [\"x\", \"ry\"]", 1, 2),
        ("select = [\"x\", \"y\", \"rx\", \"ry\"]", 2, 4),
    ] {
        let e = panda_with(SELECT, select).unwrap_err();
        assert_eq!(e.field, "task.select", "{select}: {e}");
        assert!(e.line.is_some(), "{e}");
        assert!(
            e.message.contains("singular at every configuration")
                && e.message.contains(&format!("rank {rank} < t = {t}")),
            "{select}: {e}"
        );
    }
    let text = trocar_model::description::preset("panda-laparoscope").unwrap();
    let e = RobotDescription::from_toml_str(
        &text
            .replace("h = [\"x\", \"y\"]", "h = [\"z\"]")
            .replace(SELECT, "select = [\"z\"]"),
        Some(std::path::Path::new("<preset panda-laparoscope>")),
    )
    .unwrap_err();
    assert_eq!(e.field, "task.select", "{e}");
    assert!(e.message.contains("rank 0 < t = 1"), "{e}");
    // A task the trocar allows is admitted, and so is the shipped one.
    assert!(panda_with(SELECT, "select = [\"x\", \"z\"]").is_ok());
    assert!(RobotDescription::preset("panda-laparoscope").is_ok());
}

/// With a `[task]` of six rows the counting rules blame the task, not `H`; the `i ≥ 6` rule is
/// reported on the constrained link's line.
#[test]
fn admission_errors_name_the_field_written() {
    let e = panda_with(
        "select = [\"x\", \"y\", \"z\", \"rz\"]",
        "select = [\"x\", \"y\", \"z\", \"rx\", \"ry\", \"rz\"]",
    )
    .unwrap_err();
    assert_eq!(e.field, "task.select", "{e}");
    assert!(e.message.contains("t = 6"), "{e}");
    assert!(e.line.is_some());
    let e = panda_with("link = \"panda_link7\"", "link = \"panda_link4\"").unwrap_err();
    assert_eq!(e.field, "constraint.link", "{e}");
    assert!(
        e.message.contains("i ≥ 6") && e.message.contains("i = 4"),
        "{e}"
    );
    assert!(e.line.is_some(), "{e}");
}

/// Issue 27, item 11: a trocar beyond the instrument's tip (`l_a` past the end effector along the
/// shaft) was accepted silently; it is refused on the parameter, with the largest value allowed.
#[test]
fn the_trocar_lies_on_the_instrument() {
    // The shaft runs 0.40 m beyond the flange, the trocar l_a beyond it.
    let e = panda_with("l_a = 0.25 ", "l_a = 0.45 ").unwrap_err();
    assert_eq!(e.field, "parameters.l_a", "{e}");
    assert!(e.message.contains("outside the instrument"), "{e}");
    assert!(e.message.contains("below 0.4"), "{e}");
    assert!(e.line.is_some(), "{e}");
    assert!(panda_with("l_a = 0.25 ", "l_a = 0.39 ").is_ok());
}

/// A constraint point that slides along an axis the instrument does not run along
/// (`xyz = [0, "l_a", 0.107]` on a shaft along z) was reported against `parameters.l_a` ("outside the
/// instrument"); the value is not what is wrong, the axis is: the error is on `constraint.xyz`,
/// with its line (docs/RELIABILITY.md F25).
#[test]
fn a_sliding_axis_away_from_the_tip_is_located_at_the_constraint() {
    for axis in [
        "[0, \"l_a\", 0.107]",
        "[\"l_a\", 0, 0.107]",
        "[0, 0, \"0.107 - l_a\"]",
    ] {
        let e = panda_with("xyz = [0, 0, \"0.107 + l_a\"]", &format!("xyz = {axis}")).unwrap_err();
        assert_eq!(e.field, "constraint.xyz", "{axis}: {e}");
        assert!(
            e.message.contains("does not point toward the tip"),
            "{axis}: {e}"
        );
        assert!(!e.message.contains("-0"), "{e}");
        assert!(e.line.is_some(), "{e}");
    }
}
