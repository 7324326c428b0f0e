//! Kinematic simulations of the thesis's scenarios (chapter 4).
