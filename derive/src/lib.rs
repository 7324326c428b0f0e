//! `#[constrained_robot(...)]`: a thin front over [`trocar_codegen`].
#![warn(missing_docs)]
