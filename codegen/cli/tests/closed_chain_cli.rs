//! Closed mechanisms through the command line: `trocar generate` and `trocar eval` on a mechanism
//! TOML, and their errors.

mod common;

use common::{json_matrix, trocar};
use trocar_sim::closed_chain::four_bar::FourBar;

#[test]
fn cli_generate_mechanism() {
    let (code, out, err) = trocar(&["generate", "runtime/model/robots/mechanisms/four-bar.toml"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("pub mod four_bar {"));
    assert!(out.contains("pub fn passive_velocities<T: ::trocar::emitted::Real>("));
    let (code, out, err) = trocar(&["generate", "planar-stewart", "--real", "f32"]);
    assert_eq!(code, 0, "{err}");
    let flat: String = out.split_whitespace().collect::<Vec<_>>().join(" ");
    assert!(flat.contains("pub fn reduced_jacobian( q: &[f32; N], p: &Params, )"));
    let (code, out, err) = trocar(&[
        "generate",
        "runtime/model/robots/mechanisms/cooperative-arms.toml",
    ]);
    assert_eq!(code, 1);
    assert!(out.is_empty());
    assert!(err.contains("cooperative-arms.toml"), "{err}");
    assert!(err.contains("chains"), "{err}");
    assert!(err.contains("square"), "{err}");
}

/// `trocar eval` on a mechanism: the generated closed form and `--numeric` (the runtime) agree,
/// and `jr` is `dφ/dθ1` of the closed-form output map (finite differences).
#[test]
fn cli_eval_mechanism() {
    let fb = FourBar::SOURCE;
    let theta1 = 1.3;
    let t = fb.configuration(theta1).unwrap();
    let q = format!("{},{},{},{}", t[0], t[1], t[2], t[3]);
    let h = 1e-6;
    let fd =
        (fb.orientation(theta1 + h).unwrap() - fb.orientation(theta1 - h).unwrap()) / (2.0 * h);
    for what in ["jr", "passive", "jc", "det"] {
        let (c1, gen, e1) = trocar(&["eval", "four-bar", "--q", &q, "--what", what, "--json"]);
        let (c2, num, e2) = trocar(&[
            "eval",
            "four-bar",
            "--q",
            &q,
            "--what",
            what,
            "--json",
            "--numeric",
        ]);
        assert_eq!((c1, c2), (0, 0), "{e1}{e2}");
        let (a, b) = (json_matrix(&gen).2, json_matrix(&num).2);
        assert_eq!(a.len(), b.len());
        for (ra, rb) in a.iter().zip(&b) {
            for (x, y) in ra.iter().zip(rb) {
                assert!(
                    (x - y).abs() <= 1e-12 * y.abs().max(1.0),
                    "{what}: {x} vs {y}"
                );
            }
        }
        if what == "jr" {
            assert!((a[0][0] - fd).abs() < 1e-8, "{} vs {fd}", a[0][0]);
        }
    }
    // Parameters are inputs of the generated code; --numeric rebuilds the mechanism with them.
    let (_, gen, _) = trocar(&["eval", "four-bar", "--q", &q, "--param", "l4=0.9", "--json"]);
    let (_, num, _) = trocar(&[
        "eval",
        "four-bar",
        "--q",
        &q,
        "--param",
        "l4=0.9",
        "--json",
        "--numeric",
    ]);
    assert!((json_matrix(&gen).2[0][0] - json_matrix(&num).2[0][0]).abs() < 1e-12);
    // Errors.
    let (code, _, err) = trocar(&["eval", "four-bar", "--q", "1,2,3"]);
    assert_eq!(code, 1);
    assert!(err.contains("4 joints"), "{err}");
    let (code, _, err) = trocar(&["eval", "four-bar", "--q", &q, "--what", "fk"]);
    assert_eq!(code, 1);
    assert!(err.contains("not defined for a closed mechanism"), "{err}");
    let (code, _, err) = trocar(&["eval", "four-bar", "--q", "0,0,0,0"]);
    assert_eq!(code, 1);
    assert!(err.contains("singular"), "{err}");
    let (code, _, err) = trocar(&["verify", "four-bar"]);
    assert_eq!(code, 1);
    assert!(err.contains("closed mechanism"), "{err}");
}
