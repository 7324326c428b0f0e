//! A fixed sequence of control steps, run the same way on the host and on a Cortex-M4F under
//! QEMU (`examples/firmware/run-qemu.sh`), so that the two runs can be compared step by step.
//!
//! The references come as a table of little-endian `f32`s (written on the host by
//! `cargo run -p trocar-panda --example qemu_references` from the scenarios' own reference
//! paths, so that the path is defined once): a header — the trocar point (3), the sample time,
//! the number of steps (`u32`) — then one reference a step: the tip's position (3), its
//! orientation column-major (9), its linear and angular feed-forward velocities (3 + 3).

use crate::{control_step, panda, PandaController};
use trocar::control::{ControlError, Reference, StepOutput};
use trocar::nalgebra::{Matrix3, Vector3};

/// Bytes of the table's header: the trocar (3 `f32`), `dt` (`f32`), the steps (`u32`).
pub const HEADER_BYTES: usize = 20;
/// Bytes of one reference: 18 `f32`s.
pub const REFERENCE_BYTES: usize = 72;

/// A table of references for a run of [`step`]s (see the [module](self)).
#[derive(Clone, Copy, Debug)]
pub struct ReferenceTable<'a> {
    /// The trocar point (base frame, m).
    pub trocar: [f32; 3],
    /// The sample time (s).
    pub dt: f32,
    references: &'a [u8],
}

fn f32_at(bytes: &[u8], k: usize) -> f32 {
    let mut b = [0u8; 4];
    b.copy_from_slice(&bytes[4 * k..4 * k + 4]);
    f32::from_le_bytes(b)
}

impl<'a> ReferenceTable<'a> {
    /// The table in `bytes`; `None` where its length is not the header's count of references.
    pub fn parse(bytes: &'a [u8]) -> Option<Self> {
        let header = bytes.get(..HEADER_BYTES)?;
        let mut count = [0u8; 4];
        count.copy_from_slice(&header[16..20]);
        let steps = u32::from_le_bytes(count) as usize;
        let references = &bytes[HEADER_BYTES..];
        if references.len() != steps.checked_mul(REFERENCE_BYTES)? {
            return None;
        }
        Some(ReferenceTable {
            trocar: [f32_at(header, 0), f32_at(header, 1), f32_at(header, 2)],
            dt: f32_at(header, 3),
            references,
        })
    }

    /// The number of steps.
    pub fn steps(&self) -> usize {
        self.references.len() / REFERENCE_BYTES
    }

    /// The reference of step `k` (`k < steps()`).
    pub fn reference(&self, k: usize) -> Reference<f32> {
        let b = &self.references[k * REFERENCE_BYTES..(k + 1) * REFERENCE_BYTES];
        let v = |i: usize| f32_at(b, i);
        Reference {
            position: Vector3::new(v(0), v(1), v(2)),
            rotation: Matrix3::from_fn(|r, c| v(3 + 3 * c + r)),
            velocity: Vector3::new(v(12), v(13), v(14)),
            angular_velocity: Vector3::new(v(15), v(16), v(17)),
        }
    }
}

/// A reference computed in `f64` (a scenario's path), as the `f32` controller takes it: every
/// value rounded to the nearest `f32`.
pub fn reference_to_f32(r: &Reference<f64>) -> Reference<f32> {
    Reference {
        position: r.position.cast(),
        rotation: r.rotation.cast(),
        velocity: r.velocity.cast(),
        angular_velocity: r.angular_velocity.cast(),
    }
}

/// The table's bytes for `trocar`, `dt` and `references` (the host writes it; the inverse of
/// [`ReferenceTable::parse`]), into `out` (cleared first).
pub fn write_table(
    trocar: &[f32; 3],
    dt: f32,
    references: impl ExactSizeIterator<Item = Reference<f32>>,
    out: &mut impl Extend<u8>,
) {
    let count = references.len() as u32;
    for v in trocar.iter().chain(core::iter::once(&dt)) {
        out.extend(v.to_le_bytes());
    }
    out.extend(count.to_le_bytes());
    for r in references {
        let values = r
            .position
            .iter()
            .chain(r.rotation.iter())
            .chain(r.velocity.iter())
            .chain(r.angular_velocity.iter());
        for v in values {
            out.extend(v.to_le_bytes());
        }
    }
}

/// One step of the sequence: [`control_step`] at `q` toward `reference`, then `q += dt θ̇` in
/// `f32` (where the step failed, `q` stays).
pub fn step(
    ctrl: &mut PandaController,
    q: &mut [f32; panda::N],
    reference: &Reference<f32>,
    trocar: &[f32; 3],
    dt: f32,
) -> Result<StepOutput<f32, { panda::N }, { panda::R }>, ControlError> {
    let out = control_step(ctrl, q, reference, trocar, dt)?;
    for (qk, v) in q.iter_mut().zip(out.qd.iter()) {
        *qk += dt * v;
    }
    Ok(out)
}

/// The status of a step as one number, for a log both runs print: 0 every constraint held, 1
/// the trocar yielded, 2 a joint outside its range, 3 the depth outside its bounds, 10 + the
/// error's kind where the step failed.
pub fn status_code(out: &Result<StepOutput<f32, { panda::N }, { panda::R }>, ControlError>) -> u32 {
    use trocar::control::StepStatus;
    match out {
        Ok(o) => match o.status {
            StepStatus::Held => 0,
            StepStatus::TrocarYielded => 1,
            StepStatus::JointOutside => 2,
            StepStatus::DepthOutside => 3,
        },
        Err(_) => 10,
    }
}
