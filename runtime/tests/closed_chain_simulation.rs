//! The source's simulations (§6, Figures 4 and 5) and the cooperating arms: tracking errors
//! converge; traces are written as CSV and SVG.

use trocar::closed_chain::{simulate, SimOptions};

fn max_abs_after(tr: &trocar::closed_chain::Trace, col: &str, t0: f64) -> f64 {
    let t = tr.column("t").unwrap();
    let c = tr.column(col).unwrap();
    t.iter()
        .zip(&c)
        .filter(|(t, _)| **t >= t0)
        .map(|(_, v)| v.abs())
        .fold(0.0, f64::max)
}

#[test]
fn explore() {
    for name in [
        "four-bar",
        "four-bar-sine",
        "stewart",
        "cooperative",
        "cooperative-gripped",
    ] {
        let mut calls = 0;
        let mut cb = |_f: f64| calls += 1;
        let tr = simulate(name, &SimOptions::default(), Some(&mut cb)).unwrap();
        let errs: Vec<String> = tr
            .columns
            .iter()
            .filter(|c| c.starts_with("e_"))
            .map(|c| {
                format!(
                    "{c}: final {:.3e} max(t>1) {:.3e} max {:.3e}",
                    tr.last(c).unwrap(),
                    max_abs_after(&tr, c, 1.0),
                    max_abs_after(&tr, c, 0.0)
                )
            })
            .collect();
        println!(
            "{name}: {errs:?} constraint max {:.3e} sigma_min_jcp min {:.3e} calls {calls}",
            max_abs_after(&tr, "constraint", 0.0),
            tr.column("sigma_min_jcp")
                .unwrap_or_default()
                .iter()
                .cloned()
                .fold(f64::INFINITY, f64::min)
        );
        tr.plot_svg(format!("/tmp/cc_{name}.svg")).unwrap();
        tr.plot_png(format!("/tmp/cc_{name}.png")).unwrap();
        tr.write_csv(format!("/tmp/cc_{name}.csv")).unwrap();
    }
}
