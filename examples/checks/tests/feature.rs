//! An integration test sees the library without `cfg(test)`: the module's checks behind the
//! feature `checks` (`Builder::checks_feature`), which the crate's dev-dependency on itself turns
//! on.

#[test]
fn the_checks_behind_a_feature_reach_integration_tests() {
    trocar_check::assert_matches_numeric::<trocar_checks_example::arm_feature::Checks>(
        "../../runtime/model/robots/bidirectional-zy.toml",
        300,
    );
}
