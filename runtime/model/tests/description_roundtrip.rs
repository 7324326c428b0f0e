//! Every shipped description is valid, and `to_toml_string` reads back to the same description.

use proptest::prelude::*;
use trocar_model::description::{
    preset_names, ConstraintDesc, EndEffector, Inertia, Instrument, JointDesc, JointDynamics,
    JointKind, Linear, Origin, Parameter, RobotDescription, Rotation, Wrist,
};

/// The description without what depends on where it was read from.
fn strip(mut d: RobotDescription) -> RobotDescription {
    d.source = None;
    for j in &mut d.joints {
        j.location = None;
    }
    d
}

fn round_trip(d: &RobotDescription) {
    let text = d.to_toml_string();
    let back =
        RobotDescription::from_toml_str(&text, None).unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(strip(back), strip(d.clone()), "\n{text}");
}

#[test]
fn every_preset_is_valid_and_round_trips() {
    let names: Vec<_> = preset_names().collect();
    assert_eq!(
        names,
        [
            "unidirectional",
            "bidirectional-zy",
            "bidirectional-zx",
            "dia10_like_zy",
            "dia10_like_zx",
            "panda-laparoscope",
            "iiwa-endoscope",
            "iiwa-link6"
        ]
    );
    for name in names {
        let d = RobotDescription::preset(name).unwrap();
        d.validate().unwrap();
        assert!(d.problems().is_empty(), "{name}");
        round_trip(&d);
    }
}

#[test]
fn the_shipped_files_are_the_presets() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("robots");
    for name in preset_names() {
        let from_file = RobotDescription::from_toml_file(dir.join(format!("{name}.toml"))).unwrap();
        assert_eq!(
            strip(from_file),
            strip(RobotDescription::preset(name).unwrap())
        );
    }
}

#[test]
fn unknown_preset() {
    let e = RobotDescription::preset("tridirectional").unwrap_err();
    assert_eq!(e.field, "preset");
    assert!(e.message.contains("unidirectional"), "{e}");
}

#[test]
fn the_arm7_fixture_round_trips() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/arm7.toml");
    round_trip(&RobotDescription::from_toml_file(path).unwrap());
}

#[test]
fn scalars_write_as_expressions_that_read_back() {
    for text in [
        "l_a + l_b",
        "-0.5*l_8 + 0.1",
        "l_e - 0.1",
        "2e-3*l_a - 1e-7",
        "-l_a",
        "0.1 - l_a",
        "3",
    ] {
        let s = Linear::parse(text).unwrap();
        assert_eq!(Linear::parse(&s.to_expression()).unwrap(), s, "{text}");
    }
    // A name ending in `e` followed by a term is not an exponent.
    let s = Linear::parse("l_e-0.1").unwrap();
    assert_eq!(s.terms, vec![(1.0, "l_e".to_string())]);
    assert!((s.constant + 0.1).abs() < 1e-15);
    // `inf` and `nan` are not numbers in expressions.
    assert_eq!(Linear::parse("inf").unwrap(), Linear::param("inf"));
}

fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(1.0),
        Just(-1.0),
        -10.0..10.0f64,
        (-1e-8..1e-8f64),
        any::<f64>().prop_filter("finite", |x| x.is_finite()),
    ]
}

fn scalar(params: &'static [&'static str]) -> impl Strategy<Value = Linear> {
    (
        finite(),
        proptest::collection::vec((finite(), 0..params.len()), 0..3),
    )
        .prop_map(move |(constant, terms)| {
            let mut s = Linear::constant(constant);
            for (c, k) in terms {
                let name = params[k].to_string();
                if c != 0.0 && !s.terms.iter().any(|(_, n)| *n == name) {
                    s.terms.push((c, name));
                }
            }
            s
        })
}

fn origin(params: &'static [&'static str]) -> impl Strategy<Value = Origin> {
    (
        [scalar(params), scalar(params), scalar(params)],
        prop_oneof![
            [finite(), finite(), finite()].prop_map(Rotation::Rpy),
            [
                [finite(), finite(), finite()],
                [finite(), finite(), finite()],
                [finite(), finite(), finite()]
            ]
            .prop_map(Rotation::Matrix),
        ],
    )
        .prop_map(|(xyz, rotation)| Origin { xyz, rotation })
}

const PARAMS: &[&str] = &["l_a", "l_b", "w2"];

prop_compose! {
    /// Any description, valid or not: serialisation must round-trip it all the same.
    fn description()(
        name in "[a-z][a-z0-9_ -]{0,8}",
        values in [finite(), finite(), finite()],
        joints in proptest::collection::vec(
            (origin(PARAMS), 0..3usize, [finite(), finite(), finite()],
             [scalar(PARAMS), scalar(PARAMS), scalar(PARAMS)], "[a-z\"\\\\ ]{1,6}",
             (proptest::option::of(finite()), proptest::option::of(finite()), proptest::option::of(finite()),
              proptest::option::of(finite()), proptest::option::of(finite()),
              proptest::option::of((finite(), [finite(), finite(), finite()],
                  [finite(), finite(), finite(), finite(), finite(), finite()])))),
            1..9),
        instrument in proptest::option::of((finite(), finite())),
        ee in origin(PARAMS),
        constraint in proptest::option::of((
            0..10usize,
            origin(PARAMS),
            proptest::collection::vec([finite(), finite(), finite(), finite(), finite(), finite()], 0..4),
            proptest::option::of(prop_oneof![Just(Wrist::Unidirectional), Just(Wrist::Zy), Just(Wrist::Zx)]),
        )),
    ) -> RobotDescription {
        RobotDescription {
            name,
            parameters: PARAMS.iter().zip(values).map(|(n, value)| Parameter { name: n.to_string(), value }).collect(),
            joints: joints.into_iter().enumerate().map(|(k, (origin, kind, axis, v, name, (acceleration, jerk, effort, damping, friction, inertia)))| JointDesc {
                name: format!("{name}{k}"),
                origin,
                kind: match kind {
                    0 => JointKind::Revolute { axis },
                    1 => JointKind::Prismatic { axis },
                    _ => JointKind::Twist { v, w: axis },
                },
                limits: None,
                speed_limit: None,
                acceleration_limit: acceleration,
                jerk_limit: jerk,
                dynamics: JointDynamics {
                    effort_limit: effort,
                    damping,
                    friction,
                    inertia: inertia.map(|(mass, com, inertia)| Inertia { mass, com, inertia }),
                },
                location: None,
            }).collect(),
            end_effector: EndEffector { name: "tool".into(), origin: ee },
            constraint: constraint.map(|(link, origin, h, wrist)| ConstraintDesc { link, origin, h, wrist }),
            task: None,
            instrument: instrument.map(|(mass, radius)| Instrument { mass, radius }),
            source: None,
        }
    }
}

/// Any description, valid or not, reads back unvalidated to itself; validated, exactly when it
/// has no problems.
fn check(d: &RobotDescription) {
    let text = d.to_toml_string();
    let back = RobotDescription::from_toml_str_unvalidated(&text, None)
        .unwrap_or_else(|e| panic!("{e}\n{text}"));
    assert_eq!(strip(back), strip(d.clone()), "\n{text}");
    let valid = RobotDescription::from_toml_str(&text, None).is_ok();
    assert_eq!(valid, d.problems().is_empty(), "\n{text}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    #[test]
    fn any_description_round_trips_or_is_invalid(d in description()) {
        check(&d);
    }
}
