//! The geometry of a simulated serial robot ([`ArmModel`]) and what a trace measures of it at
//! each control step ([`ArmModel::measure`]), from forward kinematics only: the scenarios and a
//! user's trajectory ([`super::Trace`]) take their rows from here.

use super::TraceRow;
use nalgebra::{Matrix3, Vector3};
use trocar::control::{self, Shaft};
use trocar::kinematics::{forward_kinematics, link_frames, Joint};
use trocar::se3::Se3;
use trocar_model::numeric::NumericModel;

/// The geometry of a serial robot as simulated and drawn: joints, tool, the constrained link and
/// its shaft.
#[derive(Clone, Debug, PartialEq)]
pub struct ArmModel {
    pub(crate) joints: Vec<Joint<f64>>,
    pub(crate) tool: Se3<f64>,
    /// The constrained link `i` (1-based).
    pub(crate) link: usize,
    pub(crate) shaft: Shaft<f64>,
}

/// What the controller computed at one step, recorded beside the measurements of a
/// [`TraceRow`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepRecord<'a> {
    /// Time (s).
    pub t: f64,
    /// Joints at the step (rad or m).
    pub q: &'a [f64],
    /// Joint rates the controller commanded (rad/s or m/s).
    pub qd: &'a [f64],
    /// Sample time (s): the joints move to `q + dt qd`.
    pub dt: f64,
    /// The trocar point (base frame, m).
    pub trocar: &'a Vector3<f64>,
    /// The tip's desired position (base frame, m).
    pub position: &'a Vector3<f64>,
    /// The tip's desired orientation, `None` when the task does not command one.
    pub rotation: Option<&'a Matrix3<f64>>,
    /// Manipulability of the task Jacobian.
    pub w_r: f64,
    /// Manipulability of `J^B_0i`.
    pub w_i: f64,
    /// Damping applied to the task Jacobian.
    pub kappa_r: f64,
    /// Commanded RCM velocity on the two lateral axes (m/s).
    pub dv_cmd: [f64; 2],
}

impl ArmModel {
    /// From a numeric model with a constraint along a shaft.
    pub fn from_model(model: &NumericModel<f64>) -> Result<Self, String> {
        let link = model
            .constrained_link()
            .ok_or_else(|| "the robot has no constrained link".to_string())?;
        Ok(ArmModel {
            joints: model.joints().to_vec(),
            tool: *model.tool(),
            link,
            shaft: model.shaft().map_err(|e| e.to_string())?,
        })
    }

    /// The number of joints.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// The constrained link `i` (1-based).
    pub fn constrained_link(&self) -> usize {
        self.link
    }

    /// The shaft of the constrained link.
    pub fn shaft(&self) -> &Shaft<f64> {
        &self.shaft
    }

    /// The two axes of `F_r` normal to the shaft ([`super::lateral_axes`]).
    pub fn lateral_axes(&self) -> [usize; 2] {
        super::lateral_axes(&self.shaft)
    }

    /// The frames `F_1 … F_n` at `q` (`q` has [`ArmModel::dof`] values).
    pub(crate) fn frames(&self, q: &[f64]) -> Vec<Se3<f64>> {
        let mut frames = vec![Se3::identity(); self.joints.len()];
        link_frames(&self.joints, q, &mut frames);
        frames
    }

    /// The tip pose `g_0e(q)`.
    pub fn tip(&self, q: &[f64]) -> Se3<f64> {
        forward_kinematics(&self.joints, q, &self.tool)
    }

    /// The constrained link's frame `g_0i(q)`.
    pub fn link_frame(&self, q: &[f64]) -> Se3<f64> {
        self.frames(q)[self.link - 1]
    }

    /// One row of a trace, measured from forward kinematics only (not from the controller's
    /// Jacobians):
    /// - `l_a = (p_t − p_0i) · shaft`, `rcm_drift` the distance from the trocar to the shaft's
    ///   axis;
    /// - `vr`: the lateral velocity over the step of the shaft at the trocar: the chord
    ///   `m(q + dt qd) − m(q)` of the shaft's point `m` at `l_a`, less its part along the shaft
    ///   at `q + dt qd` ([`trocar::control::Shaft::moved_across`]), over `dt` (explicit Euler's
    ///   chord error and the drift correction's velocity included), on the two axes of `F_r`
    ///   normal to the shaft;
    /// - the tip errors against the desired pose.
    ///
    /// `q` and `qd` have [`ArmModel::dof`] values.
    pub fn measure(&self, s: &StepRecord<'_>) -> TraceRow {
        let q_next: Vec<f64> = s.q.iter().zip(s.qd).map(|(a, b)| a + b * s.dt).collect();
        let g_i = self.link_frame(s.q);
        let l_a = self.shaft.offset(&g_i, s.trocar);
        let g_r = self.shaft.constraint_pose(&g_i, l_a);
        let point = self.shaft.frame(l_a).translation;
        let across = self
            .shaft
            .moved_across(&self.link_frame(&q_next), &point, &g_r.translation);
        let v = g_r.rotation.transpose() * across / s.dt;
        let axes = self.lateral_axes();
        let g_e = self.tip(s.q);
        let ep = s.position - g_e.translation;
        let eo = s.rotation.map_or_else(Vector3::zeros, |r| {
            control::orientation_error(r, &g_e.rotation).eps
        });
        TraceRow {
            t: s.t,
            ep_norm: ep.norm(),
            eo_norm: eo.norm(),
            vr: [v[axes[0]], v[axes[1]]],
            rcm_drift: self.shaft.trocar_in_frame(&g_i, l_a, s.trocar).norm(),
            w_r: s.w_r,
            w_i: s.w_i,
            l_a,
            q: s.q.to_vec(),
            qd: s.qd.to_vec(),
            ep: (g_e.rotation.transpose() * ep).into(),
            eo: eo.into(),
            dv_cmd: s.dv_cmd,
            kappa_r: s.kappa_r,
            reference: (*s.position).into(),
        }
    }
}
