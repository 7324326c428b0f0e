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
