//! Closed kinematic chains and cooperating arms (Freitas, Leite & Lizarralde, CBA 2010),
//! numerically: a [`Mechanism`] is a [`trocar_model::closed_chain::MechanismModel`] evaluated at
//! parameter values, with dense linear algebra on faer.
//!
//! - [`mechanism`]: the active/passive partition; `J_C = Ã J`, `J_A = A† J` (17)–(19),
//!   (29)–(31); passive velocities (7); the reduced Jacobian `J = J_Aa − J_Ap J_Cp⁻¹ J_Ca` (8);
//!   forward kinematics by Newton's method; singularity classification (§4.5).
//! - [`crate::linalg`]: ranks, pseudo-inverses, annihilators and the SVD analysis of §5.4 (faer).
//! - [`description`]: shipped and file descriptions read by trocar-model and evaluated at their
//!   nominal parameters.
//! - [`four_bar`], [`stewart`], [`cooperative`]: the source's three examples (closed-form passive
//!   joints of the four-bar linkage, inverse kinematics of the planar Gough–Stewart platform,
//!   contact models by selection `H` (35)–(42)).
//! - [`redundancy`]: `u = J†(ẋ_d + K e) + (I − J†J) u_0`, `u_0 = K ∂f/∂θ_a` (44)–(46).
//! - [`simulate()`]: the simulations of the source's §6 and of the cooperating arms, as a
//!   [`MechanismTrace`] with CSV and plots.
//!
//! ```
//! use trocar_sim::closed_chain::{description, four_bar::FourBar};
//! let mech = description::shipped("four-bar").unwrap();
//! let fb = FourBar::from_mechanism(&mech).unwrap();
//! let theta = fb.configuration(1.2).unwrap();       // θ = (θ1, θ3, θ2, θ4)
//! let red = mech.reduced(&theta).unwrap();          // J of (8): dφ/dθ1
//! assert_eq!(red.jacobian.shape(), (1, 1));
//! ```

pub mod cooperative;
pub mod description;
mod error;
pub mod four_bar;
pub mod mechanism;
pub mod redundancy;
mod simulate;
pub mod stewart;

pub use error::{ClosedChainError, SingularityKind};
pub use mechanism::{
    Differential, JointType, Mechanism, Output, PlanarChain, PlanarJoint, Pose2, Reduced,
    SingularityReport,
};
pub use simulate::{
    scenario_names, simulate, simulate_mechanism, MechanismTrace, Panel, SimOptions,
};
