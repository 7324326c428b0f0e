//! Scenes: several constrained arms, each through its own port, in one frame (the thesis's §5.2:
//! both arms of a two-armed robot, a kinematic constraint on each; instruments and an endoscope
//! on their own bases around the patient).
//!
//! A scene file names its arms, each a robot description of its own (a shipped name or a file,
//! TOML or URDF-backed) placed in the scene's frame, and the couplings between them:
//!
//! ```toml
//! [scene]
//! name = "three_ports"
//! orientation_weight = 0.1            # the tasks' angular rows against their linear ones (S1)
//! rate_weight = 0.001                 # the change of the rates themselves (S1)
//!
//! [[arms]]
//! name = "left"                       # unique, a Rust identifier (its module's name)
//! robot = "panda-laparoscope"         # a shipped description, or a file relative to this one
//! base = { port = [0.0346, -0.02, 0], rpy = [0, 0, 0.5236] }  # or xyz = [..] instead of port
//! q0 = [0, -0.785, 0, -2.356, 0, 1.571, 0.785]                 # the start; the port is the
//! parameters = { l_a = 0.25 }                                  # constraint frame's origin there
//!
//! [[arms]]
//! name = "torso_left"
//! robot = "dia10_like_zy"
//! mirror = true                       # the mirror image in the base's plane x = 0
//! shares = { arm = "right", joints = 1 }   # its first joint is the right arm's (a torso)
//! camera = { looks_at = ["left", "right"], depth = 0.08, tolerance = 0.0087 }
//!
//! [[couplings]]
//! between = ["left", "right"]
//! kind = "shafts"                     # or "tips"
//! safety = 0.010                      # m, kept at least (a velocity damper)
//! influence = 0.030                   # m, where the damper starts to act
//! gain = 0.1                          # m/s (default 0.1)
//! ```
//!
//! `base.port` places the base so that the arm's port at `q0` is at that point of the scene
//! (the base turned by `rpy` first); `base.xyz` gives the base's origin instead.
//!
//! An arm with `mirror = true` is its description's mirror image in the plane `x = 0` of its
//! base, with `M = diag(−1, 1, 1)`: every joint it does not share has its origin `(M p, M R M)`;
//! a revolute joint the axis `M a` (`M Rot(a, θ) M = Rot(M a, −θ)`: its angle counts the other
//! way), a prismatic one `M a`, a twist `(−M v, M ω)` (`(M v, 0)` without rotation); the end
//! effector and the constraint frame are mirrored alike, and each row `h` of the constraint's
//! `H` and of the task's selection becomes `h D` (`D = diag(−1, 1, 1, 1, −1, −1)`, the mirror on
//! body twists; a row of one axis keeps its sign, the same constraint). A chain whose kept
//! joints lie in the mirror plane (a torso about `z` through the origin) is then at `q` the
//! mirror image of the original at `−q` (revolute angles negated): an arm starts as the other's
//! mirror image from the other's `q0` negated, and wrist axes keep their directions (the
//! thesis's wrist presets stay admitted).
//!
//! [`SceneDescription::from_toml_str`] reads and admits a scene; every error names the file,
//! line and field (`arms[1].q0[3]`, `couplings[0].safety`), and errors of an arm's own
//! description are that description's. The admission rules ([`admission`]) are those of each
//! arm alone (its description's, as for one robot) and those of the stack: arms of one kind
//! (joints, port rows, task rows: one step drives them all), shared joints that are one joint in
//! the scene's frame, couplings between two different arms whose safety lies within their
//! influence and that do not start inside their safety distance, and the port rows of all arms
//! independent over the scene's joints at the start.

mod admission;
mod read;

pub use admission::STACK_RANK_TOLERANCE;

use crate::description::{DescriptionError, RobotDescription};
use crate::numeric::NumericModel;
use std::path::PathBuf;
use trocar::control::scene::Between;
use trocar::se3::Se3;

/// The scenes shipped with trocar: `(name, TOML text)`.
pub const SHIPPED_SCENES: &[(&str, &str)] = &[
    ("three-ports", include_str!("../../scenes/three-ports.toml")),
    ("dia10-dual", include_str!("../../scenes/dia10-dual.toml")),
];

/// The names of the shipped scenes.
pub fn shipped_scene_names() -> impl Iterator<Item = &'static str> {
    SHIPPED_SCENES.iter().map(|(n, _)| *n)
}

/// One arm of a scene: its robot, where it stands and how it starts.
#[derive(Clone, Debug)]
pub struct SceneArmDescription {
    /// The arm's name (a Rust identifier).
    pub name: String,
    /// The `robot` entry as written (a shipped name or a path relative to the scene file).
    pub robot_source: String,
    /// The arm's robot, mirrored when [`SceneArmDescription::mirror`] is set, with the scene's
    /// parameter values as its nominal ones.
    pub robot: RobotDescription,
    /// The arm's base in the scene's frame.
    pub base: Se3<f64>,
    /// The arm's joints at the start.
    pub q0: Vec<f64>,
    /// Whether the arm is its description's mirror image.
    pub mirror: bool,
    /// The arm whose first joints this arm shares, and how many (a torso): `(arm, joints)`;
    /// the scene holds them once, where the earlier of the two arms has them.
    pub shares: Option<(usize, usize)>,
    /// The arm's camera task, when it is an endoscope.
    pub camera: Option<CameraDescription>,
}

/// A camera task: the view axis through the port kept on the midpoint of some arms' tips.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraDescription {
    /// The arms whose tips' midpoint the camera looks at (by index).
    pub looks_at: Vec<usize>,
    /// The tip's depth below the port (m); `None`: the start's.
    pub depth: Option<f64>,
    /// How far the view axis may be off its point (rad).
    pub tolerance: f64,
}

/// A coupling: two arms' shafts (or tips) kept at least `safety` apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CouplingDescription {
    /// The two arms (by index).
    pub arms: (usize, usize),
    /// Shafts or tips.
    pub between: Between,
    /// The safety distance (m).
    pub safety: f64,
    /// The influence distance (m).
    pub influence: f64,
    /// The damper's gain (m/s).
    pub gain: f64,
}

/// A scene read and admitted: its arms in order, its couplings.
#[derive(Clone, Debug)]
pub struct SceneDescription {
    /// The scene's name (a Rust identifier: its module's name).
    pub name: String,
    /// The arms, in the scene's order.
    pub arms: Vec<SceneArmDescription>,
    /// The couplings.
    pub couplings: Vec<CouplingDescription>,
    /// The weight of the tasks' angular rows against their linear ones in the scene's step
    /// (0.1 by default).
    pub orientation_weight: f64,
    /// The weight of the change of the rates themselves in the scene's step (1e-3 by default).
    pub rate_weight: f64,
    /// The file the scene was read from.
    pub source: Option<PathBuf>,
}

/// A joint two arms share: `(arm a, joint index in a, arm b, joint index in b)`, 0-based.
pub type SharedJointIndex = (usize, usize, usize, usize);

impl SceneDescription {
    /// One of the shipped scenes ([`SHIPPED_SCENES`]) by name.
    pub fn shipped(name: &str) -> Result<Self, DescriptionError> {
        let text = SHIPPED_SCENES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, t)| *t)
            .ok_or_else(|| DescriptionError {
                file: None,
                line: None,
                column: None,
                field: "scene".into(),
                message: format!(
                    "unknown scene `{name}` (expected one of: {})",
                    shipped_scene_names().collect::<Vec<_>>().join(", ")
                ),
            })?;
        Self::from_toml_str(text, Some(&PathBuf::from(format!("<scene {name}>"))))
    }

    /// Reads a scene file.
    pub fn from_toml_file(path: impl AsRef<std::path::Path>) -> Result<Self, DescriptionError> {
        let path = path.as_ref();
        let text = DescriptionError::read_file(path)?;
        Self::from_toml_str(&text, Some(path))
    }

    /// Reads a scene from TOML text and admits it ([`admission`]); `file` names the text in errors
    /// and is where the arms' description files are looked up from.
    pub fn from_toml_str(
        text: &str,
        file: Option<&std::path::Path>,
    ) -> Result<Self, DescriptionError> {
        read::read(text, file)
    }

    /// Whether `text` is a scene (TOML with a top-level `[scene]` table).
    pub fn is_scene_text(text: &str) -> bool {
        text.parse::<toml::Table>()
            .is_ok_and(|t| t.get("scene").is_some_and(toml::Value::is_table))
    }

    /// The files a scene at `path` is read from: `path` and its arms' description files (and
    /// their URDFs), for `cargo:rerun-if-changed`. Unreadable files are listed all the same.
    pub fn files_read(path: impl AsRef<std::path::Path>) -> Vec<PathBuf> {
        read::files_read(path.as_ref())
    }

    /// The number of joints of each arm (all the same: one kind of arm).
    pub fn arm_joints(&self) -> usize {
        self.arms.first().map_or(0, |a| a.robot.joints.len())
    }

    /// The scene's joints: every arm's, those it shares with an earlier arm once (in the
    /// order of the arms, each arm's joints in its order). For each arm, the scene index of each
    /// of its joints.
    pub fn joint_map(&self) -> Vec<Vec<usize>> {
        // Union–find over the arms' joints: every `shares` entry joins its joints, through any
        // chain of arms.
        let offsets: Vec<usize> = self
            .arms
            .iter()
            .scan(0, |at, a| {
                let here = *at;
                *at += a.robot.joints.len();
                Some(here)
            })
            .collect();
        let total = self.arms.iter().map(|a| a.robot.joints.len()).sum();
        let mut parent: Vec<usize> = (0..total).collect();
        fn root(parent: &mut [usize], mut i: usize) -> usize {
            while parent[i] != i {
                parent[i] = parent[parent[i]];
                i = parent[i];
            }
            i
        }
        for (k, arm) in self.arms.iter().enumerate() {
            if let Some((other, count)) = arm.shares {
                let count = count
                    .min(arm.robot.joints.len())
                    .min(self.arms[other].robot.joints.len());
                for j in 0..count {
                    let (a, b) = (
                        root(&mut parent, offsets[k] + j),
                        root(&mut parent, offsets[other] + j),
                    );
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
        // Number the groups in order of first appearance.
        let mut number = vec![usize::MAX; total];
        let mut next = 0;
        self.arms
            .iter()
            .enumerate()
            .map(|(k, arm)| {
                (0..arm.robot.joints.len())
                    .map(|j| {
                        let r = root(&mut parent, offsets[k] + j);
                        if number[r] == usize::MAX {
                            number[r] = next;
                            next += 1;
                        }
                        number[r]
                    })
                    .collect()
            })
            .collect()
    }

    /// The number of the scene's joints ([`SceneDescription::joint_map`]).
    pub fn scene_joints(&self) -> usize {
        self.joint_map().iter().flatten().max().map_or(0, |m| m + 1)
    }

    /// The shared joints, one entry per pair of arm joints that are one joint of the scene.
    pub fn shared_joints(&self) -> Vec<SharedJointIndex> {
        let mut out = Vec::new();
        for (k, arm) in self.arms.iter().enumerate() {
            if let Some((other, count)) = arm.shares {
                for j in 0..count {
                    out.push((other, j, k, j));
                }
            }
        }
        out
    }

    /// Each arm's numeric model (the scene's parameter values).
    pub fn numeric_models(&self) -> Result<Vec<NumericModel<f64>>, DescriptionError> {
        self.arms
            .iter()
            .enumerate()
            .map(|(k, a)| {
                NumericModel::<f64>::from_description(&a.robot, &[])
                    .map_err(|e| self.error(&format!("arms[{k}].robot"), e.to_string()))
            })
            .collect()
    }

    /// Each arm's port at the start, in its base frame: the constraint frame's origin at `q0`.
    pub fn ports(&self) -> Result<Vec<nalgebra::Vector3<f64>>, DescriptionError> {
        let models = self.numeric_models()?;
        self.arms
            .iter()
            .zip(&models)
            .enumerate()
            .map(|(k, (a, m))| {
                admission::port_at(m, &a.q0)
                    .map_err(|e| self.error(&format!("arms[{k}].q0"), e.to_string()))
            })
            .collect()
    }

    fn error(&self, field: &str, message: String) -> DescriptionError {
        DescriptionError {
            file: self.source.clone(),
            line: None,
            column: None,
            field: field.to_string(),
            message,
        }
    }
}

/// The mirror image of a description in the plane `x = 0` of its base, its first `kept` joints
/// unchanged (see the module's documentation): at `q`, the mirror image of the original at `−q`
/// where the kept joints lie in the plane.
pub fn mirrored(description: &RobotDescription, kept: usize) -> RobotDescription {
    read::mirrored(description, kept)
}
