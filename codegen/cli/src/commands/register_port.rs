//! `trocar register-port`: the port from measured joint positions of the instrument pivoting
//! about it ([`trocar_api::register_port`]).

use crate::output::{write_stdout, CliError};
use std::path::Path;
use trocar_api::{register_port, JointRows, Robot};

/// Runs `trocar register-port`: prints the port (base frame, m), its standard deviations, the
/// lines' residual and spread, as text or JSON.
pub(crate) fn run(
    robot: &str,
    joints: &Path,
    least_spread_deg: f64,
    forgetting: Option<f64>,
    json: bool,
) -> Result<i32, CliError> {
    let robot = Robot::load(robot)?;
    let rows = JointRows::from_csv(joints, robot.dof())?;
    let e = register_port(&robot, &rows, least_spread_deg.to_radians(), forgetting)?;
    let deviation: Vec<f64> = (0..3)
        .map(|k| e.covariance[(k, k)].max(0.0).sqrt())
        .collect();
    if json {
        let rows: Vec<String> = (0..3)
            .map(|r| {
                format!(
                    "[{:e}, {:e}, {:e}]",
                    e.covariance[(r, 0)],
                    e.covariance[(r, 1)],
                    e.covariance[(r, 2)]
                )
            })
            .collect();
        write_stdout(&format!(
            "{{\"port\": [{}, {}, {}], \"covariance\": [{}], \"deviation\": [{:e}, {:e}, {:e}], \
             \"largest_deviation\": {:e}, \"residual\": {:e}, \"spread_deg\": {}, \"lines\": {}}}\n",
            e.point.x,
            e.point.y,
            e.point.z,
            rows.join(", "),
            deviation[0],
            deviation[1],
            deviation[2],
            e.largest_deviation(),
            e.residual,
            e.spread.to_degrees(),
            e.lines
        ))?;
    } else {
        write_stdout(&format!(
            "port (m, base frame): {:.6} {:.6} {:.6}\n\
             deviation (mm): x {:.3}, y {:.3}, z {:.3}; {:.3} along the least certain direction\n\
             residual: the shaft's lines pass {:.3} mm from it (root mean square)\n\
             spread: {:.2}° over {} poses\n",
            e.point.x,
            e.point.y,
            e.point.z,
            deviation[0] * 1e3,
            deviation[1] * 1e3,
            deviation[2] * 1e3,
            e.largest_deviation() * 1e3,
            e.residual * 1e3,
            e.spread.to_degrees(),
            e.lines
        ))?;
    }
    Ok(0)
}
