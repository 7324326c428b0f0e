//! trybuild UI tests: every form of `#[constrained_robot(...)]` compiles and runs; every error
//! is reported at the offending token with a helpful message (`.stderr` snapshots; regenerate
//! with `TRYBUILD=overwrite cargo test -p trocar-derive --test ui` and review the diff).
//!
//! In these tests `CARGO_MANIFEST_DIR` is trybuild's project directory
//! `$WORKSPACE/target/tests/trybuild/trocar-derive`, hence the `../../../../derive/...` paths.

#[test]
fn ui() {
    let t = trybuild::TestCases::new();
    t.pass("tests/ui/pass_*.rs");
    t.compile_fail("tests/ui/fail_*.rs");
}
