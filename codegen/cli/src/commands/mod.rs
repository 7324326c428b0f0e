//! One module a subcommand. Each has a function that computes the command's answer (for use
//! from Rust or a binding) and a `run` that prints it as the binary does.

pub(crate) mod eval;
pub(crate) mod generate;
pub(crate) mod jacobian;
pub(crate) mod list;
pub(crate) mod preset;
pub(crate) mod simulate;
pub(crate) mod verify;
