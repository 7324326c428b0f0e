//! `trocar simulate --plot`: a figure is written for a serial scenario and for each kind of
//! closed chain, with plain tick labels and the last time label inside the figure.

mod common;

use common::trocar;

/// `(x, text)` of every text element of an SVG written by plotters.
fn texts(svg: &str) -> Vec<(f64, String)> {
    svg.split("<text")
        .skip(1)
        .map(|t| {
            let x = t
                .split("x=\"")
                .nth(1)
                .and_then(|r| r.split('"').next())
                .and_then(|v| v.parse().ok())
                .unwrap_or(f64::NAN);
            let body = t.split_once('>').map_or("", |(_, b)| b);
            let body = body.split("</text>").next().unwrap_or("").trim();
            (x, body.to_string())
        })
        .collect()
}

fn figure(scenario: &str) -> Vec<(f64, String)> {
    let dir = std::env::temp_dir().join(format!("trocar-plot-labels-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("{scenario}.svg"));
    let (code, _, err) = trocar(&["simulate", scenario, "--plot", path.to_str().unwrap()]);
    assert_eq!(code, 0, "{scenario}: {err}");
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg"), "{scenario}");
    texts(&svg)
}

/// Numeric labels are plain decimals or `2.5e-8` without padding zeros (`1.400e1`, `0.000e0`
/// and stray `2.168e-19` were the old labels).
fn assert_plain(scenario: &str, labels: &[(f64, String)]) {
    let numbers: Vec<&String> = labels
        .iter()
        .map(|(_, l)| l)
        .filter(|l| l.parse::<f64>().is_ok())
        .collect();
    assert!(numbers.len() > 10, "{scenario}: {numbers:?}");
    for l in numbers {
        if let Some((m, e)) = l.split_once('e') {
            assert!(
                !m.ends_with('0') && !m.ends_with('.') && e != "0",
                "{scenario}: label {l}"
            );
            let e: i32 = e.parse().unwrap();
            assert!(!(-3..5).contains(&e), "{scenario}: {l} could be a decimal");
        }
    }
}

#[test]
fn serial_scenario_figure_has_plain_labels_and_nothing_cut_off() {
    let labels = figure("4");
    assert_plain("4", &labels);
    // Scenario 4 runs 200 s: the rightmost "200" label is centred well inside the 1600 px width.
    let right = labels
        .iter()
        .filter(|(_, l)| l == "200")
        .map(|(x, _)| *x)
        .fold(0.0, f64::max);
    assert!(
        right > 1400.0 && right < 1600.0 - 25.0,
        "x of `200`: {right}"
    );
}

#[test]
fn closed_chain_figures_have_plain_labels() {
    for scenario in ["four-bar", "stewart", "cooperative"] {
        let labels = figure(scenario);
        assert_plain(scenario, &labels);
        assert!(
            labels.iter().any(|(_, l)| l == "10"),
            "{scenario}: no `10` s label"
        );
    }
}
