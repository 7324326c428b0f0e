//! `trocar list`: what ships with trocar (robots, mechanisms, simulation scenarios), and a short
//! account of one description.

use crate::output::{write_stdout, CliError};
use trocar_model::Description;

/// The names of everything shipped, as the other commands accept them.
#[derive(Clone, Debug, PartialEq)]
pub struct Shipped {
    /// Serial robot descriptions (`generate`, `eval`, `verify`, `preset`).
    pub robots: Vec<&'static str>,
    /// Closed mechanisms (`generate`, `eval`).
    pub mechanisms: Vec<&'static str>,
    /// Simulation scenarios (`simulate`): the RCM scenarios, then the closed-chain ones.
    pub scenarios: Vec<&'static str>,
}

/// Everything shipped with trocar.
pub fn shipped() -> Shipped {
    let mut scenarios: Vec<&'static str> = trocar_sim::simulation::Scenario::ALL
        .iter()
        .map(|s| s.name())
        .collect();
    scenarios.extend_from_slice(trocar_sim::closed_chain::scenario_names());
    Shipped {
        robots: trocar_model::description::preset_names().collect(),
        mechanisms: trocar_model::closed_chain::SHIPPED.to_vec(),
        scenarios,
    }
}

/// A loaded description, in brief.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotInfo {
    /// `[robot] name` (or the mechanism's name).
    pub name: String,
    /// Whether it is a closed mechanism.
    pub mechanism: bool,
    /// Number of joint values `eval` takes.
    pub joints: usize,
    /// Parameters with their nominal values, in declaration order.
    pub params: Vec<(String, f64)>,
}

/// Loads `robot` (file or shipped name) as every command does and describes it.
pub fn robot_info(robot: &str) -> Result<RobotInfo, CliError> {
    Ok(match Description::load(robot)? {
        Description::Serial(d) => RobotInfo {
            name: d.name.clone(),
            mechanism: false,
            joints: d.joints.len(),
            params: d
                .parameters
                .iter()
                .map(|p| (p.name.clone(), p.value))
                .collect(),
        },
        Description::Mechanism(m) => RobotInfo {
            name: m.name.clone(),
            mechanism: true,
            joints: m.joint_names().len(),
            params: m
                .parameters
                .iter()
                .map(|p| (p.name.clone(), p.nominal))
                .collect(),
        },
    })
}

/// Runs `trocar list`.
pub(crate) fn run() -> Result<i32, CliError> {
    let s = shipped();
    let mut out = String::new();
    out += "robots (generate, eval, verify, preset):\n";
    for r in &s.robots {
        out += &format!("  {r}\n");
    }
    out += "mechanisms (generate, eval):\n";
    for m in &s.mechanisms {
        out += &format!("  {m}\n");
    }
    out += "scenarios (simulate):\n";
    for sc in &s.scenarios {
        out += &format!("  {sc}\n");
    }
    out += "A description file (TOML, its chain possibly from a URDF) is accepted wherever a robot or mechanism name is.\n";
    write_stdout(&out)?;
    Ok(0)
}
