//! Modules generated with `Builder::runtime_path("crate::reexport::trocar")` compile and compute
//! exactly what the modules naming `::trocar` compute.

use trocar_tests_generated::{
    bidirectional_zy, bidirectional_zy_reexport, four_bar, four_bar_reexport,
};

#[test]
fn reexported_runtime_path_gives_the_same_functions() {
    let q = [0.1, -0.3, 0.9, 0.2, -0.6, 0.1, 0.5, 0.3];
    let p = bidirectional_zy::Params::<f64>::nominal();
    let pr = bidirectional_zy_reexport::Params::<f64>::nominal();
    assert_eq!(
        bidirectional_zy::constrained_jacobian(&q, &p),
        bidirectional_zy_reexport::constrained_jacobian(&q, &pr)
    );
    assert_eq!(
        bidirectional_zy::manipulability(&q, &p),
        bidirectional_zy_reexport::manipulability(&q, &pr)
    );

    let theta = [0.7, 0.4, 1.1, -0.2];
    let p = four_bar::Params::<f64>::nominal();
    let pr = four_bar_reexport::Params::<f64>::nominal();
    assert_eq!(
        four_bar::reduced_jacobian(&theta, &p),
        four_bar_reexport::reduced_jacobian(&theta, &pr)
    );
}
