//! The presets' generated code as it was on 2026-11-23 (commit f680db9, before the generator's
//! expression graph, `mul_add` and the lane-group `sin_cos`), with that day's runtime surface
//! ([`real`]): the baseline the presets' `J^r` is measured against in the same run, so that a
//! regression of the generator or of the runtime's `sin_cos` shows as a ratio to it.
#![allow(missing_docs, clippy::all)]

pub mod real;

include!("unidirectional.rs");
include!("bidirectional_zy.rs");
include!("bidirectional_zx.rs");
