//! The port located from measured joint positions: each row's shaft line (the constrained
//! link's shaft at those joints, from the numeric model) into [`trocar::port::PortRegistration`],
//! then the point nearest to all of them with its covariance, residual and spread.

use crate::error::{Error, Result};
use crate::robot::Robot;
use crate::trajectory::{csv_lines, read_text};
use std::path::Path;
use trocar::port::{Line, PortEstimate, PortRegistration};

/// The largest joints file read (bytes).
pub const MAX_JOINTS_BYTES: u64 = 64 << 20;

/// Joint positions read from a CSV file: one row per pose, the columns `q1..qn` (any others,
/// such as a `trocar simulate` CSV's, are skipped).
#[derive(Clone, Debug, PartialEq)]
pub struct JointRows {
    /// The joint values of each row, base first.
    pub rows: Vec<Vec<f64>>,
    /// The line of the file each row came from (1-based), for messages.
    pub lines: Vec<usize>,
}

impl JointRows {
    /// Reads `path` for a robot of `n` joints. Errors name the file, line and column: no
    /// header, a missing `qk` column, a value that is not a finite number, no rows.
    pub fn from_csv(path: &Path, n: usize) -> Result<Self> {
        let text = read_text(path, "the joint positions", MAX_JOINTS_BYTES)?;
        Self::parse(&text, &path.display().to_string(), n)
    }

    /// Parses CSV text (`name` for messages) for a robot of `n` joints.
    pub fn parse(text: &str, name: &str, n: usize) -> Result<Self> {
        let mut lines = csv_lines(text);
        let Some((header_line, header)) = lines.next() else {
            return Err(Error::Input(format!(
                "{name}: no header: the file names its columns q1..q{n} on its first line"
            )));
        };
        let columns: Vec<&str> = header.split(',').map(str::trim).collect();
        let index = (1..=n)
            .map(|k| {
                let c = format!("q{k}");
                columns.iter().position(|x| *x == c).ok_or_else(|| {
                    Error::Input(format!(
                        "{name}:{header_line}: no column `{c}` (the robot has {n} joints, q1..q{n}; the header has: {})",
                        columns.join(", ")
                    ))
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let mut out = JointRows {
            rows: Vec::new(),
            lines: Vec::new(),
        };
        for (i, line) in lines {
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            let row = index
                .iter()
                .enumerate()
                .map(|(k, &c)| {
                    let field = fields.get(c).copied().unwrap_or("");
                    field
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| {
                            Error::Input(format!(
                                "{name}:{i}: column q{} (field {}): `{field}` is not a finite number",
                                k + 1,
                                c + 1
                            ))
                        })
                })
                .collect::<Result<Vec<_>>>()?;
            out.rows.push(row);
            out.lines.push(i);
        }
        if out.rows.is_empty() {
            return Err(Error::Input(format!(
                "{name}: no rows of joint positions after the header (line {header_line})"
            )));
        }
        Ok(out)
    }
}

/// The shaft's line at joints `q` in the robot's base frame: the constrained link's frame from
/// the numeric model and the shaft of its constraint (`trocar::control::Shaft::line`).
pub fn shaft_line(robot: &Robot, q: &[f64]) -> Result<Line<f64>> {
    ShaftLines::of(robot)?.at(q)
}

/// The shaft of a robot's constraint, read once, for the lines of many poses.
struct ShaftLines<'r> {
    robot: &'r Robot,
    link: usize,
    shaft: trocar::control::Shaft<f64>,
}

impl<'r> ShaftLines<'r> {
    fn of(robot: &'r Robot) -> Result<Self> {
        let numeric = robot.numeric()?;
        let (Some(link), Ok(shaft)) = (numeric.constrained_link(), numeric.model().shaft()) else {
            return Err(Error::Unsupported(format!(
                "`{}` has no constraint with a shaft (a constrained link and a parameter `l_a`): there is no shaft line to locate a port from",
                robot.name()
            )));
        };
        Ok(ShaftLines { robot, link, shaft })
    }

    fn at(&self, q: &[f64]) -> Result<Line<f64>> {
        self.robot.check_q(q)?;
        let g_0i = self
            .robot
            .numeric()?
            .link_frame(self.link, q)
            .map_err(|e| Error::Input(e.to_string()))?;
        self.shaft.line(&g_0i).ok_or_else(|| {
            Error::Input(format!(
                "the shaft of `{}` has no direction at these joints",
                self.robot.name()
            ))
        })
    }
}

pub use trocar::port::LARGEST_SPREAD;

/// The port located from joint positions, one pose per row (`trocar register-port`): every
/// row's shaft line taken, then the point nearest to them (least squares), refused where the
/// lines spread by less than `least_spread` (rad, at most [`LARGEST_SPREAD`]) or are fewer than
/// two. `forgetting` (in `(0.5, 1]`, `None` for 1) weighs each row `1/λ` times the one before,
/// for a port that moved.
pub fn register_port(
    robot: &Robot,
    rows: &JointRows,
    least_spread: f64,
    forgetting: Option<f64>,
) -> Result<PortEstimate<f64>> {
    let mut registration = match forgetting {
        Some(lambda) => PortRegistration::with_forgetting(lambda).map_err(|_| {
            Error::Input(format!(
                "the forgetting factor {lambda}: in (0.5, 1] (1 weighs every pose the same)"
            ))
        })?,
        None => PortRegistration::new(),
    };
    if !trocar::port::least_spread_admitted(least_spread) {
        return Err(Error::Input(format!(
            "the least spread {}°: an angle from 0° to {:.1}° (no lines spread more)",
            least_spread.to_degrees(),
            LARGEST_SPREAD.to_degrees()
        )));
    }
    let lines = ShaftLines::of(robot)?;
    for (q, line) in rows.rows.iter().zip(&rows.lines) {
        let shaft = lines.at(q).map_err(|e| match e {
            Error::Input(m) => Error::Input(format!("line {line}: {m}")),
            other => other,
        })?;
        registration
            .add(&shaft)
            .map_err(|e| Error::Input(format!("line {line}: {e}")))?;
    }
    registration
        .estimate(least_spread)
        .map_err(|e| Error::Input(e.to_string()))
}
