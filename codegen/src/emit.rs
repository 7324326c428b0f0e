//! Optimisation (CSE, constant folding) and emission of Rust tokens.
