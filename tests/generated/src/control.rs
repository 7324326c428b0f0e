//! The generated closed forms driving the runtime controller: each constrained module emits
//! `Kinematics<T>`, an implementation of [`trocar::control::ConstrainedKinematics`] on its own
//! functions (`g_0i`, `g_0e`, `J^r_0e`, `J^B_0i`, `J_c`, `Λ#`, `Λ†` from one `JointTrig`), so the
//! controller needs no hand-written kinematics. Here they are named for the tests and benches.

/// `dia10_like_zy` (zy wrist) through its generated closed forms.
pub type Dia10LikeZy<T> = crate::dia10_like_zy::Kinematics<T>;

/// `dia10_like_zx` (zx wrist) through its generated closed forms.
pub type Dia10LikeZx<T> = crate::dia10_like_zx::Kinematics<T>;

/// The generated kinematics of the reference arm the thesis's scenarios use (`dia10_like_zy`).
pub type GeneratedKinematics<T> = Dia10LikeZy<T>;

/// The Franka Panda with a laparoscope (`panda-laparoscope`: constraint on the last link, shaft
/// along the flange's `z`, task `x y z rz`) through its generated closed forms.
pub type PandaLaparoscope<T> = crate::panda_laparoscope::Kinematics<T>;

/// The KUKA iiwa 14 with an endoscope (`iiwa-endoscope`: constraint on the last link, task
/// `x y z rz`) through its generated closed forms.
pub type IiwaEndoscope<T> = crate::iiwa_endoscope::Kinematics<T>;
