//! Kinematic simulations of the thesis's scenarios (chapter 4).
mod arm;
pub use arm::Arm;
