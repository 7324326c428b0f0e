//! The emitted straight-line solves `lu_solve_6` (dia10_like: J^r and J^B_0i) and `lu_solve_4`
//! (the Panda's task Jacobian) against nalgebra's LU with partial pivoting: random matrices,
//! matrices that need a row exchange at every column (a permuted diagonal, zero diagonals), and
//! singular ones (`det` exactly 0 or at rounding level, which the controller's `regular` rule
//! then refuses). The Panda's `min_norm_solve_6` (its 6 × 7 J^B_0i) against the minimum-norm
//! solution `Jᵀ (J Jᵀ)⁻¹ b` (refined once) and nalgebra's SVD (the product of the singular values).

use proptest::prelude::*;
use trocar::nalgebra::{DMatrix, DVector, SMatrix, SVector};
use trocar_tests_generated::dia10_like_zy as dia10;
use trocar_tests_generated::panda_laparoscope as panda;

/// `j[col][row]` of a nalgebra matrix.
fn columns<const D: usize>(m: &SMatrix<f64, D, D>) -> [[f64; D]; D] {
    core::array::from_fn(|c| core::array::from_fn(|r| m[(r, c)]))
}

fn check<const D: usize>(m: &SMatrix<f64, D, D>, b: &SVector<f64, D>, x: [f64; D], det: f64) {
    let md = DMatrix::from_column_slice(D, D, m.as_slice());
    let bd = DVector::from_column_slice(b.as_slice());
    let lu = md.clone().lu();
    let want_det = lu.determinant();
    let scale = md.amax().powi(D as i32).max(1e-300);
    assert!(
        (det - want_det).abs() <= 1e-12 * scale,
        "det {det} vs {want_det} for {md}"
    );
    if want_det.abs() > 1e-6 * scale {
        let want = lu.solve(&bd).unwrap();
        let x = DVector::from_column_slice(&x);
        assert!(
            (&x - &want).amax() <= 1e-9 * want.amax().max(1.0),
            "x {x} vs {want} for {md}"
        );
        assert!((&md * &x - &bd).amax() <= 1e-10 * (md.amax() * x.amax()).max(bd.amax()));
    }
}

fn solve6(m: &SMatrix<f64, 6, 6>, b: &SVector<f64, 6>) {
    let (x, det) = dia10::lu_solve_6(&columns(m), &b.data.0[0]);
    check(m, b, x, det);
}

fn solve4(m: &SMatrix<f64, 4, 4>, b: &SVector<f64, 4>) {
    let (x, det) = panda::lu_solve_4(&columns(m), &b.data.0[0]);
    check(m, b, x, det);
}

#[test]
fn every_row_exchange_and_singular_matrices() {
    let b6 = SVector::<f64, 6>::from_fn(|r, _| r as f64 - 2.5);
    // Anti-diagonal and cyclic permutations scaled: a pivot exchange at every column.
    for shift in 1..6 {
        let m = SMatrix::<f64, 6, 6>::from_fn(|r, c| {
            if (r + shift) % 6 == c {
                1.0 + r as f64
            } else {
                1e-3 * (r * 6 + c) as f64
            }
        });
        solve6(&m, &b6);
    }
    let anti = SMatrix::<f64, 6, 6>::from_fn(|r, c| if r + c == 5 { 2.0 } else { 0.0 });
    solve6(&anti, &b6);
    // Zero diagonal with a full off-diagonal.
    let zero_diag = SMatrix::<f64, 6, 6>::from_fn(|r, c| {
        if r == c {
            0.0
        } else {
            (r + 2 * c) as f64 * 0.1 + 0.3
        }
    });
    solve6(&zero_diag, &b6);
    // Singular: a repeated row, and zeros.
    let mut rank5 = zero_diag;
    rank5.set_row(4, &(zero_diag.row(1) * 3.0));
    let (_, det) = dia10::lu_solve_6(&columns(&rank5), &b6.data.0[0]);
    assert!(det.abs() < 1e-12, "rank-5 det {det}");
    // All zeros: a zero pivot, then 0 · ∞; "0 or not finite" is what the controller refuses.
    let (_, det) = dia10::lu_solve_6(&[[0.0; 6]; 6], &b6.data.0[0]);
    assert!(det == 0.0 || !det.is_finite(), "zero matrix det {det}");
    let b4 = SVector::<f64, 4>::new(1.0, -2.0, 0.5, 3.0);
    let anti4 = SMatrix::<f64, 4, 4>::from_fn(|r, c| if r + c == 3 { -1.5 } else { 0.01 });
    solve4(&anti4, &b4);
}

/// `min_norm_solve_6` of `m` against the SVD: `x = J⁺ b` and `w = Π σ`, or refused (`w = 0`)
/// exactly when the unit null vector's last component is below 10⁻² (with a margin for
/// rounding either side of the threshold). Returns whether it was admitted.
fn min_norm(m: &SMatrix<f64, 6, 7>, b: &SVector<f64, 6>, tol: f64) -> bool {
    let cols: [[f64; 6]; 7] = core::array::from_fn(|c| core::array::from_fn(|r| m[(r, c)]));
    let (x, w) = panda::min_norm_solve_6(&cols, &b.data.0[0]);
    let svd = m.svd(true, true);
    let sigma = svd.singular_values;
    let want_w: f64 = sigma.iter().product();
    // The last component of J's unit null vector n̂: e₇'s projection on the null space (the
    // complement of J's row space) is (e₇·n̂) n̂, of norm |n̂₇|.
    let vt = m.transpose().svd(true, true);
    let rows_span = vt.u.unwrap();
    let mut n = SVector::<f64, 7>::from_fn(|k, _| if k == 6 { 1.0 } else { 0.0 });
    for c in 0..6 {
        let u = rows_span.column(c);
        n -= u * u.dot(&n);
    }
    let last = n.norm();
    if w == 0.0 {
        assert!(
            last < 1.01e-2 || sigma.min() < 1e-12 * sigma.max(),
            "refused although the last component of the null vector is {last}: {m}"
        );
        return false;
    }
    assert!(
        last > 0.99e-2,
        "admitted with a null vector's last component {last}: {m}"
    );
    assert!(
        (w - want_w).abs() <= tol * want_w,
        "w {w} vs {want_w} for {m}"
    );
    // x = J⁺ b = Jᵀ (J Jᵀ)⁻¹ b with one step of refinement: nalgebra's SVD pseudo-inverse was
    // off by 1e-11 (residual 4.5e-11) on a matrix with cond(J) = 7.4, where this is at 1e-16.
    let gram = (m * m.transpose()).lu();
    let mut want = m.transpose() * gram.solve(b).unwrap();
    want += m.transpose() * gram.solve(&(b - m * want)).unwrap();
    let x = SVector::<f64, 7>::from(x);
    assert!(
        (x - want).norm() <= tol * want.norm().max(1e-300),
        "x {x} vs {want} for {m}"
    );
    true
}

#[test]
fn min_norm_solve_matches_the_svd() {
    let b = SVector::<f64, 6>::new(0.3, -1.2, 0.5, 2.0, -0.7, 0.1);
    let sample = SMatrix::<f64, 6, 7>::from_fn(|r, c| {
        ((r * 7 + c) as f64 * 0.731).sin() + if r == c { 2.0 } else { 0.0 }
    });
    assert!(min_norm(&sample, &b, 1e-13));
    // A random matrix (cond 7.4) on which the SVD's pseudo-inverse, the former reference, was
    // off by 1e-11 while the emitted solve is exact to rounding.
    let rows = [
        [
            1.9194337441970795,
            0.08302311580955378,
            -0.7686359481811144,
            -0.8339539975143508,
            0.3217227577449274,
            1.7554173337345949,
            -0.36780042844093463,
        ],
        [
            -1.1453699576091667,
            0.6261161489373743,
            0.7533484049950456,
            0.0483533621160796,
            -0.7855943193385866,
            -1.4344592606444364,
            0.2111499039321957,
        ],
        [
            1.3385099217406777,
            0.2668731663598934,
            -0.505537093249758,
            -1.4695769826326897,
            0.6716977853227022,
            0.37034045284109035,
            -0.2557396616339471,
        ],
        [
            0.3081977643309647,
            -0.9968898471288976,
            1.3540332840948408,
            -1.2660081434277768,
            -1.362324900415087,
            0.967992039962159,
            -1.9173270965943205,
        ],
        [
            -1.124325947216616,
            -0.29769034350051266,
            -1.7916948020875119,
            1.2264654596214837,
            1.3489117877995174,
            1.2737305974955067,
            -1.9183076035534816,
        ],
        [
            -1.6919294305135577,
            -1.5493061966669972,
            0.24855145430818584,
            -0.5703741116103651,
            -1.6790970585293485,
            0.6615455759406473,
            -1.1424092899081186,
        ],
    ];
    let random = SMatrix::<f64, 6, 7>::from_fn(|r, c| rows[r][c]);
    assert!(min_norm(&random, &b, 1e-13));
    // A row exchange at every column of the leading block.
    let mut cyclic = sample;
    for r in 0..6 {
        cyclic.set_row(r, &sample.row((r + 1) % 6));
    }
    assert!(min_norm(&cyclic, &b, 1e-13));
    // A leading block 0.05 from singular whose last column restores the rank: admitted (1 + a·a
    // of order 10³), accurate.
    let mut near = sample;
    let dependent = near.column(1) * 0.5 - near.column(3) * 2.0;
    near.set_column(5, &(dependent + near.column(5) * 0.05));
    near.set_column(6, &(near.column(6) + dependent));
    assert!(min_norm(&near, &b, 1e-12));
    // The leading block singular, the last column carrying the rank: refused.
    let mut last = sample;
    last.set_column(5, &(last.column(1) * 0.5 - last.column(3) * 2.0));
    assert!(!min_norm(&last, &b, 1e-12));
    // J singular (two equal rows), and all zeros: refused.
    let mut rank5 = sample;
    rank5.set_row(4, &(sample.row(1) * 3.0));
    assert!(!min_norm(&rank5, &b, 1e-12));
    let (_, w) = panda::min_norm_solve_6(&[[0.0; 6]; 7], &b.data.0[0]);
    assert!(w == 0.0 || !w.is_finite(), "zero matrix w {w}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn six_by_six_matches_nalgebra(entries in proptest::collection::vec(-2.0f64..2.0, 42)) {
        let m = SMatrix::<f64, 6, 6>::from_fn(|r, c| entries[r * 6 + c]);
        let b = SVector::<f64, 6>::from_fn(|r, _| entries[36 + r]);
        solve6(&m, &b);
    }

    #[test]
    fn six_by_seven_minimum_norm_matches_the_svd(
        entries in proptest::collection::vec(-2.0f64..2.0, 48)
    ) {
        let m = SMatrix::<f64, 6, 7>::from_fn(|r, c| entries[r * 7 + c]);
        let b = SVector::<f64, 6>::from_fn(|r, _| entries[42 + r]);
        // Random matrices are mostly well-conditioned; the tolerance covers cond(J) up to ~10³.
        let sigma = m.svd(false, false).singular_values;
        let cond = sigma.max() / sigma.min();
        min_norm(&m, &b, 1e-14 * cond.max(10.0) * 10.0);
    }

    #[test]
    fn four_by_four_matches_nalgebra(entries in proptest::collection::vec(-2.0f64..2.0, 20)) {
        let m = SMatrix::<f64, 4, 4>::from_fn(|r, c| entries[r * 4 + c]);
        let b = SVector::<f64, 4>::from_fn(|r, _| entries[16 + r]);
        solve4(&m, &b);
    }
}
