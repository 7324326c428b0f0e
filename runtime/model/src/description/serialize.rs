//! Writing descriptions back to TOML, in the format [`RobotDescription::from_toml_str`] reads.
//!
//! Numbers are written with Rust's shortest round-trip formatting, so reading the text back gives
//! the same description bit for bit (apart from `source` and joint locations).

use super::parse::AXIS_LETTERS;
use super::{JointKind, Linear, Origin, RobotDescription, Rotation, Wrist};
use std::fmt::Write;

/// A TOML float or integer literal that reads back as exactly `v`.
fn number(v: f64) -> String {
    if v.is_nan() {
        "nan".into()
    } else if v.is_infinite() {
        if v > 0.0 { "inf" } else { "-inf" }.into()
    } else if v.fract() == 0.0 && v.abs() < 1e15 && !(v == 0.0 && v.is_sign_negative()) {
        // Whole numbers as TOML integers (`0`, `1`, `-2`): they read back as the same f64.
        format!("{}", v as i64)
    } else {
        // `{:?}` is the shortest representation that round-trips.
        format!("{v:?}")
    }
}

/// A TOML basic string.
fn string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if c.is_control() => {
                let _ = write!(out, "\\u{:04X}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// A key: bare when it can be, quoted otherwise.
fn key(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        s.to_string()
    } else {
        string(s)
    }
}

impl Linear {
    /// The expression [`Linear::parse`] reads back: `"l_a + l_b"`, `"-0.5*l_8 + 0.1"`.
    pub fn to_expression(&self) -> String {
        let mut out = String::new();
        for (c, name) in &self.terms {
            let (negative, magnitude) = (c.is_sign_negative(), c.abs());
            match (out.is_empty(), negative) {
                (true, false) => {}
                (true, true) => out.push('-'),
                (false, false) => out.push_str(" + "),
                (false, true) => out.push_str(" - "),
            }
            if magnitude != 1.0 {
                let _ = write!(out, "{}*", number(magnitude));
            }
            out.push_str(name);
        }
        if self.constant != 0.0 || out.is_empty() {
            let (negative, magnitude) = (self.constant.is_sign_negative(), self.constant.abs());
            match (out.is_empty(), negative) {
                (true, false) => {}
                (true, true) => out.push('-'),
                (false, false) => out.push_str(" + "),
                (false, true) => out.push_str(" - "),
            }
            out.push_str(&number(magnitude));
        }
        out
    }
}

fn scalar(s: &Linear) -> String {
    if s.is_constant() {
        number(s.constant)
    } else {
        string(&s.to_expression())
    }
}

fn array3(v: &[f64; 3]) -> String {
    format!("[{}, {}, {}]", number(v[0]), number(v[1]), number(v[2]))
}

fn origin(out: &mut String, o: &Origin) {
    let _ = writeln!(
        out,
        "xyz = [{}, {}, {}]",
        scalar(&o.xyz[0]),
        scalar(&o.xyz[1]),
        scalar(&o.xyz[2])
    );
    match &o.rotation {
        Rotation::Rpy(rpy) => {
            if rpy.iter().any(|a| *a != 0.0 || a.is_sign_negative()) {
                let _ = writeln!(out, "rpy = {}", array3(rpy));
            }
        }
        Rotation::Matrix(m) => {
            let _ = writeln!(
                out,
                "rotation = [{}, {}, {}]",
                array3(&m[0]),
                array3(&m[1]),
                array3(&m[2])
            );
        }
    }
}

impl RobotDescription {
    /// The description as TOML text that [`RobotDescription::from_toml_str`] reads back to an equal
    /// description (up to `source` and joint locations). Used by `trocar preset NAME` and for
    /// URDF → TOML conversion.
    pub fn to_toml_string(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "[robot]\nname = {}\n", string(&self.name));
        if !self.parameters.is_empty() {
            out.push_str("[parameters]\n");
            for p in &self.parameters {
                let _ = writeln!(out, "{} = {}", key(&p.name), number(p.value));
            }
            out.push('\n');
        }
        for j in &self.joints {
            let _ = writeln!(out, "[[joints]]\nname = {}", string(&j.name));
            let kind = match j.kind {
                JointKind::Revolute { .. } => "revolute",
                JointKind::Prismatic { .. } => "prismatic",
                JointKind::Twist { .. } => "twist",
            };
            let _ = writeln!(out, "type = \"{kind}\"");
            origin(&mut out, &j.origin);
            if let Some([lo, hi]) = j.limits {
                let _ = writeln!(out, "limits = [{}, {}]", number(lo), number(hi));
            }
            for (name, value) in [
                ("speed_limit", j.speed_limit),
                ("acceleration_limit", j.acceleration_limit),
                ("jerk_limit", j.jerk_limit),
                ("effort_limit", j.dynamics.effort_limit),
                ("damping", j.dynamics.damping),
                ("friction", j.dynamics.friction),
            ] {
                if let Some(v) = value {
                    let _ = writeln!(out, "{name} = {}", number(v));
                }
            }
            if let Some(i) = &j.dynamics.inertia {
                let _ = writeln!(out, "mass = {}\ncom = {}", number(i.mass), array3(&i.com));
                let _ = writeln!(out, "inertia = [{}]", i.inertia.map(number).join(", "));
            }
            match &j.kind {
                JointKind::Revolute { axis } | JointKind::Prismatic { axis } => {
                    let _ = writeln!(out, "axis = {}", array3(axis));
                }
                JointKind::Twist { v, w } => {
                    let _ = writeln!(
                        out,
                        "v = [{}, {}, {}]\nw = {}",
                        scalar(&v[0]),
                        scalar(&v[1]),
                        scalar(&v[2]),
                        array3(w)
                    );
                }
            }
            out.push('\n');
        }
        let _ = writeln!(
            out,
            "[end_effector]\nname = {}",
            string(&self.end_effector.name)
        );
        origin(&mut out, &self.end_effector.origin);
        if let Some(i) = &self.instrument {
            let _ = writeln!(
                out,
                "\n[instrument]\nmass = {}\nradius = {}",
                number(i.mass),
                number(i.radius)
            );
        }
        if let Some(c) = &self.constraint {
            let _ = writeln!(out, "\n[constraint]\nlink = {}", c.link);
            origin(&mut out, &c.origin);
            let _ = writeln!(out, "h = {}", selection(&c.h));
            if let Some(w) = c.wrist {
                let name = match w {
                    Wrist::Unidirectional => "unidirectional",
                    Wrist::Zy => "zy",
                    Wrist::Zx => "zx",
                };
                let _ = writeln!(out, "wrist = \"{name}\"");
            }
        }
        if let Some(t) = &self.task {
            let _ = writeln!(out, "\n[task]\nselect = {}", selection(&t.select));
        }
        out
    }
}

/// Rows of a selection (`H`, `S`): axis letters when every row is one, else rows of 6 numbers.
fn selection(rows: &[[f64; 6]]) -> String {
    let letters: Option<Vec<String>> = rows
        .iter()
        .map(|row| {
            let ones: Vec<usize> = (0..6).filter(|&k| row[k] != 0.0).collect();
            match ones.as_slice() {
                [k] if row[*k] == 1.0 && !row.iter().any(|x| x.is_sign_negative()) => {
                    Some(string(AXIS_LETTERS[*k]))
                }
                _ => None,
            }
        })
        .collect();
    match letters {
        Some(l) if !l.is_empty() => format!("[{}]", l.join(", ")),
        _ => {
            let rows: Vec<String> = rows
                .iter()
                .map(|row| {
                    let entries: Vec<String> = row.iter().map(|x| number(*x)).collect();
                    format!("[{}]", entries.join(", "))
                })
                .collect();
            format!("[{}]", rows.join(", "))
        }
    }
}
