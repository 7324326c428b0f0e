//! Plots (SVG/PNG) of simulation traces, with plotters: the thesis's figure set of a scenario in
//! one six-panel figure — position/orientation error, RCM velocities, manipulability of `J^r_0e`
//! and `J^B_0i`, `l_a` and `q7`, joint velocities, and the distance of the trocar from the link.

pub mod view3d;

use crate::simulation::Trace;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// The font the figures use (DejaVu Sans, free licence: `DejaVuSans-LICENSE.txt` next to this
/// file), embedded so that figures render the same everywhere.
static FONT: &[u8] = include_bytes!("DejaVuSans.ttf");

/// Registers the embedded font as plotters' `sans-serif` family (once; later calls are free).
pub(crate) fn register_font() -> Result<(), PlotError> {
    static ONCE: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let ok = *ONCE.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT).is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(PlotError("cannot load the embedded font".into()))
    }
}

/// Why a figure could not be written.
#[derive(Debug)]
pub struct PlotError(pub String);

impl core::fmt::Display for PlotError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "plot: {}", self.0)
    }
}

impl std::error::Error for PlotError {}

fn err(e: impl core::fmt::Display) -> PlotError {
    PlotError(e.to_string())
}

/// Size of the figure in pixels.
pub const SIZE: (u32, u32) = (1600, 1500);

/// Writes the figure of a trace; the format follows the extension (`.svg` or `.png`).
pub fn write_figure(trace: &Trace, path: impl AsRef<Path>) -> Result<(), PlotError> {
    let path = path.as_ref();
    match path.extension().and_then(|e| e.to_str()) {
        Some("svg") => write_svg(trace, path),
        Some("png") => write_png(trace, path),
        _ => Err(PlotError(format!(
            "{}: expected a .svg or .png file name",
            path.display()
        ))),
    }
}

/// Writes the figure as SVG.
pub fn write_svg(trace: &Trace, path: impl AsRef<Path>) -> Result<(), PlotError> {
    let root = SVGBackend::new(path.as_ref(), SIZE).into_drawing_area();
    draw(trace, &root)?;
    root.present().map_err(err)
}

/// Writes the figure as PNG.
pub fn write_png(trace: &Trace, path: impl AsRef<Path>) -> Result<(), PlotError> {
    let root = BitMapBackend::new(path.as_ref(), SIZE).into_drawing_area();
    draw(trace, &root)?;
    root.present().map_err(err)
}

const COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

/// One panel: named series over time, with a y label.
fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    ylabel: &str,
    t: &[f64],
    series: &[(&str, Vec<f64>)],
) -> Result<(), PlotError> {
    let t_end = t.last().copied().unwrap_or(1.0).max(1e-9);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for (_, ys) in series {
        for &y in ys.iter().filter(|y| y.is_finite()) {
            lo = lo.min(y);
            hi = hi.max(y);
        }
    }
    if !lo.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05)
        .max(hi.abs().max(lo.abs()) * 1e-3)
        .max(1e-12);
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(90)
        .build_cartesian_2d(0.0..t_end, (lo - pad)..(hi + pad))
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("t (s)")
        .y_desc(ylabel)
        .label_style(("sans-serif", 16))
        .y_label_formatter(&|v| format!("{v:.3e}"))
        .draw()
        .map_err(err)?;
    // At most ~4000 points per series keep the SVG small.
    let stride = (t.len() / 4000).max(1);
    for (k, (name, ys)) in series.iter().enumerate() {
        let color = COLORS[k % COLORS.len()];
        chart
            .draw_series(LineSeries::new(
                t.iter()
                    .zip(ys.iter())
                    .step_by(stride)
                    .filter(|(_, y)| y.is_finite())
                    .map(|(&x, &y)| (x, y)),
                color.stroke_width(2),
            ))
            .map_err(err)?
            .label(*name)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(3))
            });
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(err)?;
    Ok(())
}

/// Draws the six panels of a trace on a drawing area.
pub fn draw<DB: DrawingBackend>(
    trace: &Trace,
    root: &DrawingArea<DB, Shift>,
) -> Result<(), PlotError> {
    register_font()?;
    root.fill(&WHITE).map_err(err)?;
    let title = format!(
        "{} - {}, drift correction {}",
        trace.scenario.title(),
        trace.method.name(),
        if trace.drift_correction { "on" } else { "off" }
    );
    let root = root.titled(&title, ("sans-serif", 28)).map_err(err)?;
    let panels = root.split_evenly((3, 2));
    let rows = &trace.rows;
    let t: Vec<f64> = rows.iter().map(|r| r.t).collect();
    let col =
        |f: &dyn Fn(&crate::simulation::TraceRow) -> f64| rows.iter().map(f).collect::<Vec<_>>();
    panel(
        &panels[0],
        "(a) end-effector errors",
        "|e_p| (m), |eps|",
        &t,
        &[
            ("|dp - p| (m)", col(&|r| r.ep_norm)),
            ("|eps| (quaternion)", col(&|r| r.eo_norm)),
        ],
    )?;
    let [a, b] = trace.lateral_axes;
    let (va, vb) = (format!("v along {a}"), format!("v along {b}"));
    let (ca, cb) = (format!("commanded {a}"), format!("commanded {b}"));
    panel(
        &panels[1],
        "(b) lateral velocity of the link at the trocar (F_r)",
        "m/s",
        &t,
        &[
            (va.as_str(), col(&|r| r.vr[0])),
            (vb.as_str(), col(&|r| r.vr[1])),
            (ca.as_str(), col(&|r| r.dv_cmd[0])),
            (cb.as_str(), col(&|r| r.dv_cmd[1])),
        ],
    )?;
    panel(
        &panels[2],
        "(c) manipulability",
        "w",
        &t,
        &[
            ("w_r (S J^r_0e, the task)", col(&|r| r.w_r)),
            ("w_i (J^B_0i)", col(&|r| r.w_i)),
        ],
    )?;
    panel(
        &panels[3],
        "(d) l_a and q7",
        "m, rad",
        &t,
        &[("l_a (m)", col(&|r| r.l_a)), ("q7 (rad)", col(&|r| r.q[6]))],
    )?;
    let qd: Vec<(String, Vec<f64>)> = (0..trace.joints)
        .map(|k| (format!("qd{}", k + 1), col(&|r| r.qd[k])))
        .collect();
    let qd_ref: Vec<(&str, Vec<f64>)> = qd.iter().map(|(n, v)| (n.as_str(), v.clone())).collect();
    panel(&panels[4], "(e) joint velocities", "rad/s", &t, &qd_ref)?;
    panel(
        &panels[5],
        "(f) distance trocar - link axis (rcm_drift)",
        "m",
        &t,
        &[("rcm_drift", col(&|r| r.rcm_drift))],
    )?;
    Ok(())
}
