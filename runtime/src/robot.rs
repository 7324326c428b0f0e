//! A numeric robot built from a description with parameter values: dynamic-size front end of the kinematics kernels, for the CLI and verification.
