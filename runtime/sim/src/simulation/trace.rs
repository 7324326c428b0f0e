//! The recorded simulation: one row per control step, CSV output and summary figures.

use super::{ArmModel, Method, Scenario};
use std::io::Write;
use std::path::Path;

/// Which rows of a trace its CSV gets (`trocar simulate --every N` / `--dt SECONDS`). The first
/// and the last row are always written.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum CsvRows {
    /// Every row.
    #[default]
    All,
    /// Every `n`-th row (`n ≥ 1`): rows `0, n, 2n, …`, and the last.
    Every(usize),
    /// The rows at the times `0, dt, 2dt, …` (s): for each, the first row within half a sample
    /// time of it, and the last row. A `dt` at or below the trace's sample time keeps every row.
    Period(f64),
}

impl CsvRows {
    /// Checks the value: `n ≥ 1`; `dt` finite and positive. The message names the option
    /// (`--every`, `--dt`).
    pub fn check(&self) -> Result<(), String> {
        match *self {
            CsvRows::All => Ok(()),
            CsvRows::Every(0) => Err("--every: must be an integer of at least 1".into()),
            CsvRows::Every(_) => Ok(()),
            CsvRows::Period(dt) if !(dt.is_finite() && dt > 0.0) => Err(format!(
                "--dt: must be a positive number of seconds, not {dt}"
            )),
            CsvRows::Period(_) => Ok(()),
        }
    }

    /// The indices of the rows kept, in order, among rows at the increasing times `t`.
    pub fn select(&self, t: &[f64]) -> Vec<usize> {
        let n = t.len();
        let keep = |i: usize| -> bool {
            if i == 0 || i + 1 == n {
                return true;
            }
            match *self {
                CsvRows::All => true,
                CsvRows::Every(k) => i % k.max(1) == 0,
                CsvRows::Period(dt) => {
                    // Row i is the first at or past a multiple of dt, less half a sample time.
                    let half = 0.5 * (t[1] - t[0]);
                    let slot = |x: f64| ((x + half) / dt).floor();
                    slot(t[i]) != slot(t[i - 1])
                }
            }
        };
        (0..n).filter(|&i| keep(i)).collect()
    }
}

/// One control step.
#[derive(Clone, Debug, PartialEq)]
pub struct TraceRow {
    /// Time (s).
    pub t: f64,
    /// `‖dp − p_0e‖` (m).
    pub ep_norm: f64,
    /// `‖ε̃‖` of the quaternion error.
    pub eo_norm: f64,
    /// Lateral velocity of the link point at the trocar, in `F_r` (m/s), from finite
    /// differences of forward kinematics over `[t, t + dt]`: its components along the two axes
    /// of `F_r` normal to the shaft, in axis order (`(x_r, z_r)` on the reference arm, whose link
    /// runs along `y`; `(x_r, y_r)` on the Panda's laparoscope, along `z`), named in the CSV
    /// after them ([`Trace::lateral_axes`]: `vr_x, vr_z`, `vr_x, vr_y`).
    pub vr: [f64; 2],
    /// Distance from the trocar point to the link axis (m).
    pub rcm_drift: f64,
    /// Manipulability of `J^r_0e`.
    pub w_r: f64,
    /// Manipulability of `J^B_0i`.
    pub w_i: f64,
    /// `l_a` (m).
    pub l_a: f64,
    /// Joints (rad), [`Trace::joints`] values.
    pub q: Vec<f64>,
    /// Joint velocities (rad/s), [`Trace::joints`] values.
    pub qd: Vec<f64>,
    /// Position error in the end-effector frame, `R_0eᵀ(dp − p)` (m).
    pub ep: [f64; 3],
    /// Orientation error `ε̃` (base coordinates).
    pub eo: [f64; 3],
    /// Commanded RCM velocity on the lateral axes of [`TraceRow::vr`] (m/s).
    pub dv_cmd: [f64; 2],
    /// Damping applied to `J^r_0e`.
    pub kappa_r: f64,
    /// The tip's desired position `dp_0e` (base frame, m).
    pub reference: [f64; 3],
}

/// A simulation run.
#[derive(Clone, Debug, PartialEq)]
pub struct Trace {
    /// The shipped scenario, `None` for a user's trajectory.
    pub scenario: Option<Scenario>,
    /// What ran, for the figures' titles: the scenario's title, or the robot and the path.
    pub title: String,
    /// The robot that ran (its geometry, for the views of the arm).
    pub arm: ArmModel,
    /// The method.
    pub method: Method,
    /// Whether the drift correction was on.
    pub drift_correction: bool,
    /// Number of constrained directions (1: only `vr_x` is constrained).
    pub constrained_directions: usize,
    /// Sample time (s).
    pub dt: f64,
    /// Number of joints `n` (8 on the reference arm, 7 on the Panda; any other robot's).
    pub joints: usize,
    /// The axes of `F_r` of [`TraceRow::vr`]'s components: `["x_r", "z_r"]` on the reference
    /// arm, `["x_r", "y_r"]` on the Panda.
    pub lateral_axes: [&'static str; 2],
    /// Joint limits `[lower, upper]` (rad) of the `n` joints, when the robot has them.
    pub joint_limits: Option<Vec<[f64; 2]>>,
    /// Joint speed limits (rad/s) of the `n` joints that the QP step keeps, when the robot has
    /// them (the URDF's `velocity`); drawn on the figure with the joint velocities.
    pub speed_limits: Option<Vec<f64>>,
    /// The bounds `[l_min, l_max]` of `l_a` (m) that the QP step keeps, when the scenario has
    /// them; drawn on the figure with `l_a`.
    pub depth_limits: Option<[f64; 2]>,
    /// One row per step.
    pub rows: Vec<TraceRow>,
}

/// The CSV header of the reference arm (8 joints), in column order; [`Trace::csv_header`] for
/// any robot.
pub const CSV_HEADER: &str = "t,ep_norm,eo_norm,vr_x,vr_z,rcm_drift,w_r,w_i,l_a,\
q1,q2,q3,q4,q5,q6,q7,q8,qd1,qd2,qd3,qd4,qd5,qd6,qd7,qd8";

/// Figures of merit of a run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// Largest `|vr − dv_cmd|` in the constrained directions after the first step (m/s).
    pub max_rcm_velocity_error: f64,
    /// Largest `‖vr‖` (both lateral directions, including commanded motion) (m/s).
    pub max_vr: f64,
    /// Largest distance trocar–link axis (m).
    pub max_drift: f64,
    /// Distance trocar–link axis at the end (m).
    pub final_drift: f64,
    /// Largest `ep_norm` (m).
    pub max_ep: f64,
    /// Largest `ep_norm` after 10 s (m).
    pub max_ep_after_10s: f64,
    /// Largest `ep_norm` after the first second (m).
    pub max_ep_after_1s: f64,
    /// Largest `eo_norm`.
    pub max_eo: f64,
    /// Largest `|θ̇_k|` over joints and time (rad/s).
    pub peak_qd: f64,
    /// Smallest manipulability of `J^r_0e`.
    pub min_w_r: f64,
    /// Smallest manipulability of `J^B_0i`.
    pub min_w_i: f64,
    /// Smallest `|q7|` (rad); infinite for a robot of fewer than seven joints.
    pub min_abs_q7: f64,
    /// Smallest distance of a joint to its nearest limit (rad; negative beyond a limit), when
    /// the robot has limits.
    pub min_limit_margin: Option<f64>,
    /// Range of `l_a` (m).
    pub l_a_range: (f64, f64),
}

impl Trace {
    /// The CSV header: `t,ep_norm,eo_norm`, the lateral velocities named after the axes of
    /// `F_r` ([`Trace::lateral_axes`]: `vr_x,vr_z` on the reference arm, `vr_x,vr_y` on the
    /// Panda), `rcm_drift,w_r,w_i,l_a`, then `q1..qn`, `qd1..qdn` ([`CSV_HEADER`] on the
    /// reference arm).
    pub fn csv_header(&self) -> String {
        let [a, b] = self.lateral_axes.map(|axis| &axis[..1]);
        let mut h = format!("t,ep_norm,eo_norm,vr_{a},vr_{b},rcm_drift,w_r,w_i,l_a");
        for prefix in ["q", "qd"] {
            for k in 1..=self.joints {
                h += &format!(",{prefix}{k}");
            }
        }
        h
    }

    /// The values of one row in the order of [`Trace::csv_header`].
    fn row_values(&self, r: &TraceRow) -> Vec<f64> {
        let n = self.joints;
        let mut v = vec![
            r.t,
            r.ep_norm,
            r.eo_norm,
            r.vr[0],
            r.vr[1],
            r.rcm_drift,
            r.w_r,
            r.w_i,
            r.l_a,
        ];
        v.extend_from_slice(&r.q[..n.min(r.q.len())]);
        v.extend_from_slice(&r.qd[..n.min(r.qd.len())]);
        v
    }

    /// The trace as named columns, in the order of [`Trace::csv_header`].
    pub fn columns(&self) -> Vec<(String, Vec<f64>)> {
        let names: Vec<String> = self.csv_header().split(',').map(str::to_owned).collect();
        let mut cols: Vec<Vec<f64>> = vec![Vec::with_capacity(self.rows.len()); names.len()];
        for r in &self.rows {
            for (c, v) in cols.iter_mut().zip(self.row_values(r)) {
                c.push(v);
            }
        }
        names.into_iter().zip(cols).collect()
    }

    /// Writes the CSV (columns [`Trace::csv_header`]) to a writer.
    pub fn to_csv(&self, w: impl Write) -> std::io::Result<()> {
        self.to_csv_rows(w, CsvRows::All)
    }

    /// Writes the CSV of the rows `rows` selects to a writer.
    pub fn to_csv_rows(&self, mut w: impl Write, rows: CsvRows) -> std::io::Result<()> {
        rows.check().map_err(std::io::Error::other)?;
        writeln!(w, "{}", self.csv_header())?;
        let t: Vec<f64> = self.rows.iter().map(|r| r.t).collect();
        for i in rows.select(&t) {
            let v = self.row_values(&self.rows[i]);
            // `t` as written (it is a multiple of dt); the rest in scientific notation.
            write!(w, "{}", v[0])?;
            for x in &v[1..] {
                write!(w, ",{x:e}")?;
            }
            writeln!(w)?;
        }
        Ok(())
    }

    /// Writes the CSV to a file.
    pub fn write_csv(&self, path: impl AsRef<Path>) -> std::io::Result<()> {
        self.write_csv_rows(path, CsvRows::All)
    }

    /// Writes the CSV of the rows `rows` selects to a file.
    pub fn write_csv_rows(&self, path: impl AsRef<Path>, rows: CsvRows) -> std::io::Result<()> {
        let f = std::fs::File::create(path)?;
        let mut w = std::io::BufWriter::new(f);
        self.to_csv_rows(&mut w, rows)?;
        w.flush()
    }

    /// `|vr − dv_cmd|` in the constrained directions at a row.
    pub fn rcm_velocity_error(&self, r: &TraceRow) -> f64 {
        let ex = r.vr[0] - r.dv_cmd[0];
        if self.constrained_directions == 1 {
            ex.abs()
        } else {
            ex.hypot(r.vr[1] - r.dv_cmd[1])
        }
    }

    /// Figures of merit.
    pub fn summary(&self) -> Summary {
        let max = |f: &dyn Fn(&TraceRow) -> f64| self.rows.iter().map(f).fold(0.0, f64::max);
        let min =
            |f: &dyn Fn(&TraceRow) -> f64| self.rows.iter().map(f).fold(f64::INFINITY, f64::min);
        Summary {
            max_rcm_velocity_error: self
                .rows
                .iter()
                .skip(1)
                .map(|r| self.rcm_velocity_error(r))
                .fold(0.0, f64::max),
            max_vr: max(&|r| r.vr[0].hypot(r.vr[1])),
            max_drift: max(&|r| r.rcm_drift),
            final_drift: self.rows.last().map_or(0.0, |r| r.rcm_drift),
            max_ep: max(&|r| r.ep_norm),
            max_ep_after_10s: self
                .rows
                .iter()
                .filter(|r| r.t >= 10.0)
                .map(|r| r.ep_norm)
                .fold(0.0, f64::max),
            max_ep_after_1s: self
                .rows
                .iter()
                .filter(|r| r.t >= 1.0)
                .map(|r| r.ep_norm)
                .fold(0.0, f64::max),
            max_eo: max(&|r| r.eo_norm),
            peak_qd: max(&|r| r.qd.iter().fold(0.0, |a: f64, v| a.max(v.abs()))),
            min_w_r: min(&|r| r.w_r),
            min_w_i: min(&|r| r.w_i),
            min_abs_q7: min(&|r| r.q.get(6).map_or(f64::INFINITY, |q| q.abs())),
            min_limit_margin: self.joint_limits.as_ref().map(|limits| {
                min(&|r| {
                    limits
                        .iter()
                        .zip(&r.q)
                        .map(|(l, q)| (q - l[0]).min(l[1] - q))
                        .fold(f64::INFINITY, f64::min)
                })
            }),
            l_a_range: (min(&|r| r.l_a), max(&|r| r.l_a)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::CsvRows;

    fn times(n: usize, h: f64) -> Vec<f64> {
        (0..n).map(|k| k as f64 * h).collect()
    }

    #[test]
    fn every_n_keeps_first_and_last() {
        let t = times(11, 0.1);
        assert_eq!(CsvRows::Every(3).select(&t), [0, 3, 6, 9, 10]);
        assert_eq!(CsvRows::Every(5).select(&t), [0, 5, 10]);
        assert_eq!(CsvRows::Every(1).select(&t), (0..11).collect::<Vec<_>>());
        assert_eq!(CsvRows::Every(100).select(&t), [0, 10]);
        assert_eq!(CsvRows::All.select(&t).len(), 11);
    }

    #[test]
    fn period_picks_the_rows_at_its_multiples() {
        // 2 ms samples, 10 ms period: rows 0, 5, 10, ...; 0.2 s is exactly 1.0000000000000002
        // multiples away in floating point, which must not shift the pick.
        let t = times(1001, 0.002);
        let kept = CsvRows::Period(0.01).select(&t);
        assert_eq!(kept.len(), 201);
        assert!(kept.iter().all(|i| i % 5 == 0), "{kept:?}");
        // A period that is not a multiple: the nearest following row, then the last.
        let kept = CsvRows::Period(0.0062).select(&times(9, 0.002));
        assert_eq!(kept, [0, 3, 6, 8]);
        // Finer than the samples: every row.
        assert_eq!(CsvRows::Period(1e-4).select(&times(5, 0.002)).len(), 5);
    }

    #[test]
    fn bad_values_name_the_option() {
        assert!(CsvRows::Every(0).check().unwrap_err().contains("--every"));
        for dt in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(CsvRows::Period(dt).check().unwrap_err().contains("--dt"));
        }
        assert!(CsvRows::Every(2).check().is_ok() && CsvRows::Period(0.5).check().is_ok());
    }
}
