//! Verification of generated kinematics against the numeric runtime and finite differences.
