//! A shipped scene of several arms stepped by the caller's own loop (a physics plant, a robot):
//! [`SceneStepper`] holds the arms' controllers and the scene's couplings, and [`SceneStepper::step`]
//! gives every arm's rates at the scene's joints and a time.

use crate::error::{Error, Result};
use trocar::control::StepStatus;
use trocar::nalgebra::SVector;
use trocar_sim::scene::{ThreePorts, ARMS, DT, SAFETY};

/// The scenes a loop of one's own can step.
pub const STEPPABLE: [&str; 1] = ["three-ports"];

/// `three-ports` (three Pandas, each through its own port; two instruments whose shafts are
/// kept [`SAFETY`] apart, an endoscope whose view axis follows the instruments' midpoint) ready
/// to be stepped: the scene's step over all arms (`trocar::control::scene`) with each arm's own
/// QP step, warm-started from the last call.
#[derive(Clone, Debug)]
pub struct SceneStepper {
    name: &'static str,
    inner: ThreePorts,
    fresh: ThreePorts,
}

/// What one scene step commanded.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneStep {
    /// The rates of every joint of the scene, in its order (the arms in [`SceneStepper::arms`]'
    /// order, each arm's joints in its chain's order), rad/s.
    pub qd: Vec<f64>,
    /// Each coupling's distance between two shafts at the step (m), in the order of
    /// [`SceneStepper::couplings`].
    pub distances: Vec<f64>,
    /// `false` where some coupling could not hold within the ports and the joint limits.
    pub coupling_held: bool,
    /// Whether a coupling changed the arms' rates.
    pub coupling_active: bool,
    /// Each arm's own step's status (its port and its limits).
    pub statuses: Vec<StepStatus>,
}

impl SceneStepper {
    /// The shipped scene `name` at its start, with its couplings (`coupled`) or without them.
    pub fn new(name: &str, coupled: bool) -> Result<Self> {
        let Some(name) = STEPPABLE.iter().copied().find(|n| *n == name) else {
            return Err(Error::Argument {
                argument: "name",
                problem: format!(
                    "`{name}` is not a scene that can be stepped (expected one of: {}; the \
                     other scenes run with `simulate`)",
                    STEPPABLE.join(", ")
                ),
            });
        };
        let inner = ThreePorts::new(coupled).map_err(|e| Error::Simulation(e.to_string()))?;
        Ok(SceneStepper {
            name,
            fresh: inner.clone(),
            inner,
        })
    }

    /// The scene's name.
    pub fn name(&self) -> &str {
        self.name
    }

    /// The arms' names, in the scene's order.
    pub fn arms(&self) -> Vec<String> {
        ARMS.iter().map(|s| s.to_string()).collect()
    }

    /// The couplings, as pairs of arms' names.
    pub fn couplings(&self) -> Vec<(String, String)> {
        self.inner
            .scene
            .couplings
            .iter()
            .map(|c| (ARMS[c.arms.0].to_string(), ARMS[c.arms.1].to_string()))
            .collect()
    }

    /// The number of the scene's joints.
    pub fn joints(&self) -> usize {
        7 * ARMS.len()
    }

    /// The scene's sample time (s): the rates' limits (acceleration, jerk, the ranges over a
    /// step) are for this `dt`.
    pub fn dt(&self) -> f64 {
        DT
    }

    /// The shafts' safety distance (m).
    pub fn safety(&self) -> f64 {
        SAFETY
    }

    /// The scene's joints at its start.
    pub fn q0(&self) -> Vec<f64> {
        self.fresh
            .q0
            .iter()
            .flat_map(|q| q.iter().copied())
            .collect()
    }

    /// Every arm's port in the scene's frame (m).
    pub fn ports(&self) -> Vec<[f64; 3]> {
        (0..ARMS.len())
            .map(|k| {
                let p = self.inner.bases[k].transform_point(&self.inner.rcms[k].trocar);
                [p.x, p.y, p.z]
            })
            .collect()
    }

    /// Back to the start: the controllers at rest, the warm starts and the camera's last point
    /// forgotten.
    pub fn reset(&mut self) {
        self.inner = self.fresh.clone();
    }

    /// One step at the scene's joints `q` (all arms, in order) and time `t` (s, the arms' paths
    /// are functions of it; call once per sample, `t` increasing by [`Self::dt`]).
    pub fn step(&mut self, q: &[f64], t: f64) -> Result<SceneStep> {
        if q.len() != self.joints() {
            return Err(Error::Argument {
                argument: "q",
                problem: format!(
                    "{} values given; the scene has {} joints",
                    q.len(),
                    self.joints()
                ),
            });
        }
        if let Some(k) = q.iter().position(|v| !v.is_finite()) {
            return Err(Error::Argument {
                argument: "q",
                problem: format!("q[{k}] is {}", q[k]),
            });
        }
        if !t.is_finite() {
            return Err(Error::Argument {
                argument: "t",
                problem: format!("{t} is not a time"),
            });
        }
        let q: [SVector<f64, 7>; 3] =
            std::array::from_fn(|k| SVector::from_column_slice(&q[7 * k..7 * k + 7]));
        let out = self
            .inner
            .step(&q, t)
            .map_err(|e| Error::Simulation(format!("t = {t} s: {e}")))?;
        let qd: Vec<f64> = out.qd.iter().flat_map(|x| x.iter().copied()).collect();
        if qd.iter().any(|v| !v.is_finite()) {
            return Err(Error::NotFinite(format!("t = {t} s: the scene's rates")));
        }
        Ok(SceneStep {
            qd,
            distances: out.distances.to_vec(),
            coupling_held: out.coupling_held,
            coupling_active: out.coupling_active,
            statuses: out.arms.iter().map(|a| a.status).collect(),
        })
    }
}
