//! Reading a scene file: its TOML, its arms' descriptions, their mirror images, parameters and
//! bases; then [`super::admission`].

use super::{CameraDescription, CouplingDescription, SceneArmDescription, SceneDescription};
use crate::description::locate::Locator;
use crate::description::parse::{toml_error_of, Ctx};
use crate::description::{
    preset_names, DescriptionError, Inertia, JointDesc, JointKind, Linear, Origin,
    RobotDescription, Rotation,
};
use crate::validity;
use nalgebra::Vector3;
use serde::Deserialize;
use std::path::{Path, PathBuf};
use trocar::control::scene::Between;
use trocar::se3::Se3;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    scene: RawMeta,
    arms: Vec<RawArm>,
    #[serde(default)]
    couplings: Vec<RawCoupling>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMeta {
    name: String,
    orientation_weight: Option<f64>,
    rate_weight: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawArm {
    name: String,
    robot: String,
    base: Option<RawBase>,
    q0: Vec<f64>,
    #[serde(default)]
    parameters: toml::Table,
    #[serde(default)]
    mirror: bool,
    shares: Option<RawShares>,
    camera: Option<RawCamera>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawBase {
    xyz: Option<[f64; 3]>,
    port: Option<[f64; 3]>,
    rpy: Option<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawShares {
    arm: String,
    joints: usize,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCamera {
    looks_at: Vec<String>,
    depth: Option<f64>,
    tolerance: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCoupling {
    between: [String; 2],
    kind: Option<String>,
    safety: f64,
    influence: f64,
    gain: Option<f64>,
}

/// A lowercase Rust identifier (`three_ports`, `left`): a module's name.
fn is_module_name(name: &str) -> bool {
    let mut chars = name.chars();
    chars
        .next()
        .is_some_and(|c| c.is_ascii_lowercase() || c == '_')
        && chars.all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
        && name != "_"
        && ![
            "self", "super", "crate", "mod", "fn", "type", "use", "as", "in", "ref", "move",
            "match", "loop", "let", "impl", "pub", "static", "const", "struct", "enum", "trait",
            "where", "while", "for", "if", "else", "return", "true", "false", "unsafe", "extern",
            "dyn", "async", "await", "break", "continue", "box", "do", "final", "macro",
            "override", "priv", "typeof", "unsized", "virtual", "yield", "try", "abstract",
            "become", "gen",
        ]
        .contains(&name)
}

/// Where a scene's arm descriptions are looked up from: the scene file's folder.
fn folder(file: Option<&Path>) -> Option<PathBuf> {
    let f = file?;
    let s = f.to_str().unwrap_or("");
    if s.starts_with('<') && s.ends_with('>') {
        return None;
    }
    Some(f.parent().map(Path::to_path_buf).unwrap_or_default())
}

/// An arm's `robot`: a file relative to the scene's folder when there is one, else a shipped
/// description.
fn robot_of(
    ctx: &Ctx,
    field: &str,
    robot: &str,
    file: Option<&Path>,
) -> Result<RobotDescription, DescriptionError> {
    if let Some(dir) = folder(file) {
        let path = dir.join(robot);
        if path.is_file() {
            return RobotDescription::from_toml_file(&path);
        }
    }
    if preset_names().any(|n| n == robot) {
        return RobotDescription::preset(robot);
    }
    Err(ctx.err(
        field,
        format!(
            "`{robot}` is neither a description file (relative to the scene file) nor a shipped \
             description ({})",
            preset_names().collect::<Vec<_>>().join(", ")
        ),
    ))
}

fn number(ctx: &Ctx, field: &str, v: f64) -> Result<f64, DescriptionError> {
    validity::check(v).map_err(|p| ctx.err(field, format!("{v} {p}")))?;
    Ok(v)
}

fn numbers<const K: usize>(
    ctx: &Ctx,
    field: &str,
    v: &[f64; K],
) -> Result<[f64; K], DescriptionError> {
    for (k, x) in v.iter().enumerate() {
        number(ctx, &format!("{field}[{k}]"), *x)?;
    }
    Ok(*v)
}

/// An arm's index by name.
fn arm_index(
    ctx: &Ctx,
    field: &str,
    names: &[String],
    name: &str,
) -> Result<usize, DescriptionError> {
    names.iter().position(|n| n == name).ok_or_else(|| {
        ctx.err(
            field,
            format!(
                "no arm named `{name}` in the scene (its arms: {})",
                names.join(", ")
            ),
        )
    })
}

pub(super) fn read(text: &str, file: Option<&Path>) -> Result<SceneDescription, DescriptionError> {
    let locator = Locator::new(text);
    let ctx = Ctx {
        file,
        locator: &locator,
    };
    let raw: RawScene = toml::from_str(text).map_err(|e| toml_error_of(&ctx, text, &e))?;
    if !is_module_name(&raw.scene.name) {
        return Err(ctx.err(
            "scene.name",
            format!(
                "`{}` is not a lowercase Rust identifier (the scene's module is named after it)",
                raw.scene.name
            ),
        ));
    }
    if raw.arms.is_empty() {
        return Err(ctx.err("arms", "a scene needs at least one arm ([[arms]])"));
    }
    let names: Vec<String> = raw.arms.iter().map(|a| a.name.clone()).collect();
    for (k, name) in names.iter().enumerate() {
        if !is_module_name(name) {
            return Err(ctx.err(
                &format!("arms[{k}].name"),
                format!("`{name}` is not a lowercase Rust identifier (the arm's module is named after it)"),
            ));
        }
        if names[..k].contains(name) {
            return Err(ctx.err(
                &format!("arms[{k}].name"),
                format!("a second arm named `{name}`"),
            ));
        }
    }
    let mut arms = Vec::with_capacity(raw.arms.len());
    for (k, a) in raw.arms.iter().enumerate() {
        let at = |f: &str| format!("arms[{k}].{f}");
        let mut robot = robot_of(&ctx, &at("robot"), &a.robot, file)?;
        for (name, value) in &a.parameters {
            let field = at(&format!("parameters.{name}"));
            let Some(v) = value
                .as_float()
                .or_else(|| value.as_integer().map(|i| i as f64))
            else {
                return Err(ctx.err(&field, "expected a number"));
            };
            let v = number(&ctx, &field, v)?;
            match robot.parameters.iter_mut().find(|p| &p.name == name) {
                Some(p) => p.value = v,
                None => {
                    return Err(ctx.err(
                        &field,
                        format!(
                            "the arm's robot has no parameter `{name}` (its parameters: {})",
                            robot
                                .parameters
                                .iter()
                                .map(|p| p.name.as_str())
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    ))
                }
            }
        }
        let shares = match &a.shares {
            None => None,
            Some(s) => {
                let other = arm_index(&ctx, &at("shares.arm"), &names, &s.arm)?;
                if other == k {
                    return Err(
                        ctx.err(&at("shares.arm"), "an arm cannot share joints with itself")
                    );
                }
                if raw.arms[other]
                    .shares
                    .as_ref()
                    .is_some_and(|o| o.arm == a.name)
                {
                    return Err(ctx.err(
                        &at("shares.arm"),
                        format!(
                            "`{}` already shares its joints with `{}`: name the shared joints on \
                             one of the two arms",
                            s.arm, a.name
                        ),
                    ));
                }
                if s.joints == 0 {
                    return Err(ctx.err(&at("shares.joints"), "share at least one joint"));
                }
                Some((other, s.joints))
            }
        };
        // The arm's description at the scene's parameter values, admitted as one robot's.
        robot.validate().map_err(|e| {
            ctx.err(
                &at("parameters"),
                format!(
                    "`{}` at the scene's parameters is not admitted: {e}",
                    a.robot
                ),
            )
        })?;
        if a.mirror {
            robot = mirrored(&robot, shares.map_or(0, |s| s.1));
            robot.validate().map_err(|e| {
                ctx.err(
                    &at("mirror"),
                    format!("the mirror image of `{}` is not admitted: {e}", a.robot),
                )
            })?;
        }
        let n = robot.joints.len();
        if a.q0.len() != n {
            return Err(ctx.err(
                &at("q0"),
                format!("{} values for the {n} joints of `{}`", a.q0.len(), a.robot),
            ));
        }
        for (j, v) in a.q0.iter().enumerate() {
            number(&ctx, &at(&format!("q0[{j}]")), *v)?;
            if let Some([lo, hi]) = robot.joints[j].limits {
                if *v < lo || *v > hi {
                    return Err(ctx.err(
                        &at(&format!("q0[{j}]")),
                        format!(
                            "{v} is outside joint `{}`'s range [{lo}, {hi}]",
                            robot.joints[j].name
                        ),
                    ));
                }
            }
        }
        let camera = match &a.camera {
            None => None,
            Some(c) => {
                if c.looks_at.is_empty() {
                    return Err(ctx.err(&at("camera.looks_at"), "name at least one arm"));
                }
                let mut looks_at = Vec::new();
                for (m, name) in c.looks_at.iter().enumerate() {
                    let field = at(&format!("camera.looks_at[{m}]"));
                    let i = arm_index(&ctx, &field, &names, name)?;
                    if i == k {
                        return Err(ctx.err(&field, "a camera cannot look at its own tip"));
                    }
                    looks_at.push(i);
                }
                let depth = match c.depth {
                    None => None,
                    Some(d) => {
                        let d = number(&ctx, &at("camera.depth"), d)?;
                        if d <= 0.0 {
                            return Err(ctx.err(
                                &at("camera.depth"),
                                "the tip's depth below the port must be positive (m)",
                            ));
                        }
                        Some(d)
                    }
                };
                let tolerance = number(&ctx, &at("camera.tolerance"), c.tolerance)?;
                if tolerance <= 0.0 {
                    return Err(ctx.err(&at("camera.tolerance"), "must be positive (rad)"));
                }
                Some(CameraDescription {
                    looks_at,
                    depth,
                    tolerance,
                })
            }
        };
        let rpy = match a.base.as_ref().and_then(|b| b.rpy) {
            Some(r) => numbers(&ctx, &at("base.rpy"), &r)?,
            None => [0.0; 3],
        };
        let rotation = trocar::se3::rotation_from_rpy(rpy[0], rpy[1], rpy[2]);
        let translation = match a.base.as_ref().map(|b| (b.xyz, b.port)) {
            None | Some((None, None)) => Vector3::zeros(),
            Some((Some(_), Some(_))) => {
                return Err(ctx.err(
                    &at("base"),
                    "give the base's origin (`xyz`) or where its port is (`port`), not both",
                ))
            }
            Some((Some(xyz), None)) => Vector3::from(numbers(&ctx, &at("base.xyz"), &xyz)?),
            Some((None, Some(port))) => {
                let port = Vector3::from(numbers(&ctx, &at("base.port"), &port)?);
                let model = crate::numeric::NumericModel::<f64>::from_description(&robot, &[])
                    .map_err(|e| ctx.err(&at("robot"), e.to_string()))?;
                let own = super::admission::port_at(&model, &a.q0)
                    .map_err(|e| ctx.err(&at("base.port"), e))?;
                port - rotation * own
            }
        };
        arms.push(SceneArmDescription {
            name: a.name.clone(),
            robot_source: a.robot.clone(),
            robot,
            base: Se3::new(rotation, translation),
            q0: a.q0.clone(),
            mirror: a.mirror,
            shares,
            camera,
        });
    }
    if let Some(second) = arms
        .iter()
        .enumerate()
        .filter(|(_, a)| a.camera.is_some())
        .nth(1)
    {
        return Err(ctx.err(
            &format!("arms[{}].camera", second.0),
            "a scene has one endoscope: a second camera",
        ));
    }
    let mut couplings = Vec::with_capacity(raw.couplings.len());
    for (p, c) in raw.couplings.iter().enumerate() {
        let at = |f: &str| format!("couplings[{p}].{f}");
        let a = arm_index(&ctx, &at("between[0]"), &names, &c.between[0])?;
        let b = arm_index(&ctx, &at("between[1]"), &names, &c.between[1])?;
        if a == b {
            return Err(ctx.err(&at("between"), "a coupling is between two different arms"));
        }
        let between = match c.kind.as_deref() {
            None | Some("shafts") => Between::Shafts,
            Some("tips") => Between::Tips,
            Some(other) => {
                return Err(ctx.err(
                    &at("kind"),
                    format!("`{other}`: expected \"shafts\" or \"tips\""),
                ))
            }
        };
        let safety = number(&ctx, &at("safety"), c.safety)?;
        let influence = number(&ctx, &at("influence"), c.influence)?;
        let gain = number(&ctx, &at("gain"), c.gain.unwrap_or(0.1))?;
        if safety <= 0.0 {
            return Err(ctx.err(&at("safety"), "the safety distance must be positive (m)"));
        }
        if influence <= safety {
            return Err(ctx.err(
                &at("influence"),
                format!("the influence distance {influence} m must exceed the safety distance {safety} m"),
            ));
        }
        if gain <= 0.0 {
            return Err(ctx.err(&at("gain"), "the damper's gain must be positive (m/s)"));
        }
        couplings.push(CouplingDescription {
            arms: (a, b),
            between,
            safety,
            influence,
            gain,
        });
    }
    let weight = |field: &str, v: Option<f64>, default: f64| -> Result<f64, DescriptionError> {
        let v = number(&ctx, field, v.unwrap_or(default))?;
        if v <= 0.0 {
            return Err(ctx.err(field, "a weight must be positive"));
        }
        Ok(v)
    };
    let orientation_weight = weight(
        "scene.orientation_weight",
        raw.scene.orientation_weight,
        0.1,
    )?;
    let rate_weight = weight("scene.rate_weight", raw.scene.rate_weight, 1e-3)?;
    let scene = SceneDescription {
        name: raw.scene.name,
        orientation_weight,
        rate_weight,
        arms,
        couplings,
        source: file.map(Path::to_path_buf),
    };
    super::admission::admit(&scene, &|field: &str, message: String| {
        ctx.err(field, message)
    })?;
    Ok(scene)
}

/// The files a scene at `path` reads (see [`SceneDescription::files_read`]).
pub(super) fn files_read(path: &Path) -> Vec<PathBuf> {
    let mut out = vec![path.to_path_buf()];
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let robots = std::fs::read_to_string(path)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
        .and_then(|t| t.get("arms")?.as_array().cloned())
        .unwrap_or_default();
    for arm in robots {
        if let Some(robot) = arm.get("robot").and_then(toml::Value::as_str) {
            let file = dir.join(robot);
            if file.is_file() {
                for f in RobotDescription::files_read(&file) {
                    if !out.contains(&f) {
                        out.push(f);
                    }
                }
            }
        }
    }
    out
}

/// `0 − x`: the negation without a negative zero.
fn negate(x: f64) -> f64 {
    0.0 - x
}

fn mirror_linear(l: &Linear) -> Linear {
    Linear {
        constant: negate(l.constant),
        terms: l
            .terms
            .iter()
            .map(|(a, n)| (negate(*a), n.clone()))
            .collect(),
    }
}

/// `M p` for a point, `(M p, M R M)` for an origin.
fn mirror_origin(o: &Origin) -> Origin {
    let [x, y, z] = &o.xyz;
    let rotation = match &o.rotation {
        Rotation::Rpy([r, p, y]) => Rotation::Rpy([*r, negate(*p), negate(*y)]),
        Rotation::Matrix(m) => {
            let mut m = *m;
            for (r, c) in [(0, 1), (0, 2), (1, 0), (2, 0)] {
                m[r][c] = negate(m[r][c]);
            }
            Rotation::Matrix(m)
        }
    };
    Origin {
        xyz: [mirror_linear(x), y.clone(), z.clone()],
        rotation,
    }
}

/// `h D` with `D = diag(−1, 1, 1, 1, −1, −1)`; a row of one axis keeps its sign.
fn mirror_row(h: &[f64; 6]) -> [f64; 6] {
    let d = [-1.0, 1.0, 1.0, 1.0, -1.0, -1.0];
    let row: [f64; 6] = std::array::from_fn(|c| if h[c] == 0.0 { 0.0 } else { h[c] * d[c] });
    let nonzero: Vec<f64> = row.iter().copied().filter(|v| *v != 0.0).collect();
    if nonzero.len() == 1 && nonzero[0] < 0.0 {
        row.map(|v| if v == 0.0 { 0.0 } else { -v })
    } else {
        row
    }
}

fn mirror_inertia(i: &Inertia) -> Inertia {
    let [xx, yy, zz, xy, xz, yz] = i.inertia;
    Inertia {
        mass: i.mass,
        com: [negate(i.com[0]), i.com[1], i.com[2]],
        inertia: [xx, yy, zz, negate(xy), negate(xz), yz],
    }
}

pub(super) fn mirrored(d: &RobotDescription, kept: usize) -> RobotDescription {
    let mut out = d.clone();
    for j in out.joints.iter_mut().skip(kept) {
        *j = JointDesc {
            origin: mirror_origin(&j.origin),
            kind: match &j.kind {
                // `M Rot(a, θ) M = Rot(M a, −θ)`: the axis mirrored, the angle negated.
                JointKind::Revolute { axis } => JointKind::Revolute {
                    axis: [negate(axis[0]), axis[1], axis[2]],
                },
                JointKind::Prismatic { axis } => JointKind::Prismatic {
                    axis: [negate(axis[0]), axis[1], axis[2]],
                },
                // `M exp(ξ θ) M = exp(ξ' θ)` with `ξ' = (M v, −M ω)`; for a rotation, at `−θ`:
                // `(−M v, M ω)`.
                JointKind::Twist { v, w } if w.iter().any(|c| *c != 0.0) => JointKind::Twist {
                    v: [v[0].clone(), mirror_linear(&v[1]), mirror_linear(&v[2])],
                    w: [negate(w[0]), w[1], w[2]],
                },
                JointKind::Twist { v, w } => JointKind::Twist {
                    v: [mirror_linear(&v[0]), v[1].clone(), v[2].clone()],
                    w: *w,
                },
            },
            // A mirrored rotation counts its angle the other way: its range is negated.
            limits: match &j.kind {
                JointKind::Prismatic { .. } => j.limits,
                JointKind::Twist { w, .. } if w.iter().all(|c| *c == 0.0) => j.limits,
                _ => j.limits.map(|[lo, hi]| [negate(hi), negate(lo)]),
            },
            dynamics: {
                let mut dy = j.dynamics;
                dy.inertia = dy.inertia.as_ref().map(mirror_inertia);
                dy
            },
            ..j.clone()
        };
    }
    out.end_effector.origin = mirror_origin(&out.end_effector.origin);
    if let Some(c) = out.constraint.as_mut() {
        c.origin = mirror_origin(&c.origin);
        c.h = c.h.iter().map(mirror_row).collect();
    }
    if let Some(t) = out.task.as_mut() {
        t.select = t.select.iter().map(mirror_row).collect();
    }
    out
}
