//! One module a subcommand: each `run` parses nothing and computes nothing of its own; it calls
//! the library ([`trocar_api`]) and prints the answer as the binary does.

pub(crate) mod eval;
pub(crate) mod generate;
pub(crate) mod jacobian;
pub(crate) mod list;
pub(crate) mod preset;
pub(crate) mod register_port;
pub(crate) mod simulate;
pub(crate) mod verify;
