//! trybuild UI tests: every error of `#[constrained_robot(...)]` is reported at the offending
//! token with a helpful message (`.stderr` snapshots; regenerate with
//! `TRYBUILD=overwrite cargo test -p trocar-derive --test ui` and review the diff). The forms that
//! compile run in `tests/attribute` (with no passing case here, trybuild checks the cases in one
//! `cargo check` instead of building each).
//!
//! In these tests `CARGO_MANIFEST_DIR` is trybuild's project directory
//! `$WORKSPACE/target/tests/trybuild/trocar-derive`, hence the `../../../../derive/...` paths.

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.compile_fail("tests/ui/fail_*.rs");
}
