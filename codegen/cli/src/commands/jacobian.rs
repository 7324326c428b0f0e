//! `trocar jacobian`: the body or spatial Jacobian of a URDF chain.

use crate::args::Frame;
use crate::output::{CliError, MatrixOut};
use crate::robot::{check_q, numeric_robot, robot_error};
use std::path::Path;
use trocar_model::description::RobotDescription;

/// The body ((2.55)) or spatial ((2.53)) Jacobian of the chain of `urdf` from its root to
/// `tip`, at all joint values `q` (root first).
pub fn jacobian(urdf: &Path, tip: &str, q: &[f64], frame: Frame) -> Result<MatrixOut, CliError> {
    let desc = RobotDescription::from_urdf_file(urdf, tip)?;
    let nominal: Vec<f64> = desc.parameters.iter().map(|p| p.value).collect();
    let robot = numeric_robot(&desc, &nominal)?;
    check_q(&desc, q)?;
    let j = match frame {
        Frame::Body => robot.body_jacobian(q),
        Frame::Spatial => robot.spatial_jacobian(q),
    }
    .map_err(robot_error(&desc))?;
    Ok(MatrixOut::from_faer(&j))
}

/// Runs `trocar jacobian`: prints the matrix as JSON or aligned text.
pub(crate) fn run(
    urdf: &Path,
    tip: &str,
    q: &[f64],
    frame: Frame,
    json: bool,
) -> Result<i32, CliError> {
    let m = jacobian(urdf, tip, q, frame)?;
    // Rows: the twist components; columns: the joints of the chain in order, from the base.
    let rows = crate::commands::eval::TWIST.map(String::from).to_vec();
    let cols = (1..=m.cols).map(|k| format!("dq[{k}]")).collect();
    m.print(json, Some((rows, cols)))?;
    Ok(0)
}
