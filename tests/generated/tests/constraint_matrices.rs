//! The constraint's own matrices as emitted — `H` (`constraint_selection`, (3.1)), `Λ#`
//! (`lambda_null_space`, (3.6)/(3.23)/(3.27)) and `Λ†` (`lambda_pinv`, (3.31)) — against the
//! numeric runtime's constraint (`trocar::constraint::Constraint`, built from the description by
//! `trocar_model::numeric`), at the nominal parameters and at another trocar offset `l_a`; and
//! the identities `Λ Λ# = 0`, `Λ Λ† = I` on the emitted values alone.

use trocar_model::description::RobotDescription;
use trocar_model::numeric::NumericModel;

fn description(path: &str) -> RobotDescription {
    match path.strip_prefix("preset:") {
        Some(name) => RobotDescription::preset(name).unwrap(),
        None => RobotDescription::from_toml_file(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path),
        )
        .unwrap(),
    }
}

fn close(what: &str, a: &[f64], b: &[f64]) {
    assert_eq!(a.len(), b.len(), "{what}: sizes");
    let err = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-12, "{what}: max |generated − numeric| = {err:e}");
}

macro_rules! check {
    ($test:ident, $m:ident, $path:literal) => {
        #[test]
        fn $test() {
            use trocar_tests_generated::$m as g;
            for l_a in [None, Some(0.11)] {
                let mut p = g::Params::<f64>::nominal();
                let mut model =
                    NumericModel::<f64>::from_description(&description($path), &[]).unwrap();
                if let Some(v) = l_a {
                    p.l_a = v;
                    model.set_parameter("l_a", v).unwrap();
                }
                let c = model.constraint().unwrap();
                let h: Vec<f64> = g::constraint_selection(&p).concat();
                let sharp: Vec<f64> = g::lambda_null_space(&p).concat();
                let pinv: Vec<f64> = g::lambda_pinv(&p).concat();
                let numeric_sharp: Vec<f64> = c
                    .lambda_null_space_columns()
                    .iter()
                    .flat_map(|t| t.iter().copied())
                    .collect();
                close("Λ#", &sharp, &numeric_sharp);
                close("Λ†", &pinv, &c.lambda_pinv_column_major());
                // H as the description gives it (rows of six numbers).
                let rows = &description($path).constraint.unwrap().h;
                let r = g::R;
                let desc_h: Vec<f64> = (0..6)
                    .flat_map(|k| rows.iter().map(move |row| row[k]))
                    .collect();
                close("H", &h, &desc_h);
                let lambda = c.lambda_column_major();
                let lm = trocar::nalgebra::DMatrix::from_column_slice(r, 6, &lambda);
                let sm = trocar::nalgebra::DMatrix::from_column_slice(6, g::K, &sharp);
                let pm = trocar::nalgebra::DMatrix::from_column_slice(6, r, &pinv);
                assert!((&lm * &sm).amax() < 1e-12, "Λ Λ# = 0");
                let i = &lm * &pm - trocar::nalgebra::DMatrix::<f64>::identity(r, r);
                assert!(i.amax() < 1e-12, "Λ Λ† = I");
            }
        }
    };
}

check!(unidirectional, unidirectional, "preset:unidirectional");
check!(
    bidirectional_zy,
    bidirectional_zy,
    "preset:bidirectional-zy"
);
check!(
    bidirectional_zx,
    bidirectional_zx,
    "preset:bidirectional-zx"
);
check!(dia10_like_zy, dia10_like_zy, "preset:dia10_like_zy");
check!(dia10_like_zx, dia10_like_zx, "preset:dia10_like_zx");
check!(rotated_rcm, rotated_rcm, "robots/rotated_rcm.toml");
check!(
    chain9_prismatic,
    chain9_prismatic,
    "robots/chain9_prismatic.toml"
);

/// Modules whose constraint frame is `(I, (0, l_a, 0))` implement the controller's trait.
#[test]
fn the_glue_is_emitted_where_the_convention_holds() {
    fn is_kinematics<K: trocar::control::ConstrainedKinematics<f64, 8, 6, 2, 4, 6>>(_: &K) {}
    is_kinematics(&trocar_tests_generated::dia10_like_zy::Kinematics::<f64>::nominal());
    is_kinematics(&trocar_tests_generated::dia10_like_zx_f64::Kinematics::nominal());
    is_kinematics(&trocar_tests_generated::bidirectional_zy::Kinematics::<f64>::nominal());
}
