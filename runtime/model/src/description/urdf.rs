//! Importing numeric chains from URDF files (with the `urdf-rs` crate).
//!
//! [`RobotDescription::from_urdf_file`] walks the kinematic tree from the root link (the one link
//! that is no joint's child) to the requested tip link:
//!
//! - `revolute` and `continuous` joints become revolute joints, `prismatic` joints prismatic ones;
//!   the axis is normalised (a zero or non-finite axis is an error);
//! - a joint's origin (`xyz`, `rpy`) is kept as written; `fixed` joints are folded into the origin
//!   of the next moving joint (which then carries a rotation matrix, with entries below 1e-15 set
//!   to 0), or into the end effector;
//! - `floating`, `planar` and `spherical` joints on the path are errors, and so are `<mimic>`
//!   joints (their value would silently become an independent entry of `q`);
//! - a joint's `<limit lower upper>` becomes its [`limits`](super::JointDesc::limits) (none for
//!   `continuous` joints, and none for equal bounds, as for a joint without `<limit>`); a bound
//!   that breaks the number rule ([`crate::validity`]) or a lower bound above the upper one is an
//!   error;
//! - every link a joint names must be declared with `<link>`;
//! - the end effector is the tip link's frame, named after it.
//!
//! A TOML description takes its chain from a URDF with `[robot] urdf = "panda.urdf"` (relative to
//! the TOML file), `base` and `tip` link names; its `[constraint] link` may then name a URDF link
//! (see [`super::parse`]). The named link's frame is `F_i`, exactly: when fixed joints attach it
//! to the child of moving joint `i` (`panda_link8`, a UR arm's `tool0`), joint `i`'s frame is
//! moved to it (its origin and axis, or twist, rewritten, and the next origin with them), so that
//! `fk_i`, `J^B_0i` and the constraint offset `g_ir` are all in the frame the user named, as the
//! end effector is the `tip` link's frame.
//!
//! Errors name the URDF joint (`joint[elbow].axis`, with the line of its `<joint>` element) or
//! `tip_link`; the imported joints keep the line of their `<joint>` element as their location.
//! Branches that do not lead to the tip are ignored. The result has no parameters and no constraint:
//! add one with [`RobotDescription::with_constraint`], or convert the chain to TOML with
//! [`RobotDescription::to_toml_string`] and add a `[constraint]` table there.

use super::locate::location_of;
use super::{
    ConstraintDesc, DescriptionError, EndEffector, Inertia, JointDesc, JointDynamics, JointKind,
    Linear, Location, Origin, RobotDescription, Rotation,
};
use std::path::Path;
use urdf_rs::JointType;

type Mat3 = [[f64; 3]; 3];

/// `R = Rz(yaw) Ry(pitch) Rx(roll)` (URDF convention), [`trocar::se3::rotation_from_rpy_sin_cos`].
fn rpy_matrix(rpy: [f64; 3]) -> Mat3 {
    let m = trocar::se3::rotation_from_rpy_sin_cos(
        rpy[0].sin_cos(),
        rpy[1].sin_cos(),
        rpy[2].sin_cos(),
    );
    [0, 1, 2].map(|r| [0, 1, 2].map(|c| m[(r, c)]))
}

fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = [[0.0; 3]; 3];
    for (r, row) in out.iter_mut().enumerate() {
        for (c, x) in row.iter_mut().enumerate() {
            *x = (0..3).map(|k| a[r][k] * b[k][c]).sum();
        }
    }
    out
}

fn mat_vec(a: &Mat3, v: &[f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| (0..3).map(|k| a[r][k] * v[k]).sum())
}

/// A rigid transform `(R, p)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pose {
    /// Rotation, row-major.
    pub r: Mat3,
    /// Translation.
    pub p: [f64; 3],
}

impl Pose {
    pub(crate) fn identity() -> Self {
        Pose {
            r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            p: [0.0; 3],
        }
    }

    pub(crate) fn is_identity(&self) -> bool {
        *self == Self::identity()
    }

    fn from_urdf(o: &urdf_rs::Pose) -> Self {
        Pose {
            r: rpy_matrix(o.rpy.0),
            p: o.xyz.0,
        }
    }

    pub(crate) fn then(&self, other: &Pose) -> Pose {
        let q = mat_vec(&self.r, &other.p);
        Pose {
            r: mat_mul(&self.r, &other.r),
            p: [0, 1, 2].map(|k| self.p[k] + q[k]),
        }
    }

    /// `self · o`: an origin `o` written in the frame this pose places, as an origin in the frame
    /// this pose is relative to. Lengths stay linear in the parameters
    /// (`p + R · xyz`, coefficients below 1e-15 dropped as rounding noise); the rotation becomes
    /// a matrix, unless this pose is a pure translation (then `o`'s rotation is kept as written).
    pub(crate) fn compose(&self, o: &Origin) -> Origin {
        if self.is_identity() {
            return o.clone();
        }
        let snap = |x: f64| if x.abs() < 1e-15 { 0.0 } else { x };
        let xyz = [0, 1, 2].map(|c| {
            let mut out = Linear::constant(self.p[c]);
            for (k, s) in o.xyz.iter().enumerate() {
                let a = self.r[c][k];
                out.constant += a * s.constant;
                for (coefficient, name) in &s.terms {
                    let add = snap(a * coefficient);
                    match out.terms.iter_mut().find(|(_, n)| n == name) {
                        Some((c, _)) => *c += add,
                        None => out.terms.push((add, name.clone())),
                    }
                }
            }
            out.constant = snap(out.constant);
            out.terms.retain(|(c, _)| *c != 0.0);
            out
        });
        let rotation = if self.r == Self::identity().r {
            o.rotation.clone()
        } else {
            let own = match &o.rotation {
                Rotation::Rpy(rpy) => rpy_matrix(*rpy),
                Rotation::Matrix(m) => *m,
            };
            Rotation::Matrix(mat_mul(&self.r, &own).map(|row| row.map(snap)))
        };
        Origin { xyz, rotation }
    }

    /// The inverse transform `(Rᵀ, −Rᵀ p)`.
    pub(crate) fn inverse(&self) -> Pose {
        let rt = [0, 1, 2].map(|r| [0, 1, 2].map(|c| self.r[c][r]));
        let q = mat_vec(&rt, &self.p);
        Pose {
            r: rt,
            p: q.map(|x| -x),
        }
    }

    /// An origin without parameters as a pose; `None` when a length names a parameter.
    fn of_constant(o: &Origin) -> Option<Pose> {
        if !o.xyz.iter().all(Linear::is_constant) {
            return None;
        }
        Some(Pose {
            r: match &o.rotation {
                Rotation::Rpy(rpy) => rpy_matrix(*rpy),
                Rotation::Matrix(m) => *m,
            },
            p: o.xyz.clone().map(|x| x.constant),
        })
    }

    /// As an origin with a rotation matrix; entries below 1e-15 in magnitude (the rounding noise of
    /// `cos(π/2)` in composed rpy rotations) are written as 0.
    pub(crate) fn to_origin(self) -> Origin {
        let snap = |x: f64| if x.abs() < 1e-15 { 0.0 } else { x };
        Origin {
            xyz: self.p.map(|x| Linear::constant(snap(x))),
            rotation: Rotation::Matrix(self.r.map(|row| row.map(snap))),
        }
    }
}

/// Moves the frame of joint `k` (1-based) to the frame `to` written in it, so that link frame `k`
/// becomes that frame: joint `k`'s origin becomes `origin · to` and its twist `Ad_{to⁻¹} ξ`
/// (a revolute joint whose axis does not pass through the new origin becomes a twist joint), and
/// the next joint's origin (or, for `k = n`, the end effector's) becomes `to⁻¹ · origin`. The
/// kinematics are unchanged; only the frame carried by joint `k` moves. This is how a constraint
/// naming a URDF link that fixed joints attach to joint `k`'s child (`panda_link8`, `tool0`) gets
/// that link's frame as `F_i`. Joint `k`'s origin has no parameters (it comes from a URDF);
/// `false` (nothing changed) otherwise.
pub(crate) fn move_joint_frame(
    joints: &mut [JointDesc],
    end_effector: &mut EndEffector,
    k: usize,
    to: &Pose,
) -> bool {
    let Some(joint) = k.checked_sub(1).and_then(|j| joints.get(j)) else {
        return false;
    };
    let Some(origin) = Pose::of_constant(&joint.origin) else {
        return false;
    };
    let snap = |x: f64| if x.abs() < 1e-15 { 0.0 } else { x };
    let back = to.inverse();
    // Ad_{to⁻¹} (v, ω) = (Rᵀ (v + ω × p), Rᵀ ω).
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let kind = match &joint.kind {
        JointKind::Revolute { axis } => {
            let w = mat_vec(&back.r, axis).map(snap);
            let v = mat_vec(&back.r, &cross(*axis, to.p)).map(snap);
            if v == [0.0; 3] {
                JointKind::Revolute { axis: w }
            } else {
                JointKind::Twist {
                    v: v.map(Linear::constant),
                    w,
                }
            }
        }
        JointKind::Prismatic { axis } => JointKind::Prismatic {
            axis: mat_vec(&back.r, axis).map(snap),
        },
        JointKind::Twist { v, w } => {
            if !v.iter().all(Linear::is_constant) {
                return false;
            }
            let v = [0, 1, 2].map(|c| v[c].constant + cross(*w, to.p)[c]);
            JointKind::Twist {
                v: mat_vec(&back.r, &v).map(|x| Linear::constant(snap(x))),
                w: mat_vec(&back.r, w).map(snap),
            }
        }
    };
    let joint = &mut joints[k - 1];
    joint.origin = origin.then(to).to_origin();
    joint.kind = kind;
    // The link's mass properties, from the old frame into the new one.
    if let Some(i) = &mut joint.dynamics.inertia {
        *i = i.transformed(&back.r, &back.p);
    }
    match joints.get_mut(k) {
        Some(next) => next.origin = back.compose(&next.origin),
        None => end_effector.origin = back.compose(&end_effector.origin),
    }
    true
}

/// The most names an error message lists.
const LISTED: usize = 20;

/// `names` joined with commas, the first [`LISTED`] of them and how many more.
pub(crate) fn capped_list(names: &[&str]) -> String {
    if names.len() <= LISTED {
        names.join(", ")
    } else {
        format!(
            "{}, … and {} more",
            names[..LISTED].join(", "),
            names.len() - LISTED
        )
    }
}

/// The line of `<joint name="NAME" ...>` in the URDF text.
/// The deepest element nesting a URDF may have (`<robot>`, `<joint>`, `<origin>` is 3 levels;
/// `<link>`, `<visual>`, `<geometry>`, `<mesh>` is 4).
const MAX_XML_DEPTH: usize = 64;

/// Whether `text` is well-formed XML (every element closed, in order, and the file does not end
/// inside one); otherwise where and what is wrong. The URDF reader behind
/// [`urdf_rs::read_from_string`] reports no position, and accepted a mismatched end tag.
fn check_xml(text: &str) -> Result<(), (Location, String)> {
    use quick_xml::events::Event;
    let mut reader = quick_xml::Reader::from_str(text);
    let mut open: Vec<(String, usize)> = Vec::new();
    let mut root_seen = false;
    loop {
        let before = usize::try_from(reader.buffer_position()).unwrap_or(usize::MAX);
        let event = reader.read_event();
        // The document's root element must be <robot>: the URDF reader reads any other root as
        // a robot without links or joints.
        if let (true, Ok(Event::Start(e) | Event::Empty(e))) = (open.is_empty(), &event) {
            if !root_seen {
                root_seen = true;
                let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
                if name != "robot" {
                    return Err((
                        location_of(text, before),
                        format!("the root element is <{name}>; a URDF's root element is <robot>"),
                    ));
                }
            }
        }
        match event {
            Ok(Event::Start(e)) => {
                open.push((
                    String::from_utf8_lossy(e.name().as_ref()).into_owned(),
                    before,
                ));
                // The URDF reader recurses once per level (unknown elements included): refuse
                // a nesting no URDF needs before it exhausts the stack.
                if open.len() > MAX_XML_DEPTH {
                    return Err((
                        location_of(text, before),
                        format!(
                            "elements nested more than {MAX_XML_DEPTH} levels deep (a URDF needs 4)"
                        ),
                    ));
                }
            }
            Ok(Event::End(_)) => {
                open.pop();
            }
            Ok(Event::Eof) => {
                return match open.last() {
                    None if !root_seen => Err((
                        location_of(text, text.len()),
                        "no <robot> element: a URDF's root element is <robot>".to_string(),
                    )),
                    None => Ok(()),
                    Some((name, at)) => Err((
                        location_of(text, text.len()),
                        format!(
                            "the file ends inside <{name}> (opened at line {})",
                            location_of(text, *at).line
                        ),
                    )),
                };
            }
            Ok(_) => {}
            Err(e) => {
                let at = usize::try_from(reader.error_position()).unwrap_or(usize::MAX);
                return Err((location_of(text, at), e.to_string()));
            }
        }
    }
}

/// Where an error message of the URDF reader points: its own "Line: L, Column: C" when it gives
/// one, else where the value it quotes (in `[…]`, `` `…` `` or `"…"`) first appears in `text`.
fn locate_message(text: &str, message: &str) -> Option<Location> {
    let number_after = |key: &str| -> Option<usize> {
        let rest = &message[message.find(key)? + key.len()..];
        let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
        digits.parse().ok()
    };
    if let (Some(line), Some(column)) = (number_after("Line: "), number_after("Column: ")) {
        // xml-rs prints both 1-based.
        return Some(Location { line, column });
    }
    [('[', ']'), ('`', '`'), ('"', '"')]
        .iter()
        .filter_map(|&(open, close)| {
            let start = message.find(open)? + open.len_utf8();
            let len = message[start..].find(close)?;
            let quoted = &message[start..start + len];
            (!quoted.trim().is_empty())
                .then(|| text.find(quoted))
                .flatten()
        })
        .min()
        .map(|offset| location_of(text, offset))
}

/// The location of every `<joint name="…">` tag (the first, for a repeated name), in one pass
/// over `text`: a chain's joints are located in time linear in the file's length.
fn joint_locations(text: &str) -> std::collections::HashMap<&str, Location> {
    let mut out = std::collections::HashMap::new();
    let (mut from, mut line, mut line_start) = (0, 1, 0);
    while let Some(k) = text[from..].find("<joint") {
        let start = from + k;
        for (i, _) in text[from..start].match_indices('\n') {
            line += 1;
            line_start = from + i + 1;
        }
        let end = text[start..].find('>').map_or(text.len(), |e| start + e);
        let tag = &text[start..end];
        let name = ["name=\"", "name='"].iter().find_map(|key| {
            let at = tag.find(key)? + key.len();
            let quote = key.chars().last()?;
            let len = tag[at..].find(quote)?;
            Some(&tag[at..at + len])
        });
        if let Some(name) = name {
            let column = text[line_start..start].chars().count() + 1;
            out.entry(name).or_insert(Location { line, column });
        }
        from = start + "<joint".len();
    }
    out
}

fn origin_of(o: &urdf_rs::Pose) -> Origin {
    Origin {
        xyz: o.xyz.0.map(Linear::constant),
        rotation: Rotation::Rpy(o.rpy.0),
    }
}

/// The chain of a URDF between a base and a tip link, as [`from_urdf_file`] imports it, with
/// where every link of the path sits on it (for naming a constrained link by its URDF name).
///
/// [`from_urdf_file`]: RobotDescription::from_urdf_file
pub(crate) struct UrdfChain {
    /// The URDF's robot name.
    pub name: String,
    /// The moving joints, base first.
    pub joints: Vec<JointDesc>,
    /// The tip link's frame relative to the last moving joint's frame (fixed joints folded), or
    /// to the base when there is no moving joint.
    pub tip: Pose,
    /// Every link on the path from the base to the tip: its name, the number `k` of moving
    /// joints before it (its frame is fixed in link `k`) and its pose relative to `F_k`.
    pub links: Vec<(String, usize, Pose)>,
}

impl RobotDescription {
    /// Imports the chain from the root link to `tip_link` of a URDF file (see the module
    /// documentation for the rules). No parameters, no constraint.
    pub fn from_urdf_file(
        path: impl AsRef<Path>,
        tip_link: &str,
    ) -> Result<Self, DescriptionError> {
        let path = path.as_ref();
        let text = DescriptionError::read_file(path)?;
        Self::from_urdf_text(&text, tip_link, Some(path))
    }

    /// Imports the chain from the root link to `tip_link` of URDF text.
    pub fn from_urdf_str(text: &str, tip_link: &str) -> Result<Self, DescriptionError> {
        Self::from_urdf_text(text, tip_link, None)
    }

    /// This description with `constraint` added (replacing any), validated.
    pub fn with_constraint(mut self, constraint: ConstraintDesc) -> Result<Self, DescriptionError> {
        self.constraint = Some(constraint);
        self.validate()?;
        Ok(self)
    }

    fn from_urdf_text(
        text: &str,
        tip_link: &str,
        file: Option<&Path>,
    ) -> Result<Self, DescriptionError> {
        let chain = import_chain(text, None, tip_link, file, &|f| format!("{f}_link"))?;
        let end_effector = EndEffector {
            name: tip_link.to_string(),
            origin: if chain.tip.is_identity() {
                Origin {
                    xyz: Default::default(),
                    rotation: Rotation::Rpy([0.0; 3]),
                }
            } else {
                chain.tip.to_origin()
            },
        };
        let description = RobotDescription {
            name: chain.name,
            parameters: Vec::new(),
            joints: chain.joints,
            end_effector,
            constraint: None,
            task: None,
            instrument: None,
            source: file.map(Path::to_path_buf),
        };
        description.validate()?;
        Ok(description)
    }
}

/// Imports the chain from `base` (default: the root link) to `tip` of URDF `text` (the rules are
/// the module documentation's). Errors about the base and tip links are given the field
/// `field("base")`/`field("tip")` (the TOML reader maps them to `robot.base`, `robot.tip`).
pub(crate) fn import_chain(
    text: &str,
    base: Option<&str>,
    tip_link: &str,
    file: Option<&Path>,
    field_of: &dyn Fn(&str) -> String,
) -> Result<UrdfChain, DescriptionError> {
    let err = |field: &str, line: Option<Location>, message: String| DescriptionError {
        file: file.map(Path::to_path_buf),
        line: line.map(|l| l.line),
        column: line.map(|l| l.column),
        field: field.to_string(),
        message,
    };
    check_xml(text).map_err(|(at, message)| {
        err(
            "(document)",
            Some(at),
            format!("not well-formed XML: {message}"),
        )
    })?;
    let robot = urdf_rs::read_from_string(text).map_err(|e| {
        let message = e.to_string();
        // URDF 1.2's limit checks name the joint ("joint [NAME]: lower value (nan) is ..."):
        // the error goes to that joint's `<limit>`.
        let joint_limit = message.strip_prefix("joint [").and_then(|rest| {
            let name = &rest[..rest.find("]: ")?];
            let limit = [
                "lower",
                "upper",
                "effort",
                "velocity",
                "acceleration",
                "deceleration",
                "jerk",
            ]
            .iter()
            .any(|a| {
                rest.contains(&format!("{a} value"))
                    || rest.contains(&format!("{a} position limit"))
            });
            limit.then(|| name.to_string())
        });
        if let Some(name) = joint_limit {
            let at = joint_locations(text).get(name.as_str()).copied();
            return err(
                &format!("joint[{name}].limit"),
                at,
                format!("not a valid URDF: {message}"),
            );
        }
        let at = locate_message(text, &message).or(Some(Location { line: 1, column: 1 }));
        err("(document)", at, format!("not a valid URDF: {message}"))
    })?;
    let link_names = || {
        let names: Vec<&str> = robot.links.iter().map(|l| l.name.as_str()).collect();
        if names.is_empty() {
            "none".to_string()
        } else {
            capped_list(&names)
        }
    };
    let declared = |name: &str| robot.links.iter().any(|l| l.name == name);
    let locations = joint_locations(text);
    for (what, name) in [("tip", Some(tip_link)), ("base", base)] {
        if let Some(name) = name {
            if !declared(name) {
                return Err(err(
                    &field_of(what),
                    None,
                    format!("unknown {what} link `{name}` (links: {})", link_names()),
                ));
            }
        }
    }
    for j in &robot.joints {
        for (end, name) in [("parent", &j.parent.link), ("child", &j.child.link)] {
            if !declared(name) {
                return Err(err(
                    &format!("joint[{}].{end}", j.name),
                    locations.get(j.name.as_str()).copied(),
                    format!("the {end} link `{name}` is not declared with <link name=\"{name}\">"),
                ));
            }
        }
    }
    // Walk up from the tip to the base (or the root). One map from child link to joint, so the
    // walk is linear in the chain's length.
    let mut parent_joint: std::collections::HashMap<&str, &urdf_rs::Joint> =
        std::collections::HashMap::with_capacity(robot.joints.len());
    for j in &robot.joints {
        if let Some(other) = parent_joint.insert(j.child.link.as_str(), j) {
            return Err(err(
                &format!("joint[{}]", j.name),
                locations.get(j.name.as_str()).copied(),
                format!(
                    "link `{}` is the child of two joints (`{}` and `{}`): a URDF must be a tree",
                    j.child.link, other.name, j.name
                ),
            ));
        }
    }
    // A cycle anywhere (not only on the path to the tip) makes the file no tree: follow every
    // link's parents, each link visited once.
    {
        let mut state: std::collections::HashMap<&str, bool> = std::collections::HashMap::new();
        for start in robot.links.iter().map(|l| l.name.as_str()) {
            let mut path = Vec::new();
            let mut current = start;
            while !state.contains_key(current) {
                state.insert(current, false);
                path.push(current);
                let Some(j) = parent_joint.get(current) else {
                    break;
                };
                current = j.parent.link.as_str();
                if state.get(current) == Some(&false) {
                    return Err(err(
                        &format!("joint[{}]", j.name),
                        locations.get(j.name.as_str()).copied(),
                        format!(
                            "the joints form a cycle through link `{current}` (joint `{}` makes `{}` a child of its own descendant): a URDF must be a tree",
                            j.name, j.parent.link
                        ),
                    ));
                }
            }
            for link in path {
                state.insert(link, true);
            }
        }
    }
    let mut chain = Vec::new();
    let mut current = tip_link;
    while base != Some(current) {
        let Some(j) = parent_joint.get(current) else {
            if let Some(base) = base {
                return Err(err(
                    &field_of("tip"),
                    None,
                    format!("the tip link `{tip_link}` is not below the base link `{base}`: the path from the tip up to the root (`{current}`) does not pass through the base"),
                ));
            }
            break;
        };
        if chain.len() > robot.joints.len() {
            return Err(err(
                &format!("joint[{}]", j.name),
                locations.get(j.name.as_str()).copied(),
                "the joints form a cycle: a URDF must be a tree".into(),
            ));
        }
        chain.push(*j);
        current = j.parent.link.as_str();
    }
    chain.reverse();
    let mut joints = Vec::new();
    let mut pending = Pose::identity();
    let mut links = vec![(current.to_string(), 0, Pose::identity())];
    for j in chain {
        let field = format!("joint[{}]", j.name);
        let line = locations.get(j.name.as_str()).copied();
        let finite = j
            .origin
            .xyz
            .iter()
            .chain(j.origin.rpy.iter())
            .all(|x| x.is_finite());
        if !finite {
            return Err(err(
                &format!("{field}.origin"),
                line,
                "origin numbers must be finite".into(),
            ));
        }
        if j.mimic.is_some() && j.joint_type != JointType::Fixed {
            return Err(err(
                &format!("{field}.mimic"),
                line,
                format!("joint `{}` mimics another joint; mimic joints are not supported (their value would become an independent entry of q): remove <mimic> or make the joint fixed", j.name),
            ));
        }
        let moving = match j.joint_type {
            JointType::Fixed => None,
            JointType::Revolute | JointType::Continuous => Some(true),
            JointType::Prismatic => Some(false),
            JointType::Floating | JointType::Planar | JointType::Spherical => {
                return Err(err(
                    &format!("{field}.type"),
                    line,
                    format!(
                        "joint type `{:?}` is not supported on the path to `{tip_link}` (only revolute, continuous, prismatic and fixed)",
                        j.joint_type
                    )
                    .to_lowercase(),
                ))
            }
        };
        let here = Pose::from_urdf(&j.origin);
        let Some(revolute) = moving else {
            pending = pending.then(&here);
            links.push((j.child.link.clone(), joints.len(), pending));
            continue;
        };
        let a = j.axis.xyz.0;
        let n = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        if !n.is_finite() || n == 0.0 {
            return Err(err(
                &format!("{field}.axis"),
                line,
                format!(
                    "the axis [{}, {}, {}] cannot be normalised",
                    a[0], a[1], a[2]
                ),
            ));
        }
        let axis = a.map(|x| x / n);
        let origin = if pending.is_identity() {
            origin_of(&j.origin)
        } else {
            pending.then(&here).to_origin()
        };
        pending = Pose::identity();
        let (mut lower, mut upper) = (j.limit.lower, j.limit.upper);
        // URDF 1.2 reads an omitted bound as infinite: no limit.
        if lower == f64::NEG_INFINITY && upper == f64::INFINITY {
            (lower, upper) = (0.0, 0.0);
        }
        if j.joint_type != JointType::Continuous {
            // A bad limit is an error: dropping it silently dropped the robot's joint limits.
            for (side, v) in [("lower", lower), ("upper", upper)] {
                if let Err(problem) = crate::validity::check(v) {
                    return Err(err(
                        &format!("{field}.limit.{side}"),
                        line,
                        format!("the limit {v:e} {problem}"),
                    ));
                }
            }
            if lower > upper {
                return Err(err(
                    &format!("{field}.limit"),
                    line,
                    format!("lower {lower} is above upper {upper}"),
                ));
            }
        }
        let limits = match j.joint_type {
            JointType::Continuous => None,
            // Equal bounds (also a joint without `<limit>`, read as 0 and 0): no limits.
            _ if lower < upper => Some([lower, upper]),
            _ => None,
        };
        // URDF 1.2 `acceleration`/`jerk` (absent: infinite) and the dynamics: a bad number is
        // an error, as for the position limits.
        let positive = |name: &str, v: f64| -> Result<Option<f64>, DescriptionError> {
            if v.is_nan() || v < 0.0 {
                return Err(err(
                    &format!("{field}.{name}"),
                    line,
                    format!("{name} {v} must be a non-negative number"),
                ));
            }
            Ok((v > 0.0 && v.is_finite()).then_some(v))
        };
        let acceleration_limit = positive("limit.acceleration", j.limit.acceleration)?;
        let jerk_limit = positive("limit.jerk", j.limit.jerk)?;
        let effort_limit = positive("limit.effort", j.limit.effort)?;
        let (damping, friction) = match &j.dynamics {
            Some(d) => (
                positive("dynamics.damping", d.damping)?.or(Some(0.0)),
                positive("dynamics.friction", d.friction)?.or(Some(0.0)),
            ),
            None => (None, None),
        };
        joints.push(JointDesc {
            name: j.name.clone(),
            origin,
            kind: if revolute {
                JointKind::Revolute { axis }
            } else {
                JointKind::Prismatic { axis }
            },
            limits,
            speed_limit: (j.limit.velocity > 0.0 && j.limit.velocity.is_finite())
                .then_some(j.limit.velocity),
            acceleration_limit,
            jerk_limit,
            dynamics: JointDynamics {
                effort_limit,
                damping,
                friction,
                inertia: None,
            },
            location: line,
        });
        links.push((j.child.link.clone(), joints.len(), Pose::identity()));
    }
    if joints.is_empty() {
        let path: Vec<&str> = links.iter().map(|(n, _, _)| n.as_str()).collect();
        return Err(err(
            &field_of("tip"),
            None,
            format!(
                "no revolute, continuous or prismatic joint moves the tip link `{tip_link}`: the path from the base to it ({}) has fixed joints only; choose a tip below a moving joint",
                capped_list(&path)
            ),
        ));
    }
    // The mass properties of every link on the path, folded onto the joint that moves it.
    for (name, k, pose) in &links {
        let Some(link) = robot.links.iter().find(|l| &l.name == name) else {
            continue;
        };
        let Some(joint) = k.checked_sub(1).and_then(|k| joints.get_mut(k)) else {
            continue;
        };
        let inertial = &link.inertial;
        let i = &inertial.inertia;
        let values = [
            inertial.mass.value,
            i.ixx,
            i.iyy,
            i.izz,
            i.ixy,
            i.ixz,
            i.iyz,
        ];
        if values
            .iter()
            .chain(inertial.origin.xyz.0.iter())
            .chain(inertial.origin.rpy.0.iter())
            .any(|v| !v.is_finite())
            || inertial.mass.value < 0.0
        {
            let at = text
                .find(&format!("name=\"{name}\""))
                .map(|offset| location_of(text, offset));
            return Err(err(
                &format!("link[{name}].inertial"),
                at,
                "mass, origin and inertia must be finite numbers, the mass non-negative".into(),
            ));
        }
        if inertial.mass.value == 0.0 {
            continue;
        }
        let own = Inertia {
            mass: inertial.mass.value,
            com: [0.0; 3],
            inertia: [i.ixx, i.iyy, i.izz, i.ixy, i.ixz, i.iyz],
        };
        let at = pose.then(&Pose::from_urdf(&inertial.origin));
        let here = own.transformed(&at.r, &at.p);
        joint.dynamics.inertia = Some(match joint.dynamics.inertia {
            Some(before) => before.combined(&here),
            None => here,
        });
    }
    Ok(UrdfChain {
        name: robot.name.clone(),
        joints,
        tip: pending,
        links,
    })
}
