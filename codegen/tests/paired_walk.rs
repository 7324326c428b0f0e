//! Which chains are walked with the rows of the homogeneous transform as pairs
//! (`bridge::paired_heads`, `trocar::paired_rows`), and what the emitted function then holds.
//! The values themselves are checked against the numeric runtime by `tests/generated`'s `agree`
//! (built for the default x86-64 target, which takes the walk) and `verify_generated`.

use std::path::{Path, PathBuf};
use trocar_codegen::catalogue::Function;
use trocar_codegen::derivation::derive;
use trocar_codegen::emit::bridge::paired_heads;
use trocar_codegen::{Builder, Scalar};
use trocar_model::description::RobotDescription;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn heads(robot: &str) -> Option<Vec<(i8, [f64; 3])>> {
    let path = root().join(robot);
    let desc = RobotDescription::from_toml_file(&path).unwrap_or_else(|e| panic!("{e}"));
    let d = derive(&desc).unwrap();
    paired_heads(&d, d.constraint.as_ref().unwrap().link)
}

/// The Panda's joints 1–7 are `Trans(xyz) R_x(roll) R_z(q)` with the `<origin>` of each
/// `panda_jointk` in `urdf/panda.urdf` (`rpy = "±1.5707963267948966 0 0"` read as quarter turns).
#[test]
fn the_panda_is_a_chain_of_right_angle_joints() {
    let want: Vec<(i8, [f64; 3])> = vec![
        (0, [0.0, 0.0, 0.333]),
        (-1, [0.0, 0.0, 0.0]),
        (1, [0.0, -0.316, 0.0]),
        (1, [0.0825, 0.0, 0.0]),
        (-1, [-0.0825, 0.384, 0.0]),
        (1, [0.0, 0.0, 0.0]),
        (1, [0.088, 0.0, 0.0]),
    ];
    assert_eq!(
        heads("runtime/model/robots/panda-laparoscope.toml"),
        Some(want)
    );
}

/// Chains that are not walked so: the iiwa's joints have heads with half turns about `z`
/// (`rpy = "±π/2 0 π"`), the thesis's arm has joints about `y`, the oblique chain turned frames.
#[test]
fn other_chains_are_not() {
    for robot in [
        "runtime/model/robots/iiwa-link6.toml",
        "runtime/model/robots/dia10_like_zy.toml",
        "runtime/api/tests/data/oblique7.toml",
    ] {
        assert_eq!(heads(robot), None, "{robot}");
    }
}

/// The emitted `link_pose_and_jacobian` (and its `_trig`) of the Panda takes the walk on the
/// default x86-64 target and keeps the program otherwise; other fused functions, and every
/// function of a module generated with `fma_at_run_time`, do not walk.
#[test]
fn the_walk_is_emitted_for_link_pose_and_jacobian_only() {
    let robot = root().join("runtime/model/robots/panda-laparoscope.toml");
    let generate = |fma: bool| {
        let modules = Builder::new()
            .robot(&robot)
            .real(Scalar::Generic)
            .fma_at_run_time(fma)
            .function(
                "pose_and_jacobian_i",
                [
                    Function::PartialBodyJacobian,
                    Function::ConstrainedLinkKinematics,
                ],
            )
            .function("link_pose", [Function::ConstrainedLinkKinematics])
            .generate()
            .unwrap();
        assert_eq!(modules.len(), 1);
        modules.into_values().next().unwrap()
    };
    let code = generate(false);
    let walks = |name: &str| {
        let start = code
            .find(&format!("pub fn {name}<"))
            .unwrap_or_else(|| panic!("{name} emitted"));
        let end = code[start..].find("\n    }\n").unwrap() + start;
        code[start..end].contains("paired_rows::Rows::first")
    };
    for name in [
        "link_pose_and_jacobian",
        "link_pose_and_jacobian_trig",
        "pose_and_jacobian_i",
        "pose_and_jacobian_i_trig",
    ] {
        assert!(walks(name), "{name}");
    }
    for name in ["link_pose", "pose_and_jacobian", "pose_and_jacobians_trig"] {
        assert!(!walks(name), "{name}");
    }
    assert!(code.contains(r#"cfg!(all(target_arch = "x86_64", not(target_feature = "avx")))"#));
    assert!(!generate(true).contains("paired_rows"));
}
