//! `trocar jacobian`: the body or spatial Jacobian of a URDF chain.

use crate::args::Frame;
use crate::output::{print_matrix, CliError};
use std::path::Path;

/// Runs `trocar jacobian`: prints the matrix as JSON or aligned text.
pub(crate) fn run(
    urdf: &Path,
    tip: &str,
    q: &[f64],
    frame: Frame,
    json: bool,
) -> Result<i32, CliError> {
    let m = trocar_api::urdf_jacobian(urdf, tip, q, frame == Frame::Spatial)?;
    // Rows: the twist components; columns: the joints of the chain in order, from the base.
    let rows = trocar_api::TWIST.map(String::from).to_vec();
    let cols = (1..=m.cols).map(|k| format!("dq[{k}]")).collect();
    print_matrix(&m, json, Some((rows, cols)))?;
    Ok(0)
}
