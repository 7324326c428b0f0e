//! Every form of `#[constrained_robot(...)]` compiles and runs (relative paths from the crate's
//! directory, as `CARGO_MANIFEST_DIR` gives them): a description file and the inline forms, every
//! preset and its options, a URDF-based robot with its controller, and scenes. The forms that must
//! not compile, and their messages, are `tests/ui.rs`'s.

mod file_inline;
mod panda_controller;
mod preset;
mod scene;
