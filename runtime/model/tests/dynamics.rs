//! What a physics plant reads from a description: joint acceleration, jerk and effort limits,
//! damping and friction, the links' mass properties (folded over fixed joints) and the
//! instrument.

use trocar_model::description::{Inertia, RobotDescription};

fn panda() -> RobotDescription {
    RobotDescription::preset("panda-laparoscope").unwrap()
}

#[test]
fn the_panda_carries_its_datasheet_limits_and_franka_inertials() {
    let d = panda();
    let acceleration: Vec<f64> = d
        .joints
        .iter()
        .map(|j| j.acceleration_limit.unwrap())
        .collect();
    let jerk: Vec<f64> = d.joints.iter().map(|j| j.jerk_limit.unwrap()).collect();
    assert_eq!(acceleration, [15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0]);
    assert_eq!(
        jerk,
        [7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0]
    );
    let effort: Vec<f64> = d
        .joints
        .iter()
        .map(|j| j.dynamics.effort_limit.unwrap())
        .collect();
    assert_eq!(effort, [87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0]);
    for j in &d.joints {
        assert_eq!(j.dynamics.damping, Some(0.003));
        assert_eq!(j.dynamics.friction, Some(0.2));
    }
    // Link 1 as written in the URDF (its frame is joint 1's: nothing folded onto it).
    let i1 = d.joints[0].dynamics.inertia.unwrap();
    assert_eq!(i1.mass, 2.7907);
    assert_eq!(i1.com, [0.00033, -0.02204, -0.04762]);
    assert_eq!(i1.inertia[0], 0.01564782655);
    let masses: f64 = d
        .joints
        .iter()
        .map(|j| j.dynamics.inertia.unwrap().mass)
        .sum();
    assert!((masses - 13.78593).abs() < 1e-12, "{masses}");
    let instrument = d.instrument.unwrap();
    assert_eq!((instrument.mass, instrument.radius), (0.25, 0.005));
}

/// A link fixed to the moving one by a rotated, offset fixed joint folds in with its centre of
/// mass and tensor moved into the moving link's frame (checked against the sums written out).
#[test]
fn links_on_fixed_joints_fold_into_the_moving_link() {
    let urdf = r#"<robot name="r" version="1.2">
  <link name="base"/>
  <link name="a">
    <inertial><origin xyz="0 0 0.1"/><mass value="2"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>
  </link>
  <link name="b">
    <inertial><origin xyz="0.1 0 0"/><mass value="1"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.003"/></inertial>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="a"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1" acceleration="3" jerk="40"/>
    <dynamics damping="0.5" friction="0.1"/></joint>
  <joint name="f" type="fixed"><parent link="a"/><child link="b"/>
    <origin xyz="0 0 0.3" rpy="0 0 1.5707963267948966"/></joint>
</robot>"#;
    let d = RobotDescription::from_urdf_str(urdf, "b").unwrap();
    let j = &d.joints[0];
    assert_eq!(
        (j.acceleration_limit, j.jerk_limit),
        (Some(3.0), Some(40.0))
    );
    assert_eq!(j.dynamics.effort_limit, Some(5.0));
    assert_eq!(
        (j.dynamics.damping, j.dynamics.friction),
        (Some(0.5), Some(0.1))
    );
    let i = j.dynamics.inertia.unwrap();
    // b's centre of mass: (0, 0, 0.3) + Rz(90°) (0.1, 0, 0) = (0, 0.1, 0.3); a's (0, 0, 0.1).
    let com = [0.0, 0.1 / 3.0, (2.0 * 0.1 + 0.3) / 3.0];
    assert_eq!(i.mass, 3.0);
    for (got, want) in i.com.iter().zip(com) {
        assert!((got - want).abs() < 1e-15, "{:?}", i.com);
    }
    // Tensors about the common centre: b's rotated (ixx ↔ iyy), both shifted.
    let shift = |m: f64, d: [f64; 3]| {
        [
            m * (d[1] * d[1] + d[2] * d[2]),
            m * (d[0] * d[0] + d[2] * d[2]),
            m * (d[0] * d[0] + d[1] * d[1]),
            -m * d[0] * d[1],
            -m * d[0] * d[2],
            -m * d[1] * d[2],
        ]
    };
    let da = [0.0 - com[0], 0.0 - com[1], 0.1 - com[2]];
    let db = [0.0 - com[0], 0.1 - com[1], 0.3 - com[2]];
    let (sa, sb) = (shift(2.0, da), shift(1.0, db));
    let own = [0.01 + 0.002, 0.02 + 0.001, 0.03 + 0.003, 0.0, 0.0, 0.0];
    for k in 0..6 {
        let want = own[k] + sa[k] + sb[k];
        assert!((i.inertia[k] - want).abs() < 1e-15, "{k}: {:?}", i.inertia);
    }
}

#[test]
fn transformed_and_combined_agree_with_the_definitions() {
    let i = Inertia {
        mass: 1.5,
        com: [0.1, -0.2, 0.3],
        inertia: [0.02, 0.03, 0.04, 0.001, -0.002, 0.003],
    };
    // A rotation about z by 90° maps x to y: ixx ↔ iyy, ixz → iyz, iyz → −ixz, ixy → −ixy.
    let r = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]];
    let t = i.transformed(&r, &[1.0, 2.0, 3.0]);
    assert_eq!(t.com, [1.2, 2.1, 3.3]);
    assert_eq!(t.inertia, [0.03, 0.02, 0.04, -0.001, -0.003, -0.002]);
    // A massless body adds nothing.
    let zero = Inertia {
        mass: 0.0,
        com: [5.0; 3],
        inertia: [0.0; 6],
    };
    let c = i.combined(&zero);
    assert_eq!((c.mass, c.inertia), (i.mass, i.inertia));
    for (got, want) in c.com.iter().zip(i.com) {
        assert!((got - want).abs() < 1e-16);
    }
}

#[test]
fn bad_dynamics_are_refused_with_their_field() {
    let base = |joint_extra: &str, extra: &str| {
        format!(
            "[robot]\nname = \"r\"\n{extra}\n[[joints]]\nname = \"j1\"\ntype = \"revolute\"\naxis = [0, 0, 1]\n{joint_extra}\n"
        )
    };
    let cases = [
        (
            base("acceleration_limit = -1", ""),
            "joints[0].acceleration_limit",
        ),
        (base("jerk_limit = 0", ""), "joints[0].jerk_limit"),
        (base("damping = -0.1", ""), "joints[0].damping"),
        (base("mass = 1", ""), "joints[0].inertia"),
        (base("inertia = [1, 1, 1, 0, 0, 0]", ""), "joints[0].mass"),
        (
            base("mass = 1\ninertia = [1, 1, -3, 0, 0, 0]", ""),
            "joints[0].inertia",
        ),
        (
            base("mass = 0\ninertia = [1, 1, 1, 0, 0, 0]", ""),
            "joints[0].mass",
        ),
        (
            base("", "[instrument]\nmass = 0.2\nradius = -1\n"),
            "instrument.radius",
        ),
    ];
    for (text, field) in cases {
        let e = RobotDescription::from_toml_str(&text, None).unwrap_err();
        assert_eq!(e.field, field, "{text}\n{e}");
        assert!(e.line.is_some(), "{e}");
    }
    let urdf = r#"<robot name="r" version="1.2"><link name="base"/><link name="a"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="a"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="5" velocity="1" acceleration="-3"/></joint>
</robot>"#;
    let e = RobotDescription::from_urdf_str(urdf, "a").unwrap_err();
    assert!(
        e.message.contains("acceleration value (-3) is negative"),
        "{e}"
    );
    assert!(e.line.is_some(), "{e}");
    // Before URDF 1.2 the attributes do not exist (read as urdfdom reads them: ignored).
    let old = urdf.replace(r#" version="1.2""#, "").replace("-3", "3");
    let d = RobotDescription::from_urdf_str(&old, "a").unwrap();
    assert_eq!(d.joints[0].acceleration_limit, None);
}

#[test]
fn dynamics_round_trip_through_toml() {
    let d = panda();
    let text = d.to_toml_string();
    let back = RobotDescription::from_toml_str(&text, None).unwrap();
    for (a, b) in d.joints.iter().zip(&back.joints) {
        assert_eq!(a.acceleration_limit, b.acceleration_limit);
        assert_eq!(a.jerk_limit, b.jerk_limit);
        assert_eq!(a.dynamics, b.dynamics);
    }
    assert_eq!(back.instrument, d.instrument);
}
