//! Constrained kinematic control (3.17)–(3.18), (3.33)–(3.34), with pseudo-inverse, damped least squares and filtered inverse.
