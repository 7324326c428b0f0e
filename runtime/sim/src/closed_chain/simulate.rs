//! Simulations of the source's §6 (Figures 4 and 5) and of the cooperating arms, as traces.

use super::cooperative::{two_arms, ContactModel};
use super::description;
use super::error::ClosedChainError;
use super::four_bar::FourBar;
use super::mechanism::{Mechanism, Pose2};
use super::redundancy::{resolve, Objective};
use super::stewart;
use crate::linalg::{self, as_slice};
use crate::simulation::CsvRows;
use faer::{Col, ColRef, Scale};
use std::f64::consts::PI;
use std::path::Path;

/// Scenario names accepted by [`simulate`].
pub fn scenario_names() -> &'static [&'static str] {
    &[
        "four-bar",
        "four-bar-sine",
        "stewart",
        "cooperative",
        "cooperative-gripped",
    ]
}

/// Options of a simulation. Integration is fourth-order Runge–Kutta of the closed loop
/// `θ̇_a = u(θ, t)`, `θ̇_p = −J_Cp⁻¹ (J_Ca u + k_c c(θ))` (7) (with a constraint-stabilising
/// term `k_c c`, which is zero on the constraint manifold).
#[derive(Clone, Debug, PartialEq)]
pub struct SimOptions {
    /// Simulated time (s); `None` for the scenario's default (10 s, as in the source's figures).
    pub duration: Option<f64>,
    /// Integration step (s).
    pub dt: f64,
    /// Record one sample every `record_every` steps (the last step is always recorded).
    pub record_every: usize,
    /// Task gains `K` (one per output); `None` for the source's values.
    pub gains: Option<Vec<f64>>,
    /// Null-space objective of (46) (used only where the mechanism is redundant).
    pub objective: Option<Objective>,
    /// Gain `K_0` of `u_0 = K_0 ∂f/∂θ_a` (46).
    pub null_gain: f64,
    /// Contact model for the cooperative scenario (`cooperative-gripped` forces `Gripped`).
    pub contact: ContactModel,
    /// Constraint stabilisation gain `k_c` (1/s).
    pub constraint_gain: f64,
}

impl Default for SimOptions {
    fn default() -> Self {
        SimOptions {
            duration: None,
            dt: 1e-3,
            record_every: 10,
            gains: None,
            objective: None,
            null_gain: 1.0,
            contact: ContactModel::PointWithFriction,
            constraint_gain: 10.0,
        }
    }
}

/// One plot panel: lines `(x column, y column, legend)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Panel {
    /// Title.
    pub title: String,
    /// x-axis label.
    pub x_label: String,
    /// y-axis label.
    pub y_label: String,
    /// Lines to draw: `(x column, y column, legend)`.
    pub lines: Vec<(String, String, String)>,
    /// The y axis starts at 0, or is logarithmic where the values span decades (norms,
    /// singular values).
    pub non_negative: bool,
}

/// A closed-mechanism simulation's time series: named columns, one row per recorded sample, and
/// suggested plot panels.
#[derive(Clone, Debug, PartialEq)]
pub struct MechanismTrace {
    /// Scenario name.
    pub name: String,
    /// Column names (`t` first).
    pub columns: Vec<String>,
    /// Samples (each as long as `columns`).
    pub rows: Vec<Vec<f64>>,
    /// Panels drawn by [`MechanismTrace::plot_svg`].
    pub panels: Vec<Panel>,
}

impl MechanismTrace {
    /// A column by name.
    pub fn column(&self, name: &str) -> Option<Vec<f64>> {
        let i = self.columns.iter().position(|c| c == name)?;
        Some(self.rows.iter().map(|r| r[i]).collect())
    }

    /// The last value of a column.
    pub fn last(&self, name: &str) -> Option<f64> {
        let i = self.columns.iter().position(|c| c == name)?;
        self.rows.last().map(|r| r[i])
    }

    /// The trace as CSV text (header line, then one line per sample).
    pub fn to_csv(&self) -> String {
        self.to_csv_rows(CsvRows::All)
    }

    /// The CSV text of the rows `rows` selects (the first and the last always).
    pub fn to_csv_rows(&self, rows: CsvRows) -> String {
        let mut s = self.columns.join(",");
        s.push('\n');
        let t: Vec<f64> = self.rows.iter().map(|r| r[0]).collect();
        for r in rows.select(&t).into_iter().map(|i| &self.rows[i]) {
            let line: Vec<String> = r.iter().map(|x| format!("{x:.12e}")).collect();
            s.push_str(&line.join(","));
            s.push('\n');
        }
        s
    }

    /// Writes the CSV to `path`.
    pub fn write_csv(&self, path: impl AsRef<Path>) -> Result<(), ClosedChainError> {
        self.write_csv_rows(path, CsvRows::All)
    }

    /// Writes the CSV of the rows `rows` selects to `path`.
    pub fn write_csv_rows(
        &self,
        path: impl AsRef<Path>,
        rows: CsvRows,
    ) -> Result<(), ClosedChainError> {
        let path = path.as_ref();
        rows.check().map_err(|message| ClosedChainError::Option {
            field: "csv rows".into(),
            message,
        })?;
        std::fs::write(path, self.to_csv_rows(rows)).map_err(|e| ClosedChainError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    }

    /// Draws the panels as an SVG file (one panel per row).
    ///
    /// Text uses the font embedded in [`crate::plot`], so figures render the same everywhere.
    pub fn plot_svg(&self, path: impl AsRef<Path>) -> Result<(), ClosedChainError> {
        self.plot_to(path.as_ref(), |p, size| {
            plotters::prelude::SVGBackend::new(p, size)
        })
    }

    /// Draws the panels as a PNG file (same layout and font as [`MechanismTrace::plot_svg`]).
    pub fn plot_png(&self, path: impl AsRef<Path>) -> Result<(), ClosedChainError> {
        self.plot_to(path.as_ref(), |p, size| {
            plotters::prelude::BitMapBackend::new(p, size)
        })
    }

    /// Draws the panels, one per row, on the backend `backend(path, size)` makes.
    fn plot_to<'p, DB: plotters::prelude::DrawingBackend>(
        &self,
        path: &'p Path,
        backend: impl FnOnce(&'p Path, (u32, u32)) -> DB,
    ) -> Result<(), ClosedChainError>
    where
        DB::ErrorType: 'static,
    {
        let size = (1000, 380 * self.panels.len().max(1) as u32);
        let io = |e: String| ClosedChainError::Io {
            path: path.display().to_string(),
            message: e,
        };
        ensure_font().map_err(io)?;
        let root = plotters::prelude::IntoDrawingArea::into_drawing_area(backend(path, size));
        self.draw(root).map_err(io)
    }

    fn draw<DB: plotters::prelude::DrawingBackend>(
        &self,
        root: plotters::drawing::DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        use crate::plot::{draw_panel, Fonts, Line, Panel2d};
        use plotters::prelude::*;
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let areas = root.split_evenly((self.panels.len().max(1), 1));
        for (panel, area) in self.panels.iter().zip(areas.iter()) {
            let mut lines = Vec::new();
            for (xc, yc, label) in &panel.lines {
                let (Some(x), Some(y)) = (self.column(xc), self.column(yc)) else {
                    return Err(format!("no column `{xc}` or `{yc}`"));
                };
                lines.push(Line {
                    label: label.clone(),
                    x,
                    y,
                });
            }
            draw_panel(
                area,
                &Panel2d {
                    title: &panel.title,
                    x_label: &panel.x_label,
                    y_label: &panel.y_label,
                    lines,
                    non_negative: panel.non_negative,
                },
                Fonts {
                    title: 20,
                    text: 16,
                },
            )
            .map_err(|e| e.to_string())?;
        }
        root.present()
            .map_err(|e| crate::plot::backend_message(&e))?;
        Ok(())
    }
}

/// Registers the embedded plot font for plotters' `sans-serif` family (see [`crate::plot`]).
fn ensure_font() -> Result<(), String> {
    crate::plot::register_font().map_err(|e| e.to_string())
}

/// A reference `t ↦ (x_d(t), ẋ_d(t))`.
pub type Reference<'a> = dyn Fn(f64) -> (Col<f64>, Col<f64>) + 'a;

/// Runs one of the source's simulations by name (see [`scenario_names`]):
///
/// - `four-bar`: orientation tracking of a pulse train (Figure 4a–b), `K = 50`;
/// - `four-bar-sine`: orientation tracking of a sinusoid (Figure 4c–d);
/// - `stewart`: planar Gough–Stewart pose tracking of a sinusoid (Figure 5), `K_x = diag(50, 50, 1)`;
/// - `cooperative`: two arms with point contacts (redundant) tracking a sinusoidal object pose,
///   with the null-space objective of `opts.objective`; `cooperative-gripped`: gripped contacts.
///
/// `progress` receives the completed fraction in `[0, 1]`.
pub fn simulate(
    name: &str,
    opts: &SimOptions,
    progress: Option<&mut dyn FnMut(f64)>,
) -> Result<MechanismTrace, ClosedChainError> {
    match name {
        "four-bar" | "four-bar-pulse" | "four-bar-sine" => {
            let mech = description::shipped("four-bar")?;
            let fb = FourBar::from_mechanism(&mech)?;
            let theta0 = fb.configuration(1.2)?;
            let sine = name == "four-bar-sine";
            let reference = move |t: f64| -> (Col<f64>, Col<f64>) {
                if sine {
                    let w = 2.0 * PI / 5.0;
                    (
                        col(&[6.95 + 0.35 * (w * t).sin()]),
                        col(&[0.35 * w * (w * t).cos()]),
                    )
                } else {
                    // Pulse train: period 6 s, 7.3 rad on [2, 5) s, 6.6 rad otherwise; its
                    // derivative is zero between the edges (a step has no finite feed-forward).
                    let level = if (2.0..5.0).contains(&t.rem_euclid(6.0)) {
                        7.3
                    } else {
                        6.6
                    };
                    (col(&[level]), Col::zeros(1))
                }
            };
            let gains = opts.gains.clone().unwrap_or_else(|| vec![50.0]);
            let mut tr =
                simulate_mechanism(&mech, &theta0, &reference, &gains, 10.0, opts, progress)?;
            tr.name = name.to_string();
            tr.panels = vec![
                panel(
                    "(a) orientation of the end effector",
                    "phi (rad)",
                    &[("phi_d", "φ_d"), ("phi", "φ")],
                ),
                panel("(b) orientation error", "e_phi (rad)", &[("e_phi", "e_φ")]),
                panel(
                    "(c) active joint velocity",
                    "u (rad/s)",
                    &[("u_theta1", "u = dθ1/dt")],
                ),
            ];
            Ok(tr)
        }
        "stewart" | "planar-stewart" => {
            let mech = description::shipped("planar-stewart")?;
            let theta0 = stewart::inverse_kinematics(&mech, Pose2::new(13.0, 12.5, -0.5))?;
            let w = 2.0 * PI / 10.0;
            let reference = move |t: f64| -> (Col<f64>, Col<f64>) {
                (
                    col(&[
                        14.0 + 3.0 * (w * t).sin(),
                        14.0 + 2.5 * (2.0 * w * t).sin(),
                        0.3 * (w * t).sin(),
                    ]),
                    col(&[
                        3.0 * w * (w * t).cos(),
                        5.0 * w * (2.0 * w * t).cos(),
                        0.3 * w * (w * t).cos(),
                    ]),
                )
            };
            let gains = opts.gains.clone().unwrap_or_else(|| vec![50.0, 50.0, 1.0]);
            let mut tr =
                simulate_mechanism(&mech, &theta0, &reference, &gains, 10.0, opts, progress)?;
            tr.name = "stewart".into();
            tr.panels = vec![
                Panel {
                    title: "(a) platform position".into(),
                    x_label: "X (m)".into(),
                    y_label: "Y (m)".into(),
                    lines: vec![
                        ("x_d".into(), "y_d".into(), "p_d (reference)".into()),
                        ("x".into(), "y".into(), "p".into()),
                    ],
                    non_negative: false,
                },
                panel(
                    "(b) position error",
                    "e_p (m)",
                    &[("e_x", "e_px"), ("e_y", "e_py")],
                ),
                panel("(c) orientation error", "e_phi (rad)", &[("e_phi", "e_φ")]),
                norm_panel(
                    "(d) smallest singular value of J_Cp",
                    "sigma_min (-)",
                    &[("sigma_min_jcp", "σ_min(J_Cp)")],
                ),
            ];
            Ok(tr)
        }
        "cooperative" | "cooperative-gripped" => {
            let model = if name == "cooperative-gripped" {
                ContactModel::Gripped
            } else {
                opts.contact.clone()
            };
            let mech = two_arms(&model)?;
            let x0 = col(&[1.0, 1.2, 0.0]);
            let guess = col(mech.initial.as_deref().unwrap_or_default());
            let theta0 = mech.assemble(&guess, Some(&x0))?;
            let w = 2.0 * PI / 5.0;
            let reference = move |t: f64| -> (Col<f64>, Col<f64>) {
                (
                    col(&[
                        1.05 + 0.15 * (w * t).sin(),
                        1.15 + 0.1 * (2.0 * w * t).sin(),
                        0.05 + 0.15 * (w * t).sin(),
                    ]),
                    col(&[
                        0.15 * w * (w * t).cos(),
                        0.2 * w * (2.0 * w * t).cos(),
                        0.15 * w * (w * t).cos(),
                    ]),
                )
            };
            let gains = opts.gains.clone().unwrap_or_else(|| vec![50.0, 50.0, 50.0]);
            let mut tr =
                simulate_mechanism(&mech, &theta0, &reference, &gains, 10.0, opts, progress)?;
            tr.name = name.to_string();
            tr.panels = vec![
                panel(
                    "(a) object position",
                    "x, y (m)",
                    &[("x_d", "x_d"), ("x", "x"), ("y_d", "y_d"), ("y", "y")],
                ),
                panel(
                    "(b) object pose error",
                    "e_x, e_y (m), e_phi (rad)",
                    &[("e_x", "e_x"), ("e_y", "e_y"), ("e_phi", "e_φ")],
                ),
                norm_panel(
                    "(c) constraint residual",
                    "|c(theta)| (m)",
                    &[("constraint", "‖c(θ)‖")],
                ),
            ];
            if tr.columns.iter().any(|c| c == "objective") {
                tr.panels.push(panel(
                    "(d) null-space objective (46)",
                    "f (-)",
                    &[(
                        "objective",
                        opts.objective.as_ref().map_or("f", |o| o.name()),
                    )],
                ));
            }
            Ok(tr)
        }
        _ => Err(ClosedChainError::UnknownScenario {
            name: name.into(),
            known: scenario_names().to_vec(),
        }),
    }
}

fn panel(title: &str, y: &str, cols: &[(&str, &str)]) -> Panel {
    Panel {
        title: title.into(),
        x_label: "t (s)".into(),
        y_label: y.into(),
        lines: cols
            .iter()
            .map(|(c, l)| ("t".to_string(), c.to_string(), l.to_string()))
            .collect(),
        non_negative: false,
    }
}

/// A panel of norms over time (`t` in seconds): a non-negative y axis.
fn norm_panel(title: &str, y: &str, cols: &[(&str, &str)]) -> Panel {
    Panel {
        non_negative: true,
        ..panel(title, y, cols)
    }
}

/// The closed-loop joint velocities at `(t, θ)`: (45) with the admissibility rows, then (7).
fn closed_loop(
    mech: &Mechanism,
    theta: &Col<f64>,
    t: f64,
    reference: &Reference<'_>,
    gains: &[f64],
    opts: &SimOptions,
) -> Result<(Col<f64>, Col<f64>), ClosedChainError> {
    let red = mech.reduced(theta)?;
    let x = mech.task(theta);
    let (xd, xd_dot) = reference(t);
    let e = &xd - &x;
    let v = Col::from_fn(e.nrows(), |i| xd_dot[i] + gains[i] * e[i]);
    let c = mech.structural(theta);
    let rows = &red.active_constraint;
    let rhs = Scale(-opts.constraint_gain) * (red.complement.transpose() * &c);
    let redundant = rows.nrows() + red.jacobian.nrows() < red.jacobian.ncols();
    let u0 = match (&opts.objective, redundant) {
        (Some(obj), true) => Some(Scale(opts.null_gain) * obj.gradient(mech, theta)?),
        _ => None,
    };
    let u = resolve(&red.jacobian, &v, rows, &rhs, u0.as_ref())?;
    let pdot = &red.passive_map * &u - Scale(opts.constraint_gain) * (&red.j_cp_inverse * &c);
    Ok((mech.join(&u, &pdot), u))
}

/// Simulates the kinematic control `u = J†(ẋ_d + K e) + (I − J†J) u_0` (45) of any mechanism
/// from `theta0` (a consistent configuration) along `reference`, for `opts.duration` (or
/// `default_duration`) seconds. Columns: `t`, then for each output `o`: `o_d`, `o`, `e_o`; then
/// `u_<active joint>`, `constraint` (‖c(θ)‖), `sigma_min_jcp`, `objective` (when set and the
/// mechanism is redundant), and every joint.
#[allow(clippy::too_many_arguments)]
pub fn simulate_mechanism(
    mech: &Mechanism,
    theta0: &Col<f64>,
    reference: &Reference<'_>,
    gains: &[f64],
    default_duration: f64,
    opts: &SimOptions,
    mut progress: Option<&mut dyn FnMut(f64)>,
) -> Result<MechanismTrace, ClosedChainError> {
    mech.check_theta(theta0)?;
    let duration = opts.duration.unwrap_or(default_duration);
    if !(duration.is_finite() && duration > 0.0) {
        return Err(ClosedChainError::Option {
            field: "duration".into(),
            message: "must be positive".into(),
        });
    }
    if !(opts.dt.is_finite() && opts.dt > 0.0 && opts.dt <= duration) {
        return Err(ClosedChainError::Option {
            field: "dt".into(),
            message: "must be positive and at most the duration".into(),
        });
    }
    if gains.len() != mech.outputs.len() || gains.iter().any(|g| !(g.is_finite() && *g > 0.0)) {
        return Err(ClosedChainError::Option {
            field: "gains".into(),
            message: format!("need {} positive gains", mech.outputs.len()),
        });
    }
    if !(opts.null_gain.is_finite()
        && opts.constraint_gain.is_finite()
        && opts.constraint_gain >= 0.0)
    {
        return Err(ClosedChainError::Option {
            field: "null_gain/constraint_gain".into(),
            message: "must be finite (constraint gain ≥ 0)".into(),
        });
    }
    let every = opts.record_every.max(1);
    let steps = (duration / opts.dt).round().max(1.0) as usize;
    let dt = duration / steps as f64;
    let names = mech.joint_names();
    let redundant = {
        let red = mech.reduced(theta0)?;
        red.active_constraint.nrows() + red.jacobian.nrows() < red.jacobian.ncols()
    };
    let with_objective = opts.objective.is_some() && redundant;
    let mut columns = vec!["t".to_string()];
    for o in &mech.outputs {
        columns.push(format!("{}_d", o.name()));
        columns.push(o.name().to_string());
        columns.push(format!("e_{}", o.name()));
    }
    for &i in mech.active_indices() {
        columns.push(format!("u_{}", names[i]));
    }
    columns.push("constraint".into());
    let has_passive = !mech.passive_indices().is_empty();
    if has_passive {
        columns.push("sigma_min_jcp".into());
    }
    if with_objective {
        columns.push("objective".into());
    }
    for n in &names {
        columns.push(n.to_string());
    }
    let mut rows = Vec::new();
    let mut theta = theta0.clone();
    for k in 0..=steps {
        let t = k as f64 * dt;
        if k % every == 0 || k == steps {
            let (_, u) = closed_loop(mech, &theta, t, reference, gains, opts)?;
            let x = mech.task(&theta);
            let (xd, _) = reference(t);
            let mut row = vec![t];
            for i in 0..x.nrows() {
                row.push(xd[i]);
                row.push(x[i]);
                row.push(xd[i] - x[i]);
            }
            row.extend(as_slice(&u));
            row.push(mech.structural(&theta).norm_l2());
            if has_passive {
                row.push(linalg::sigma_min(mech.differential(&theta)?.j_cp.as_ref()));
            }
            if with_objective {
                if let Some(obj) = &opts.objective {
                    row.push(obj.value(mech, &theta)?);
                }
            }
            row.extend(as_slice(&theta));
            if row.iter().any(|x| !x.is_finite()) {
                return Err(ClosedChainError::NonFinite {
                    what: format!("simulation state at t = {t}"),
                });
            }
            rows.push(row);
            if let Some(p) = progress.as_deref_mut() {
                p(k as f64 / steps as f64);
            }
        }
        if k == steps {
            break;
        }
        let f = |th: &Col<f64>, tt: f64| -> Result<Col<f64>, ClosedChainError> {
            Ok(closed_loop(mech, th, tt, reference, gains, opts)?.0)
        };
        let k1 = f(&theta, t)?;
        let k2 = f(&(&theta + Scale(0.5 * dt) * &k1), t + 0.5 * dt)?;
        let k3 = f(&(&theta + Scale(0.5 * dt) * &k2), t + 0.5 * dt)?;
        let k4 = f(&(&theta + Scale(dt) * &k3), t + dt)?;
        theta += Scale(dt / 6.0) * (k1 + Scale(2.0) * k2 + Scale(2.0) * k3 + k4);
    }
    Ok(MechanismTrace {
        name: mech.name.clone(),
        columns,
        rows,
        panels: Vec::new(),
    })
}

/// A column with the entries `values`.
fn col(values: &[f64]) -> Col<f64> {
    ColRef::from_slice(values).to_owned()
}
