//! Which chains are walked with the rows of the homogeneous transform as pairs
//! (`lower::paired_heads`, `trocar::emitted::paired_rows`), and what the emitted function then holds.
//! The values themselves are checked against the numeric robot by `tests/generated`'s
//! `urdf_robots` (the Panda's fused `g_0i` and `J^B_0i`, `f64`, built for the default x86-64
//! target, which takes the walk) and `agree` (`f64` and `f32`), and the lane types against the
//! scalar walk bit for bit by its `lanes`.

use std::path::{Path, PathBuf};
use trocar_codegen::catalogue::Function;
use trocar_codegen::derivation::derive;
use trocar_codegen::lower::paired_heads;
use trocar_codegen::{Builder, Real};
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
        "codegen/api/tests/data/oblique7.toml",
    ] {
        assert_eq!(heads(robot), None, "{robot}");
    }
}

/// The Panda's fused functions of exactly `g_0i` and `J^B_0i` (`link_pose_and_jacobian`, a
/// requested one with the outputs the other way round, and their `_trig`) take the walk on the
/// default x86-64 target and keep the program otherwise; fused functions of other outputs, and
/// every function of a module generated with `fma_at_run_time`, do not walk.
#[test]
fn the_walk_is_emitted_for_link_pose_and_jacobian_only() {
    let robot = root().join("runtime/model/robots/panda-laparoscope.toml");
    let generate = |fma: bool| {
        let modules = Builder::new()
            .robot(&robot)
            .real(Real::Generic)
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
    let bare: String = code.chars().filter(|c| !c.is_whitespace()).collect();
    assert!(bare.contains(
        r#"cfg!(all(target_arch="x86_64",target_feature="sse2",not(target_feature="avx")))"#
    ));
    assert!(!generate(true).contains("paired_rows"));
}

/// A seven-joint chain of right-angle joints written out (the constraint on link 6, one row of
/// `H`), with one joint changed by `edit`: `(joint, field line)`.
fn chain(edit: Option<(usize, &str)>) -> Option<Vec<(i8, [f64; 3])>> {
    let quarter = std::f64::consts::FRAC_PI_2;
    let heads: [(f64, [&str; 3]); 7] = [
        (0.0, ["0", "0", "0.3"]),
        (-quarter, ["0", "0", "0"]),
        (quarter, ["0", "-0.3", "0"]),
        (quarter, ["0.08", "0", "0"]),
        (-quarter, ["-0.08", "0.38", "0"]),
        (quarter, ["0", "0", "0"]),
        (quarter, ["0.09", "0", "0"]),
    ];
    let mut toml =
        String::from("[robot]\nname = \"right_angles\"\n\n[parameters]\nl_a = 0.1\nd = 0.05\n");
    for (k, (roll, xyz)) in heads.iter().enumerate() {
        toml += &format!(
            "\n[[joints]]\nname = \"j{}\"\ntype = \"revolute\"\nxyz = [{}]\nrpy = [{roll:?}, 0.0, 0.0]\naxis = [0, 0, 1]\n",
            k + 1,
            xyz.iter().map(|x| format!("\"{x}\"")).collect::<Vec<_>>().join(", ")
        );
        if let Some((j, line)) = edit {
            if j == k {
                toml += line;
                toml += "\n";
            }
        }
    }
    toml += "\n[end_effector]\nname = \"tool\"\nxyz = [0, 0, 0.1]\n\n[constraint]\nlink = 6\nxyz = [0, 0, \"l_a\"]\nh = [\"x\"]\n";
    // A later key of the same name replaces the joint's earlier one.
    let toml = dedup_keys(&toml);
    let desc = RobotDescription::from_toml_str(&toml, None).unwrap_or_else(|e| panic!("{e}"));
    let d = derive(&desc).unwrap();
    paired_heads(&d, 6)
}

/// Within each `[[joints]]` table, keeps the last line of each key.
fn dedup_keys(toml: &str) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut table_start = 0;
    for line in toml.lines() {
        if line.starts_with('[') {
            table_start = out.len();
        }
        if let Some((key, _)) = line.split_once(" = ") {
            if let Some(i) =
                (table_start..out.len()).find(|&i| out[i].starts_with(&format!("{key} = ")))
            {
                out[i] = line.to_string();
                continue;
            }
        }
        out.push(line.to_string());
    }
    out.join("\n")
}

/// The written-out chain is walked; a parameter in an offset, a head with a half turn about
/// `z`, an axis `−z`, a prismatic joint or an oblique axis each take it out.
#[test]
fn what_takes_a_chain_out() {
    let heads = chain(None).expect("right-angle joints");
    assert_eq!(heads.len(), 6);
    assert_eq!(heads[0], (0, [0.0, 0.0, 0.3]));
    assert_eq!(heads[4], (-1, [-0.08, 0.38, 0.0]));
    for (joint, line) in [
        (2, "xyz = [0, \"-d\", 0]"),
        (3, "rpy = [1.5707963267948966, 0.0, 3.141592653589793]"),
        (1, "axis = [0, 0, -1]"),
        (4, "type = \"prismatic\""),
        (5, "axis = [0, 0.6, 0.8]"),
    ] {
        assert_eq!(
            chain(Some((joint, line))),
            None,
            "joint {}: {line}",
            joint + 1
        );
    }
    // A change beyond the constrained link does not matter.
    assert!(chain(Some((6, "xyz = [0, \"-d\", 0]"))).is_some());
}
