//! Reading descriptions from TOML, with the location of every field.
//!
//! The format (see the shipped files in `runtime/model/robots/`):
//!
//! ```toml
//! [robot]
//! name = "bidirectional_zy"
//!
//! [parameters]          # named lengths and their nominal values
//! l_a = 0.15
//!
//! [[joints]]            # base first; link frame k is joint k's frame
//! name = "torso"        # unique
//! type = "revolute"     # or "prismatic", or "twist" with v = [..], w = [..] instead of axis
//! xyz = [0, 0, 0]       # origin from the parent frame; entries may be "l_a + l_b", "-0.5*l_8 + 0.1"
//! rpy = [0, 0, 0]       # or rotation = [[..], [..], [..]] (row-major); default: identity
//! axis = [0, 0, 1]      # unit
//!
//! [end_effector]
//! name = "tool"
//! xyz = [0, "l_8", 0]
//!
//! [constraint]
//! link = 6              # constrained link i (1-based)
//! xyz = [0, "l_a", 0]   # g_ir
//! h = ["x", "z"]        # axis letters x y z (linear) rx ry rz (angular), or rows of 6 numbers
//! wrist = "zy"          # optional: unidirectional | zy | zx (thesis basis for Λ#)
//! ```
//!
//! Every key is checked (`deny_unknown_fields`), every error names the field by path
//! (`joints[3].axis`, `constraint.h[1]`, `parameters.l_a`) with its line and column (looked up by
//! [`super::locate`]), and the result is validated ([`RobotDescription::validate`]) before it is
//! returned.

use super::locate::{location_of, Locator};
use super::urdf::{import_chain, move_joint_frame, UrdfChain};
use super::{
    ConstraintDesc, DescriptionError, EndEffector, Inertia, Instrument, JointDesc, JointDynamics,
    JointKind, Linear, Origin, Parameter, RobotDescription, Rotation, TaskDesc, Wrist,
};
use serde::Deserialize;
use std::path::Path;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRobot {
    robot: RawMeta,
    #[serde(default)]
    parameters: toml::Table,
    #[serde(default)]
    joints: Vec<toml::Spanned<RawJoint>>,
    end_effector: Option<RawFrame>,
    constraint: Option<RawConstraint>,
    task: Option<RawTask>,
    instrument: Option<RawInstrument>,
    /// Read on its own ([`super::SimulationDesc`]); a table here.
    #[allow(dead_code)]
    simulation: Option<toml::Table>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMeta {
    name: String,
    urdf: Option<String>,
    base: Option<String>,
    tip: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTask {
    select: RawH,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum RawLink {
    Index(usize),
    Name(String),
}

#[derive(Deserialize)]
#[serde(untagged)]
enum RawScalar {
    Number(f64),
    Text(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawJoint {
    name: String,
    #[serde(rename = "type")]
    kind: String,
    xyz: Option<[RawScalar; 3]>,
    rpy: Option<[f64; 3]>,
    rotation: Option<[[f64; 3]; 3]>,
    axis: Option<[f64; 3]>,
    v: Option<[RawScalar; 3]>,
    w: Option<[f64; 3]>,
    limits: Option<[f64; 2]>,
    speed_limit: Option<f64>,
    acceleration_limit: Option<f64>,
    jerk_limit: Option<f64>,
    effort_limit: Option<f64>,
    damping: Option<f64>,
    friction: Option<f64>,
    mass: Option<f64>,
    com: Option<[f64; 3]>,
    inertia: Option<[f64; 6]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInstrument {
    mass: f64,
    radius: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFrame {
    name: Option<String>,
    xyz: Option<[RawScalar; 3]>,
    rpy: Option<[f64; 3]>,
    rotation: Option<[[f64; 3]; 3]>,
}

#[derive(Deserialize)]
#[serde(untagged)]
enum RawH {
    Letters(Vec<String>),
    Rows(Vec<Vec<f64>>),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConstraint {
    link: RawLink,
    xyz: Option<[RawScalar; 3]>,
    rpy: Option<[f64; 3]>,
    rotation: Option<[[f64; 3]; 3]>,
    h: RawH,
    wrist: Option<String>,
}

/// The axis letters of `H` rows, in twist order `(v, ω)`.
pub(crate) const AXIS_LETTERS: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

pub(crate) struct Ctx<'a> {
    pub(crate) file: Option<&'a Path>,
    pub(crate) locator: &'a Locator<'a>,
}

impl Ctx<'_> {
    pub(crate) fn err(&self, field: &str, message: impl Into<String>) -> DescriptionError {
        let loc = self.locator.locate(field);
        DescriptionError {
            file: self.file.map(Path::to_path_buf),
            line: loc.map(|l| l.line),
            column: loc.map(|l| l.column),
            field: field.to_string(),
            message: message.into(),
        }
    }
}

impl Linear {
    /// A single parameter.
    pub fn param(name: &str) -> Self {
        Linear {
            constant: 0.0,
            terms: vec![(1.0, name.to_string())],
        }
    }

    /// `true` when no parameter appears.
    pub fn is_constant(&self) -> bool {
        self.terms.is_empty()
    }

    /// Parses `"l_a + l_b"`, `"-0.5*l_8 + 0.1"`, `"2 * l_a"`, `"(l_a + l_b)/2"` or a number: any
    /// [length expression](crate::expr) linear in its parameters. The error names the byte
    /// offset of the offending token.
    pub fn parse(text: &str) -> Result<Self, String> {
        crate::expr::Expr::parse(text)
            .and_then(|e| e.linear())
            .map_err(|e| format!("cannot read `{}`: {e}", crate::expr::quoted(text)))
    }

    /// Value with the given parameter lookup; `Err(name)` for an unknown parameter.
    pub fn eval(&self, lookup: impl Fn(&str) -> Option<f64>) -> Result<f64, String> {
        let mut v = self.constant;
        for (c, n) in &self.terms {
            v += c * lookup(n).ok_or_else(|| n.clone())?;
        }
        Ok(v)
    }
}

fn scalar(ctx: &Ctx, field: &str, raw: &RawScalar) -> Result<Linear, DescriptionError> {
    match raw {
        RawScalar::Number(v) => Ok(Linear::constant(*v)),
        RawScalar::Text(t) => Linear::parse(t).map_err(|m| ctx.err(field, m)),
    }
}

fn scalars(ctx: &Ctx, field: &str, raw: &[RawScalar; 3]) -> Result<[Linear; 3], DescriptionError> {
    Ok([
        scalar(ctx, &format!("{field}[0]"), &raw[0])?,
        scalar(ctx, &format!("{field}[1]"), &raw[1])?,
        scalar(ctx, &format!("{field}[2]"), &raw[2])?,
    ])
}

fn origin(
    ctx: &Ctx,
    field: &str,
    xyz: &Option<[RawScalar; 3]>,
    rpy: &Option<[f64; 3]>,
    rotation: &Option<[[f64; 3]; 3]>,
) -> Result<Origin, DescriptionError> {
    let xyz = match xyz {
        Some(v) => scalars(ctx, &format!("{field}.xyz"), v)?,
        None => Default::default(),
    };
    let rotation = match (rpy, rotation) {
        (Some(_), Some(_)) => {
            return Err(ctx.err(
                &format!("{field}.rotation"),
                "give either `rpy` or `rotation`, not both",
            ))
        }
        (Some(r), None) => Rotation::Rpy(*r),
        (None, Some(m)) => Rotation::Matrix(*m),
        (None, None) => Rotation::Rpy([0.0; 3]),
    };
    Ok(Origin { xyz, rotation })
}

/// Rows of a selection matrix (`constraint.h`, `task.select`): axis letters or rows of 6 numbers.
fn selection(ctx: &Ctx, prefix: &str, raw: &RawH) -> Result<Vec<[f64; 6]>, DescriptionError> {
    match raw {
        RawH::Rows(rows) => rows
            .iter()
            .enumerate()
            .map(|(k, row)| {
                <[f64; 6]>::try_from(row.as_slice()).map_err(|_| {
                    ctx.err(
                        &format!("{prefix}[{k}]"),
                        format!(
                            "a row has 6 entries (twist order vx vy vz wx wy wz), this one has {}",
                            row.len()
                        ),
                    )
                })
            })
            .collect(),
        RawH::Letters(letters) => letters
            .iter()
            .enumerate()
            .map(|(k, l)| {
                let index = AXIS_LETTERS.iter().position(|a| a == l).ok_or_else(|| {
                    ctx.err(
                        &format!("{prefix}[{k}]"),
                        format!("unknown axis `{l}` (expected x, y, z, rx, ry or rz)"),
                    )
                })?;
                let mut row = [0.0; 6];
                row[index] = 1.0;
                Ok(row)
            })
            .collect(),
    }
}

/// The chain of `[robot] urdf = "…"` between `base` and `tip`, the URDF read relative to the TOML
/// file's folder (shipped descriptions read their shipped URDF).
fn urdf_chain(ctx: &Ctx, rel: &str, meta: &RawMeta) -> Result<UrdfChain, DescriptionError> {
    let tip = meta.tip.as_deref().ok_or_else(|| {
        ctx.err(
            "robot.tip",
            "a chain from a URDF needs `tip = \"LINK\"` in [robot]: the link that carries the end effector",
        )
    })?;
    let (text, path) = match super::presets::shipped_urdf(ctx.file, rel) {
        Some(text) => (text.to_string(), std::path::PathBuf::from(rel)),
        None => {
            let path = match ctx.file.and_then(Path::parent) {
                Some(dir) => dir.join(rel),
                None => std::path::PathBuf::from(rel),
            };
            let text = DescriptionError::read_file(&path).map_err(|e| {
                ctx.err(
                    "robot.urdf",
                    format!("the URDF `{}`: {}", path.display(), e.message),
                )
            })?;
            (text, path)
        }
    };
    let mut chain = import_chain(&text, meta.base.as_deref(), tip, Some(&path), &|key| {
        format!("robot.{key}")
    })
    .map_err(|mut e| {
        // Base and tip errors are about this file's keys; the others about the URDF's text.
        if e.field.starts_with("robot.") {
            let at = ctx.err(&e.field, "");
            e.file = at.file;
            e.line = at.line;
            e.column = at.column;
            e.message = format!("{} (in `{}`)", e.message, path.display());
        }
        e
    })?;
    // Joint lines are the URDF's, not this file's.
    for j in &mut chain.joints {
        j.location = None;
    }
    Ok(chain)
}

/// `field` without its last key: the table it lives in.
fn parent_of(field: &str) -> &str {
    field.rfind('.').map_or("", |k| &field[..k])
}

fn table_phrase(table: &str) -> String {
    if table.is_empty() {
        "at the top level".into()
    } else {
        format!("in table `{table}`")
    }
}

/// A serde/TOML error as a description error ([`toml_error`]), for the other readers of a
/// description's text.
pub(crate) fn toml_error_of(ctx: &Ctx, text: &str, e: &toml::de::Error) -> DescriptionError {
    toml_error(ctx, text, e)
}

/// A serde/TOML error as a description error: the field found from the error's span, a message
/// that names the key and its table.
fn toml_error(ctx: &Ctx, text: &str, e: &toml::de::Error) -> DescriptionError {
    let message = e.message().trim();
    let offset = e.span().map(|s| s.start);
    let at = offset.and_then(|o| ctx.locator.path_at(o));
    let quoted = message.split('`').nth(1).unwrap_or("").to_string();
    let syntax = !ctx.locator.syntax_ok && message != "duplicate key";
    let (field, message) = if syntax {
        // Paths in a broken document can mislead: the position says where.
        (
            "(document)".to_string(),
            format!("not valid TOML: {message}"),
        )
    } else if let Some(rest) = message.strip_prefix("unknown field `") {
        let field = at.unwrap_or_else(|| quoted.clone());
        let table = parent_of(&field).to_string();
        let expected = rest.split_once(", ").map_or("", |(_, e)| e).to_string();
        let message = format!(
            "unknown key `{quoted}` {}{}",
            table_phrase(&table),
            if expected.is_empty() {
                String::new()
            } else {
                format!(" ({expected})")
            }
        );
        (field, message)
    } else if message.starts_with("missing field `") {
        let table = match e.span() {
            Some(span) if !span.is_empty() => at.unwrap_or_default(),
            _ => String::new(),
        };
        let field = if table.is_empty() {
            quoted.clone()
        } else {
            format!("{table}.{quoted}")
        };
        (
            field,
            format!("missing key `{quoted}` {}", table_phrase(&table)),
        )
    } else if message.contains("untagged enum RawScalar") {
        // The span is the array's: name the offending element.
        let at = at.map(|a| ctx.locator.first_non_scalar(&a).unwrap_or(a));
        (
            at.unwrap_or_else(|| "(document)".into()),
            "expected a number or a parameter expression such as \"l_a + l_b\"".into(),
        )
    } else if message.contains("untagged enum RawH") {
        (
            at.unwrap_or_else(|| "constraint.h".into()),
            "expected axis letters such as [\"x\", \"z\"] or rows of 6 numbers".into(),
        )
    } else if message == "duplicate key" {
        // The second key is not in the (recovered) document: name it from the text.
        let span = e.span().unwrap_or(0..0);
        let key = text
            .get(span.clone())
            .unwrap_or("")
            .trim_matches(['"', '\''])
            .to_string();
        let table = ctx.locator.table_before(span.start);
        let field = if table.is_empty() {
            key.clone()
        } else {
            format!("{table}.{key}")
        };
        (
            field,
            format!("duplicate key `{key}` {}", table_phrase(&table)),
        )
    } else if let Some(field) = at {
        (field, message.to_string())
    } else {
        ("(document)".into(), message.to_string())
    };
    let loc = match ctx.locator.locate(&field) {
        // The element named above, rather than the array the error points at.
        Some(l) if field.ends_with(']') => Some(l),
        _ => offset.map(|o| location_of(text, o)),
    };
    DescriptionError {
        file: ctx.file.map(Path::to_path_buf),
        line: loc.map(|l| l.line),
        column: loc.map(|l| l.column),
        field,
        message,
    }
}

impl RobotDescription {
    /// Reads a description from TOML text and validates it ([`RobotDescription::validate`]), every
    /// error with the line and column of its field. `file` is used in error messages only.
    pub fn from_toml_str(text: &str, file: Option<&Path>) -> Result<Self, DescriptionError> {
        let locator = Locator::new(text);
        let description = Self::read(text, file, &locator)?;
        let problems = super::validate::problems(&description, &|field| locator.locate(field));
        match problems.into_iter().next() {
            Some(first) => Err(first),
            None => Ok(description),
        }
    }

    /// Reads a description from TOML text without the checks of [`RobotDescription::validate`]:
    /// only the format is checked (TOML syntax, known keys, types, axis letters, joint types).
    /// Use [`RobotDescription::problems`] to list every problem of the result at once.
    pub fn from_toml_str_unvalidated(
        text: &str,
        file: Option<&Path>,
    ) -> Result<Self, DescriptionError> {
        Self::read(text, file, &Locator::new(text))
    }

    fn read(text: &str, file: Option<&Path>, locator: &Locator) -> Result<Self, DescriptionError> {
        let ctx = Ctx { file, locator };
        let raw: RawRobot = toml::from_str(text).map_err(|e| toml_error(&ctx, text, &e))?;
        let mut parameters = Vec::new();
        for (name, value) in &raw.parameters {
            if name == "pi" {
                return Err(ctx.err(
                    &format!("parameters.{name}"),
                    "`pi` is the constant π in expressions, which a parameter of that name \
                     would silently lose to; give the parameter another name"
                        .to_string(),
                ));
            }
            let value = match value {
                toml::Value::Float(v) => *v,
                toml::Value::Integer(v) => *v as f64,
                other => {
                    return Err(ctx.err(
                        &format!("parameters.{name}"),
                        format!(
                            "a parameter's nominal value must be a number, not a {}",
                            other.type_str()
                        ),
                    ))
                }
            };
            parameters.push(Parameter {
                name: name.clone(),
                value,
            });
        }
        let urdf = match &raw.robot.urdf {
            Some(rel) => Some(urdf_chain(&ctx, rel, &raw.robot)?),
            None => {
                for (key, given) in [("base", &raw.robot.base), ("tip", &raw.robot.tip)] {
                    if given.is_some() {
                        return Err(ctx.err(
                            &format!("robot.{key}"),
                            format!("`{key}` names a URDF link: it needs `urdf = \"FILE.urdf\"` in [robot]"),
                        ));
                    }
                }
                None
            }
        };
        if urdf.is_some() && !raw.joints.is_empty() {
            return Err(ctx.err(
                "joints[0]",
                "the chain comes from the URDF (`robot.urdf`): remove the [[joints]] tables, or the `urdf` key",
            ));
        }
        let mut joints = urdf.as_ref().map_or_else(Vec::new, |u| u.joints.clone());
        if joints.len() + raw.joints.len() > super::MAX_JOINTS {
            let field = if joints.is_empty() {
                format!("joints[{}]", super::MAX_JOINTS)
            } else {
                "robot.urdf".to_string()
            };
            return Err(ctx.err(
                &field,
                format!(
                    "{} joints: a robot has at most {}",
                    joints.len() + raw.joints.len(),
                    super::MAX_JOINTS
                ),
            ));
        }
        for (k, spanned) in raw.joints.iter().enumerate() {
            let loc = Some(location_of(text, spanned.span().start));
            let j = spanned.get_ref();
            let field = format!("joints[{k}]");
            let unused = |key: &str, present: bool, why: &str| {
                if present {
                    Err(ctx.err(&format!("{field}.{key}"), why.to_string()))
                } else {
                    Ok(())
                }
            };
            let kind = match j.kind.as_str() {
                "revolute" | "prismatic" => {
                    let why = format!("a {} joint has an `axis`, not a twist", j.kind);
                    unused("v", j.v.is_some(), &why)?;
                    unused("w", j.w.is_some(), &why)?;
                    let axis = j.axis.ok_or_else(|| {
                        ctx.err(
                            &format!("{field}.axis"),
                            format!("a {} joint needs `axis = [x, y, z]`", j.kind),
                        )
                    })?;
                    if j.kind == "revolute" {
                        JointKind::Revolute { axis }
                    } else {
                        JointKind::Prismatic { axis }
                    }
                }
                "twist" => {
                    unused(
                        "axis",
                        j.axis.is_some(),
                        "a twist joint has `v` and `w`, not an `axis`",
                    )?;
                    let v = j.v.as_ref().ok_or_else(|| {
                        ctx.err(&format!("{field}.v"), "a twist joint needs `v = [x, y, z]`")
                    })?;
                    let w = j.w.ok_or_else(|| {
                        ctx.err(&format!("{field}.w"), "a twist joint needs `w = [x, y, z]`")
                    })?;
                    JointKind::Twist {
                        v: scalars(&ctx, &format!("{field}.v"), v)?,
                        w,
                    }
                }
                other => {
                    return Err(ctx.err(
                        &format!("{field}.type"),
                        format!(
                            "unknown joint type `{other}` (expected revolute, prismatic or twist)"
                        ),
                    ))
                }
            };
            joints.push(JointDesc {
                name: j.name.clone(),
                origin: origin(&ctx, &field, &j.xyz, &j.rpy, &j.rotation)?,
                kind,
                limits: j.limits,
                speed_limit: j.speed_limit,
                acceleration_limit: j.acceleration_limit,
                jerk_limit: j.jerk_limit,
                dynamics: JointDynamics {
                    effort_limit: j.effort_limit,
                    damping: j.damping,
                    friction: j.friction,
                    inertia: match (j.mass, j.com, j.inertia) {
                        (None, None, None) => None,
                        (Some(mass), com, Some(inertia)) => Some(Inertia {
                            mass,
                            com: com.unwrap_or([0.0; 3]),
                            inertia,
                        }),
                        (None, ..) => {
                            return Err(ctx.err(
                                &format!("{field}.mass"),
                                "`com` and `inertia` need the link's `mass` (kg)",
                            ))
                        }
                        (Some(_), _, None) => {
                            return Err(ctx.err(
                                &format!("{field}.inertia"),
                                "`mass` needs the link's `inertia = [ixx, iyy, izz, ixy, ixz, iyz]` (kg m², about the centre of mass `com`)",
                            ))
                        }
                    },
                },
                location: loc,
            });
        }
        let mut end_effector = match &raw.end_effector {
            Some(f) => EndEffector {
                name: f.name.clone().unwrap_or_else(|| "end_effector".into()),
                origin: origin(&ctx, "end_effector", &f.xyz, &f.rpy, &f.rotation)?,
            },
            None => EndEffector {
                name: "end_effector".into(),
                origin: Origin {
                    xyz: Default::default(),
                    rotation: Rotation::Rpy([0.0; 3]),
                },
            },
        };
        if let Some(u) = &urdf {
            // `[end_effector]` is written relative to the tip link's frame.
            end_effector.origin = u.tip.compose(&end_effector.origin);
            if raw.end_effector.as_ref().is_none_or(|f| f.name.is_none()) {
                end_effector.name = raw.robot.tip.clone().unwrap_or_default();
            }
        }
        let constraint = match &raw.constraint {
            None => None,
            Some(c) => {
                let h = selection(&ctx, "constraint.h", &c.h)?;
                let (link, offset) = match &c.link {
                    RawLink::Index(i) => (*i, None),
                    RawLink::Name(name) => {
                        let Some(u) = &urdf else {
                            return Err(ctx.err(
                                "constraint.link",
                                format!("`{name}` is a link name, which needs the chain from a URDF (`urdf = \"FILE.urdf\"` in [robot]); otherwise give the link's number i (link i is carried by joint i)"),
                            ));
                        };
                        let Some((_, k, pose)) = u.links.iter().find(|(n, _, _)| n == name) else {
                            let on_path: Vec<&str> =
                                u.links.iter().map(|(n, _, _)| n.as_str()).collect();
                            return Err(ctx.err(
                                "constraint.link",
                                format!(
                                    "link `{name}` is not on the chain from the base to the tip (links on it: {})",
                                    super::urdf::capped_list(&on_path)
                                ),
                            ));
                        };
                        if *k == 0 {
                            return Err(ctx.err(
                                "constraint.link",
                                format!("link `{name}` is fixed to the base (no joint moves it); the constraint needs a link that a joint carries"),
                            ));
                        }
                        (*k, Some(*pose))
                    }
                };
                let wrist = match c.wrist.as_deref() {
                    None => None,
                    Some("unidirectional") => Some(Wrist::Unidirectional),
                    Some("zy") => Some(Wrist::Zy),
                    Some("zx") => Some(Wrist::Zx),
                    Some(other) => {
                        return Err(ctx.err(
                            "constraint.wrist",
                            format!("unknown wrist `{other}` (expected unidirectional, zy or zx)"),
                        ))
                    }
                };
                let origin = origin(&ctx, "constraint", &c.xyz, &c.rpy, &c.rotation)?;
                // A named link that fixed joints attach to joint i's child is F_i itself: joint
                // i's frame moves there (`move_joint_frame`), so `fk_i`, `J^B_0i` and `g_ir` are
                // all in the frame the user named.
                let moved = offset.is_some_and(|pose| {
                    pose.is_identity()
                        || move_joint_frame(&mut joints, &mut end_effector, link, &pose)
                });
                Some(ConstraintDesc {
                    link,
                    // Otherwise written relative to the named link's frame, at `offset` in F_i.
                    origin: match offset {
                        Some(pose) if !moved => pose.compose(&origin),
                        _ => origin,
                    },
                    h,
                    wrist,
                })
            }
        };
        Ok(RobotDescription {
            name: raw.robot.name,
            parameters,
            joints,
            end_effector,
            constraint,
            task: match &raw.task {
                Some(t) => Some(TaskDesc {
                    select: selection(&ctx, "task.select", &t.select)?,
                }),
                None => None,
            },
            instrument: raw.instrument.as_ref().map(|i| Instrument {
                mass: i.mass,
                radius: i.radius,
            }),
            source: file.map(Path::to_path_buf),
        })
    }

    /// The files a TOML description at `path` is read from: `path` itself and, when its chain comes
    /// from a URDF (`[robot] urdf = "…"`), that URDF (for `cargo:rerun-if-changed`). Unreadable
    /// files are listed all the same: reading them reports the error.
    pub fn files_read(path: impl AsRef<Path>) -> Vec<std::path::PathBuf> {
        let path = path.as_ref();
        let mut out = vec![path.to_path_buf()];
        let urdf = std::fs::read_to_string(path)
            .ok()
            .and_then(|text| text.parse::<toml::Table>().ok())
            .and_then(|t| {
                t.get("robot")?
                    .get("urdf")?
                    .as_str()
                    .map(std::string::ToString::to_string)
            });
        if let Some(rel) = urdf {
            out.push(match path.parent() {
                Some(dir) => dir.join(rel),
                None => rel.into(),
            });
        }
        out
    }

    /// Reads a description from a TOML file.
    pub fn from_toml_file(path: impl AsRef<Path>) -> Result<Self, DescriptionError> {
        let path = path.as_ref();
        let text = DescriptionError::read_file(path)?;
        Self::from_toml_str(&text, Some(path))
    }

    /// One of the shipped descriptions (see [`super::PRESETS`]) by name.
    pub fn preset(name: &str) -> Result<Self, DescriptionError> {
        let text = super::preset(name).ok_or_else(|| DescriptionError {
            file: None,
            line: None,
            column: None,
            field: "preset".into(),
            message: format!(
                "unknown preset `{name}` (expected one of: {})",
                super::preset_names().collect::<Vec<_>>().join(", ")
            ),
        })?;
        Self::from_toml_str(text, Some(Path::new(&format!("<preset {name}>"))))
    }

    /// Nominal value of a parameter.
    pub fn parameter(&self, name: &str) -> Option<f64> {
        self.parameters
            .iter()
            .find(|p| p.name == name)
            .map(|p| p.value)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalars_parse_linear_combinations() {
        let s = Linear::parse("l_a + l_b").unwrap();
        assert_eq!(s.terms, vec![(1.0, "l_a".into()), (1.0, "l_b".into())]);
        let s = Linear::parse("-0.5*l_8 + 0.1 - 2e-1").unwrap();
        assert_eq!(s.terms, vec![(-0.5, "l_8".into())]);
        assert!((s.constant - (-0.1)).abs() < 1e-15);
        assert!(Linear::parse("l_a*l_b").is_err());
        assert!(Linear::parse("l_a + $").is_err());
        assert_eq!(Linear::parse("2*l_a").unwrap().eval(|_| Some(0.5)), Ok(1.0));
        assert_eq!(
            Linear::parse("l_q").unwrap().eval(|_| None),
            Err("l_q".into())
        );
    }

    #[test]
    fn every_shipped_description_reads() {
        for name in super::super::preset_names() {
            let d = RobotDescription::preset(name).unwrap();
            let from_urdf = [
                ("panda-laparoscope", 7),
                ("iiwa-endoscope", 7),
                ("iiwa-link6", 6),
            ];
            if let Some((_, link)) = from_urdf.iter().find(|(n, _)| *n == name) {
                // The chain comes from a shipped URDF: no TOML lines for its joints.
                assert_eq!(d.joints.len(), 7, "{name}");
                assert_eq!(d.constraint.as_ref().unwrap().link, *link, "{name}");
                assert!(d.joints.iter().all(|j| j.location.is_none()), "{name}");
                continue;
            }
            assert_eq!(d.joints.len(), 8, "{name}");
            assert_eq!(d.constraint.as_ref().unwrap().link, 6);
            assert!(d.joints[1].location.unwrap().line > 10);
        }
    }
}
