//! The serial chain in **product form**: forward kinematics `T_1 ⋯ T_n g_ne` from the per-joint
//! transforms ([`Derivation::joint_transforms`], composed as (2.21)), and each body-Jacobian
//! column `Ad⁻¹_{g_ke} ξ_k = (R_keᵀ (v_k + ω_k × p_ke), R_keᵀ ω_k)` (2.45) from the suffix
//! products `g_ke = T_{k+1} ⋯ T_n g_ne`, walked from the end of the chain. The per-joint
//! transforms are those of the turned link frames ([`Derivation::frame_turns`]): a product that
//! starts or ends at a link turns there ([`Derivation::frame_turn`],
//! [`Derivation::turned_back`]). Also which chains the runtime can walk with the rows of the
//! homogeneous transform as pairs ([`paired_heads`]).

use super::poly::{cross, new_program, rot_t_apply, NumTransform, PolyBuilder};
use crate::derivation::Derivation;
use crate::ir::{Program, ValueId};
use crate::symbolic::{Poly, Transform};

/// Forward kinematics of the first `upto` joints (then `tail`, if given), product form.
pub(super) fn fk_product_program(d: &Derivation, upto: usize, tail: Option<&Transform>) -> Program {
    let mut prog = new_program(d);
    let acc = chain_product(d, &mut prog, 0..upto, tail);
    prog.set_outputs(acc.outputs());
    prog
}

/// The product `T_a ⋯ T_b` of the joints `range` (0-based), then `tail` if given (in the
/// description's frame of the last link), built into `prog` left to right (2.21); the identity
/// when both are empty. Turned link frames ([`Derivation::frame_turns`]) are turned back at both
/// ends.
pub(super) fn chain_product(
    d: &Derivation,
    prog: &mut Program,
    range: std::ops::Range<usize>,
    tail: Option<&Transform>,
) -> NumTransform {
    let head = d.frame_turn(range.start).cloned();
    let end = d.turned_back(range.end, tail);
    let mut b = PolyBuilder::new(prog);
    let mut factors: Vec<NumTransform> = head.iter().map(|t| b.transform(t)).collect();
    factors.extend(d.joint_transforms[range].iter().map(|t| b.transform(t)));
    if let Some(t) = &end {
        factors.push(b.transform(t));
    }
    let mut acc = match factors.first() {
        Some(&f) => f,
        None => b.transform(&Transform::identity()),
    };
    for f in factors.iter().skip(1) {
        acc = acc.compose(f, prog);
    }
    acc
}

/// Body Jacobian of the chain `joints[..upto]` then `tail` (`J^B_0e` with `tail = g_ne`,
/// `J^B_0i` with `upto = i` and no tail), product form.
pub(super) fn body_jacobian_product_program(
    d: &Derivation,
    upto: usize,
    tail: Option<&Transform>,
) -> Program {
    let mut prog = new_program(d);
    let (cols, _) = body_jacobian_walk(d, &mut prog, upto, tail);
    prog.set_outputs(cols.into_iter().flatten().collect());
    prog
}

/// The columns `Ad⁻¹_{g_ke} ξ_k` (2.45) of the body Jacobian of `joints[..upto]` then `tail`, built
/// into `prog` by walking the chain from its end: `g_ke` is the suffix product
/// `T_{k+1} ⋯ T_upto · tail`, so the walk ends with the whole product `T_1 ⋯ T_upto · tail`, which
/// is returned beside the columns (`g_0i` for `J^B_0i`).
pub(super) fn body_jacobian_walk(
    d: &Derivation,
    prog: &mut Program,
    upto: usize,
    tail: Option<&Transform>,
) -> (Vec<[ValueId; 6]>, NumTransform) {
    let mut b = PolyBuilder::new(prog);
    let joints: Vec<NumTransform> = d.joint_transforms[..upto]
        .iter()
        .map(|t| b.transform(t))
        .collect();
    let twists: Vec<([ValueId; 3], [ValueId; 3])> = d.twists[..upto]
        .iter()
        .map(|x| {
            let v = [
                b.poly(x.get(0, 0)),
                b.poly(x.get(1, 0)),
                b.poly(x.get(2, 0)),
            ];
            let w = [
                b.poly(x.get(3, 0)),
                b.poly(x.get(4, 0)),
                b.poly(x.get(5, 0)),
            ];
            (v, w)
        })
        .collect();
    // In the description's frame of link `upto` (a turned frame turned back), then `tail`.
    let mut g = match d.turned_back(upto, tail) {
        Some(t) => b.transform(&t),
        None => b.transform(&Transform::identity()),
    };
    let mut cols = vec![[ValueId(0); 6]; upto];
    for k in (0..upto).rev() {
        // g = g_ke: F_k → F_e.
        let (v, w) = &twists[k];
        let wxp = cross(prog, w, &g.pos);
        let mut lin_in = [ValueId(0); 3];
        for i in 0..3 {
            lin_in[i] = prog.add(v[i], wxp[i]);
        }
        let lin = rot_t_apply(prog, &g.rot, &lin_in);
        let ang = rot_t_apply(prog, &g.rot, w);
        cols[k] = [lin[0], lin[1], lin[2], ang[0], ang[1], ang[2]];
        g = joints[k].compose(&g, prog);
    }
    (cols, g)
}

/// The heads `Trans(o_k) R_x(roll_k)` of joints `1..=upto`, base first, as `(roll in quarter
/// turns, o)`, when the chain up to link `upto` is one of right-angle joints: every joint turns
/// about the `z` axis of its link frame, `T_k = Trans(o_k) R_x(roll_k) R_z(q_k)` with a constant
/// `o_k` and `roll_k` one of `0`, `+π/2`, `−π/2` (modified Denavit–Hartenberg with right-angle
/// twists, as the Panda), and no frame up to link `upto` is turned. `None` otherwise.
///
/// Such a chain's `g_0i` and `J^B_0i` can be walked with the rows of the homogeneous transform
/// as pairs (`trocar::emitted::paired_rows`). A joint about `−z` (twist `(0, −ẑ)`) is not taken.
pub fn paired_heads(d: &Derivation, upto: usize) -> Option<Vec<(i8, [f64; 3])>> {
    if upto == 0 || d.turned_back(upto, None).is_some() {
        return None;
    }
    let z_twist: Vec<Poly> = [0, 0, 0, 0, 0, 1].map(Poly::integer).to_vec();
    (0..upto)
        .map(|k| {
            if d.joint_is_linear[k]
                || d.frame_turns[k].is_some()
                || d.twists[k].entries() != z_twist.as_slice()
            {
                return None;
            }
            let t = &d.joint_transforms[k];
            let (c, s) = (Poly::cos(k), Poly::sin(k));
            let (zero, one) = (Poly::zero(), Poly::one());
            // Row 1 of R_x(roll) R_z(q) is (c, −s, 0) for every roll; rows 2 and 3 tell it.
            let rz = [
                [c.clone(), s.neg(), zero.clone()],
                [s.clone(), c.clone(), zero.clone()],
                [zero.clone(), zero.clone(), one.clone()],
            ];
            let neg = |r: &[Poly; 3]| [r[0].neg(), r[1].neg(), r[2].neg()];
            let candidates = [
                (0i8, [rz[0].clone(), rz[1].clone(), rz[2].clone()]),
                (1, [rz[0].clone(), neg(&rz[2]), rz[1].clone()]),
                (-1, [rz[0].clone(), rz[2].clone(), neg(&rz[1])]),
            ];
            let roll = candidates.into_iter().find_map(|(roll, rows)| {
                let fits = (0..3).all(|i| (0..3).all(|j| t.rot.get(i, j) == &rows[i][j]));
                fits.then_some(roll)
            })?;
            let mut o = [0.0; 3];
            for (i, x) in o.iter_mut().enumerate() {
                *x = t.pos.get(i, 0).as_constant()?.to_f64();
            }
            Some((roll, o))
        })
        .collect()
}
