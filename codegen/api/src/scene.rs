//! A shipped scene of several arms stepped by the caller's own loop (a physics plant, a robot):
//! [`SceneStepper`] holds the arms' controllers and the scene's couplings, and [`SceneStepper::step`]
//! gives every arm's rates at the scene's joints and a time.

use crate::error::{Error, Result};
use trocar::control::StepStatus;
use trocar::nalgebra::SVector;
use trocar_sim::scene::dual::{self, torso_once, Dia10Dual};
use trocar_sim::scene::{ThreePorts, ARMS, DT};

/// The scenes a loop of one's own can step.
pub const STEPPABLE: [&str; 2] = ["three-ports", "dia10-dual"];

/// A shipped scene ready to be stepped: the scene's step over all arms
/// (`trocar::control::scene`) with each arm's own QP step, warm-started from the last call.
/// `three-ports`: three Pandas, each through its own port, two instruments and an endoscope whose
/// shafts are kept their scene file's safety distance apart, the endoscope's view axis on the instruments' midpoint.
/// `dia10-dual`: the reference arm and its mirror image on one torso (15 joints: the torso, the
/// left arm's 7, the right arm's 7), the left tip held while the right one cuts.
#[derive(Clone, Debug)]
pub struct SceneStepper {
    name: &'static str,
    safety: f64,
    inner: Setup,
    fresh: Setup,
}

/// The scenes' own setups.
#[derive(Clone, Debug)]
enum Setup {
    ThreePorts(Box<ThreePorts>),
    Dia10Dual(Box<Dia10Dual>),
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
    /// The shipped scene `name` ([`STEPPABLE`]) at its start, with its couplings (`coupled`) or
    /// without them (`three-ports` only; `dia10-dual` keeps its coupling).
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
        let simulation = |e: trocar_sim::scene::SceneRunError| Error::Simulation(e.to_string());
        let inner = match name {
            "dia10-dual" => Setup::Dia10Dual(Box::new(Dia10Dual::new().map_err(simulation)?)),
            _ => Setup::ThreePorts(Box::new(ThreePorts::new(coupled).map_err(simulation)?)),
        };
        let safety = trocar_sim::scene::safety(name).map_err(simulation)?;
        Ok(SceneStepper {
            name,
            safety,
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
        self.names().iter().map(|s| s.to_string()).collect()
    }

    fn names(&self) -> &'static [&'static str] {
        match &self.inner {
            Setup::ThreePorts(_) => &ARMS,
            Setup::Dia10Dual(_) => &dual::ARMS,
        }
    }

    /// The couplings, as pairs of arms' names.
    pub fn couplings(&self) -> Vec<(String, String)> {
        let pairs: Vec<(usize, usize)> = match &self.inner {
            Setup::ThreePorts(s) => s.scene.couplings.iter().map(|c| c.arms).collect(),
            Setup::Dia10Dual(s) => s.scene.couplings.iter().map(|c| c.arms).collect(),
        };
        let names = self.names();
        pairs
            .into_iter()
            .map(|(a, b)| (names[a].to_string(), names[b].to_string()))
            .collect()
    }

    /// The number of the scene's joints (a shared torso counted once).
    pub fn joints(&self) -> usize {
        match &self.inner {
            Setup::ThreePorts(_) => 21,
            Setup::Dia10Dual(_) => 15,
        }
    }

    /// The scene's sample time (s): the rates' limits (acceleration, jerk, the ranges over a
    /// step) are for this `dt`.
    pub fn dt(&self) -> f64 {
        match &self.inner {
            Setup::ThreePorts(_) => DT,
            Setup::Dia10Dual(_) => dual::DT,
        }
    }

    /// The shafts' safety distance (m).
    pub fn safety(&self) -> f64 {
        self.safety
    }

    /// The scene's joints at its start.
    pub fn q0(&self) -> Vec<f64> {
        match &self.fresh {
            Setup::ThreePorts(s) => s.q0.iter().flat_map(|q| q.iter().copied()).collect(),
            Setup::Dia10Dual(s) => torso_once(&s.q0),
        }
    }

    /// Every arm's port in the scene's frame (m).
    pub fn ports(&self) -> Vec<[f64; 3]> {
        match &self.inner {
            Setup::ThreePorts(s) => (0..ARMS.len())
                .map(|k| {
                    let p = s.bases[k].transform_point(&s.rcms[k].trocar);
                    [p.x, p.y, p.z]
                })
                .collect(),
            Setup::Dia10Dual(s) => s
                .rcms
                .iter()
                .map(|r| [r.trocar.x, r.trocar.y, r.trocar.z])
                .collect(),
        }
    }

    /// Back to the start: the controllers at rest, the warm starts and the camera's last point
    /// forgotten.
    pub fn reset(&mut self) {
        self.inner = self.fresh.clone();
    }

    /// One step at the scene's joints `q` (all arms, in order; a shared torso once) and time `t`
    /// (s, the arms' paths are functions of it; call once per sample, `t` increasing by
    /// [`Self::dt`]).
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
        let step = match &mut self.inner {
            Setup::ThreePorts(s) => {
                let q: [SVector<f64, 7>; 3] =
                    std::array::from_fn(|k| SVector::from_column_slice(&q[7 * k..7 * k + 7]));
                let out = s
                    .step(&q, t)
                    .map_err(|e| Error::Simulation(format!("t = {t} s: {e}")))?;
                SceneStep {
                    qd: out.qd.iter().flat_map(|x| x.iter().copied()).collect(),
                    distances: out.distances.to_vec(),
                    coupling_held: out.coupling_held,
                    coupling_active: out.coupling_active,
                    statuses: out.arms.iter().map(|a| a.status).collect(),
                }
            }
            Setup::Dia10Dual(s) => {
                // Each arm's chain: the torso, then its own 7.
                let arm = |k: usize| {
                    SVector::<f64, 8>::from_fn(|j, _| if j == 0 { q[0] } else { q[7 * k + j] })
                };
                let out = s
                    .step(&[arm(0), arm(1)], t)
                    .map_err(|e| Error::Simulation(e.to_string()))?;
                SceneStep {
                    qd: torso_once(&out.qd),
                    distances: out.distances.to_vec(),
                    coupling_held: out.coupling_held,
                    coupling_active: out.coupling_active,
                    statuses: out.arms.iter().map(|a| a.status).collect(),
                }
            }
        };
        if step.qd.iter().any(|v| !v.is_finite()) {
            return Err(Error::NotFinite(format!("t = {t} s: the scene's rates")));
        }
        Ok(step)
    }
}

/// The scene `name_or_path`: a scene file (TOML with a `[scene]` table), or a shipped scene
/// (`three-ports`, `dia10-dual`) where no such file exists. `None` when it is neither (a robot,
/// a mechanism, or nothing). Errors name the file, line and field.
pub fn load_scene(name_or_path: &str) -> Result<Option<trocar_model::scene::SceneDescription>> {
    use trocar_model::scene::{shipped_scene_names, SceneDescription};
    let path = std::path::Path::new(name_or_path);
    if path.is_file() {
        let text =
            trocar_model::description::DescriptionError::read_file(path).map_err(Error::from)?;
        if !SceneDescription::is_scene_text(&text) {
            return Ok(None);
        }
        return Ok(Some(
            SceneDescription::from_toml_str(&text, Some(path)).map_err(Error::from)?,
        ));
    }
    if shipped_scene_names().any(|n| n == name_or_path) {
        return Ok(Some(
            SceneDescription::shipped(name_or_path).map_err(Error::from)?,
        ));
    }
    Ok(None)
}

/// The generated module of a scene (`trocar_codegen::scene`): every arm's closed forms and the
/// scene's step kinematics, `no_std`, for `options.real`. The C ABI and fused functions are
/// emitted for single robots only.
pub fn generate_scene(
    scene: &trocar_model::scene::SceneDescription,
    options: &trocar_codegen::ModuleOptions,
) -> Result<String> {
    if options.c_api || !options.functions.is_empty() || options.fma_at_run_time {
        return Err(Error::Unsupported(format!(
            "`{}` is a scene: the C ABI, fused functions and FMA at run time are emitted for \
             single robots (generate an arm's description for them)",
            scene.name
        )));
    }
    trocar_codegen::scene::generate_scene_string(scene, options).map_err(Error::from)
}
