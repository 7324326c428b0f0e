//! Finite-difference references: body Jacobians by central differences of forward kinematics through the SE(3) logarithm.
