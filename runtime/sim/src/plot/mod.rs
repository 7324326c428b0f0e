//! Plots (SVG/PNG) of simulation traces, with plotters: the thesis's figure set of a scenario in
//! one six-panel figure — position/orientation error, RCM velocities, manipulability of `J^r_0e`
//! and `J^B_0i`, `l_a` and `q7`, joint velocities, and the distance of the trocar from the link.

pub mod axis;
pub mod scene_view;
pub mod view3d;

use crate::simulation::Trace;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
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

/// The bitmap backend's error type (PNG and GIF files).
type BitmapError = <BitMapBackend<'static> as DrawingBackend>::ErrorType;

/// A bitmap backend's error in words: the I/O or encoder error's own message (the backend's
/// `Display` is its debug form, `ImageError(IoError(Os { code: 28, … }))`).
pub(crate) fn bitmap_message(e: &BitmapError) -> String {
    match e {
        BitmapError::IOError(io) => io.to_string(),
        BitmapError::ImageError(i) => format!("the PNG encoder: {i}"),
        BitmapError::GifEncodingError(g) => format!("the GIF encoder: {g}"),
        BitmapError::InvalidBuffer => "the pixel buffer has the wrong size".to_string(),
    }
}

/// A drawing error of any backend in words ([`bitmap_message`] for bitmaps).
pub(crate) fn backend_message<E: std::error::Error + Send + Sync + 'static>(
    e: &DrawingAreaErrorKind<E>,
) -> String {
    use plotters_backend::DrawingErrorKind;
    match e {
        DrawingAreaErrorKind::BackendError(DrawingErrorKind::DrawingError(b)) => {
            match (b as &dyn std::any::Any).downcast_ref::<BitmapError>() {
                Some(bitmap) => bitmap_message(bitmap),
                None => b.to_string(),
            }
        }
        DrawingAreaErrorKind::BackendError(DrawingErrorKind::FontError(f)) => {
            format!("the font: {f}")
        }
        other => other.to_string(),
    }
}

/// [`backend_message`] as a [`PlotError`].
pub(crate) fn backend_err<E: std::error::Error + Send + Sync + 'static>(
    e: DrawingAreaErrorKind<E>,
) -> PlotError {
    PlotError(backend_message(&e))
}

/// Size of the figure in pixels.
pub const SIZE: (u32, u32) = (1600, 1500);

/// The image formats figures are written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// SVG (vector).
    Svg,
    /// PNG (bitmap).
    Png,
}

impl ImageFormat {
    /// The format a file name asks for by its extension, `.svg` or `.png` in either case.
    pub fn of(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?;
        if ext.eq_ignore_ascii_case("svg") {
            Some(ImageFormat::Svg)
        } else if ext.eq_ignore_ascii_case("png") {
            Some(ImageFormat::Png)
        } else {
            None
        }
    }
}

/// A picture drawn on any plotters backend, which [`write_image`] writes as SVG or PNG.
pub(crate) trait Figure {
    /// Draws the picture on `root`.
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError>;
}

/// Writes `figure` at `size` pixels to `path`, in the format its extension names
/// ([`ImageFormat::of`]).
pub(crate) fn write_image(
    path: &Path,
    size: (u32, u32),
    figure: &impl Figure,
) -> Result<(), PlotError> {
    match ImageFormat::of(path) {
        Some(ImageFormat::Svg) => {
            let root = SVGBackend::new(path, size).into_drawing_area();
            figure.draw_on(&root)?;
            root.present().map_err(backend_err)
        }
        Some(ImageFormat::Png) => {
            let root = BitMapBackend::new(path, size).into_drawing_area();
            figure.draw_on(&root)?;
            root.present().map_err(backend_err)
        }
        None => Err(PlotError(format!(
            "{}: expected a .svg or .png file name",
            path.display()
        ))),
    }
}

/// The six-panel figure of one trace ([`draw`]).
struct TraceFigure<'a>(&'a Trace);

impl Figure for TraceFigure<'_> {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        draw(self.0, root)
    }
}

/// Writes the figure of a trace; the format follows the extension (`.svg` or `.png`, either
/// case).
pub fn write_figure(trace: &Trace, path: impl AsRef<Path>) -> Result<(), PlotError> {
    write_image(path.as_ref(), SIZE, &TraceFigure(trace))
}

/// Writes the figure as SVG.
pub fn write_svg(trace: &Trace, path: impl AsRef<Path>) -> Result<(), PlotError> {
    let root = SVGBackend::new(path.as_ref(), SIZE).into_drawing_area();
    draw(trace, &root)?;
    root.present().map_err(backend_err)
}

/// Writes the figure as PNG.
pub fn write_png(trace: &Trace, path: impl AsRef<Path>) -> Result<(), PlotError> {
    let root = BitMapBackend::new(path.as_ref(), SIZE).into_drawing_area();
    draw(trace, &root)?;
    root.present().map_err(backend_err)
}

/// Size in pixels of the figure of [`write_comparison`] (two rows of two panels).
pub const COMPARISON_SIZE: (u32, u32) = (1600, 1100);

/// Writes one figure comparing runs of one scenario with different methods (the thesis's
/// Figure 4.28: pinv vs DLS vs FI): the title names the methods ("pinv vs DLS vs FI") and each
/// panel overlays the runs in one colour each, with a legend above the data — the
/// end-effector position error `|dp - p|`, the RCM drift, the manipulability `w_r` and the
/// peak joint speed `max_k |qd_k|`. The format follows the extension (`.svg` or `.png`).
///
/// Refused when `traces` is empty or the runs are of different scenarios or drift corrections.
pub fn write_comparison(traces: &[&Trace], path: impl AsRef<Path>) -> Result<(), PlotError> {
    check_comparison(traces)?;
    write_image(path.as_ref(), COMPARISON_SIZE, &Comparison(traces))
}

/// One panel of [`write_time_panels`]: lines over the time `t (s)`, each
/// `(legend, t, y)` with as many `y` as `t`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TimePanel {
    /// Title above the panel.
    pub title: String,
    /// y-axis label, with its unit.
    pub y_label: String,
    /// `(legend, t, y)` of each line.
    pub lines: Vec<(String, Vec<f64>, Vec<f64>)>,
    /// Whether the y axis starts at 0.
    pub non_negative: bool,
}

/// Writes `panels` in two columns under `title`, as SVG or PNG by the extension of `path`
/// (the figures of runs whose columns come from elsewhere, such as a physics plant's).
pub fn write_time_panels(
    path: impl AsRef<Path>,
    title: &str,
    panels: &[TimePanel],
) -> Result<(), PlotError> {
    if panels.is_empty() {
        return Err(PlotError("a figure needs at least one panel".into()));
    }
    for p in panels {
        if let Some((label, ..)) = p.lines.iter().find(|(_, t, y)| t.len() != y.len()) {
            return Err(PlotError(format!(
                "panel `{}`, line `{label}`: as many values as times",
                p.title
            )));
        }
    }
    let rows = panels.len().div_ceil(2);
    let size = (1600, 80 + 520 * rows as u32);
    write_image(path.as_ref(), size, &Panels { title, panels })
}

/// The figure of [`write_time_panels`].
struct Panels<'a> {
    title: &'a str,
    panels: &'a [TimePanel],
}

impl Figure for Panels<'_> {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        register_font()?;
        root.fill(&WHITE).map_err(err)?;
        let root = root.titled(self.title, ("sans-serif", 28)).map_err(err)?;
        let rows = self.panels.len().div_ceil(2);
        let areas = root.split_evenly((rows, 2));
        for (area, p) in areas.iter().zip(self.panels) {
            let lines = p
                .lines
                .iter()
                .map(|(label, t, y)| Line {
                    label: label.clone(),
                    x: t.clone(),
                    y: y.clone(),
                })
                .collect();
            time_panel(area, &p.title, &p.y_label, p.non_negative, lines)?;
        }
        Ok(())
    }
}

/// The comparison figure of several runs ([`draw_comparison`]).
struct Comparison<'a>(&'a [&'a Trace]);

impl Figure for Comparison<'_> {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        draw_comparison(self.0, root)
    }
}

/// The runs of a comparison: at least one, all of one scenario and drift correction.
fn check_comparison(traces: &[&Trace]) -> Result<(), PlotError> {
    let Some(first) = traces.first() else {
        return Err(PlotError("a comparison needs at least one run".into()));
    };
    if let Some(other) = traces
        .iter()
        .find(|t| t.scenario != first.scenario || t.title != first.title)
    {
        return Err(PlotError(format!(
            "a comparison draws runs of one scenario (got {} and {})",
            first.scenario.map_or(first.title.as_str(), |s| s.name()),
            other.scenario.map_or(other.title.as_str(), |s| s.name())
        )));
    }
    if traces
        .iter()
        .any(|t| t.drift_correction != first.drift_correction)
    {
        return Err(PlotError(
            "a comparison draws runs with one drift correction (on or off)".into(),
        ));
    }
    Ok(())
}

/// The font sizes of the trace figures ([`draw`], [`draw_comparison`]).
const TRACE_FONTS: Fonts = Fonts {
    title: 22,
    text: 17,
};

/// The title of a trace figure: the scenario, the method(s) and the drift correction.
fn figure_title(trace: &Trace, methods: &str) -> String {
    format!(
        "{} - {}, drift correction {}",
        trace.title,
        methods,
        if trace.drift_correction { "on" } else { "off" }
    )
}

/// A panel of a trace figure: lines over the time `t (s)`.
fn time_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    title: &str,
    y_label: &str,
    non_negative: bool,
    lines: Vec<Line>,
) -> Result<(), PlotError> {
    draw_panel(
        area,
        &Panel2d {
            title,
            x_label: "t (s)",
            y_label,
            lines,
            non_negative,
        },
        TRACE_FONTS,
    )
}

/// The name of a method in a comparison's title and legends (the thesis's spelling).
fn method_label(method: crate::simulation::Method) -> &'static str {
    match method {
        crate::simulation::Method::Pinv => "pinv",
        crate::simulation::Method::Dls => "DLS",
        crate::simulation::Method::Fi => "FI",
        crate::simulation::Method::Qp => "QP",
    }
}

/// Draws the comparison figure of [`write_comparison`] on a drawing area.
pub fn draw_comparison<DB: DrawingBackend>(
    traces: &[&Trace],
    root: &DrawingArea<DB, Shift>,
) -> Result<(), PlotError> {
    check_comparison(traces)?;
    register_font()?;
    root.fill(&WHITE).map_err(err)?;
    let methods: Vec<&str> = traces.iter().map(|t| method_label(t.method)).collect();
    let root = root
        .titled(
            &figure_title(traces[0], &methods.join(" vs ")),
            ("sans-serif", 28),
        )
        .map_err(err)?;
    let panels = root.split_evenly((2, 2));
    let panel = |area: &DrawingArea<DB, Shift>,
                 title: &str,
                 y_label: &str,
                 f: &dyn Fn(&crate::simulation::TraceRow) -> f64| {
        let lines = traces
            .iter()
            .map(|t| Line {
                label: method_label(t.method).to_string(),
                x: t.rows.iter().map(|r| r.t).collect(),
                y: t.rows.iter().map(f).collect(),
            })
            .collect();
        time_panel(area, title, y_label, true, lines)
    };
    panel(
        &panels[0],
        "(a) end-effector position error |dp - p|",
        "|e_p| (m)",
        &|r| r.ep_norm,
    )?;
    panel(
        &panels[1],
        "(b) distance trocar - link axis (rcm_drift)",
        "distance (m)",
        &|r| r.rcm_drift,
    )?;
    panel(
        &panels[2],
        "(c) manipulability of the task w_r",
        "w_r (-)",
        &|r| r.w_r,
    )?;
    panel(
        &panels[3],
        "(d) peak joint speed max_k |qd_k|",
        "max |qd_k| (rad/s)",
        &|r| r.qd.iter().fold(0.0, |m: f64, v| m.max(v.abs())),
    )?;
    Ok(())
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

/// One line of a panel: its legend, x and y values.
pub(crate) struct Line {
    /// Legend text.
    pub label: String,
    /// x values.
    pub x: Vec<f64>,
    /// y values (as many as `x`).
    pub y: Vec<f64>,
}

/// A panel of a 2-D figure.
pub(crate) struct Panel2d<'a> {
    /// Title, above the legend.
    pub title: &'a str,
    /// x-axis label, with its unit.
    pub x_label: &'a str,
    /// y-axis label, with its unit.
    pub y_label: &'a str,
    /// The lines.
    pub lines: Vec<Line>,
    /// The y axis starts at 0 (or is logarithmic where the values span decades): norms,
    /// distances, manipulabilities.
    pub non_negative: bool,
}

/// Font sizes (pixels) of a figure's panels.
#[derive(Clone, Copy)]
pub(crate) struct Fonts {
    /// Panel title.
    pub title: u32,
    /// Legend, tick labels and axis labels.
    pub text: u32,
}

/// At most this many points of a line are drawn (evenly spaced rows), which keeps SVGs small.
const MAX_POINTS: usize = 4000;

/// Draws one panel: the title on top, the legend under it (outside the data, wrapped onto as
/// many rows as it needs), then the chart with round ticks and plain labels ([`axis::Axis`])
/// and margins that keep the last tick label inside the panel.
pub(crate) fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel2d<'_>,
    fonts: Fonts,
) -> Result<(), PlotError> {
    let (w, _) = area.dim_in_pixel();
    let text = ("sans-serif", fonts.text).into_font();
    // Legend layout: entries left to right, wrapped.
    let sample = 28i32;
    let row_h = fonts.text as i32 + 8;
    let mut placed = Vec::new();
    let (mut x, mut row) = (16i32, 0i32);
    for (k, line) in panel.lines.iter().enumerate() {
        let tw = area
            .estimate_text_size(&line.label, &TextStyle::from(text.clone()))
            .map_err(err)?
            .0 as i32;
        let width = sample + 6 + tw + 22;
        if x > 16 && x + width > w as i32 - 16 {
            (x, row) = (16, row + 1);
        }
        placed.push((k, x, row));
        x += width;
    }
    let rows = if panel.lines.is_empty() { 0 } else { row + 1 };
    let title_h = fonts.title as i32 + 16;
    let top_h = title_h + rows * row_h + 4;
    let (top, body) = area.split_vertically(top_h);
    top.draw(&Text::new(
        panel.title.to_string(),
        (w as i32 / 2, 8),
        ("sans-serif", fonts.title)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Center, VPos::Top)),
    ))
    .map_err(err)?;
    for (k, x, row) in placed {
        let color = COLORS[k % COLORS.len()];
        let y = title_h + row * row_h + row_h / 2;
        top.draw(&PathElement::new(
            vec![(x, y), (x + sample, y)],
            color.stroke_width(3),
        ))
        .map_err(err)?;
        top.draw(&Text::new(
            panel.lines[k].label.clone(),
            (x + sample + 6, y),
            text.color(&BLACK).pos(Pos::new(HPos::Left, VPos::Center)),
        ))
        .map_err(err)?;
    }

    let finite = |l: &Line| {
        l.x.iter()
            .zip(&l.y)
            .filter(|(a, b)| a.is_finite() && b.is_finite())
            .map(|(&a, &b)| (a, b))
            .collect::<Vec<_>>()
    };
    let points: Vec<Vec<(f64, f64)>> = panel.lines.iter().map(finite).collect();
    let bounds = |f: fn(&(f64, f64)) -> f64| {
        points
            .iter()
            .flatten()
            .map(f)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            })
    };
    let (x0, x1) = bounds(|p| p.0);
    let (y0, y1) = bounds(|p| p.1);
    let x_axis = axis::Axis::linear(x0, x1, 6);
    let y_axis = if panel.non_negative {
        axis::Axis::non_negative(points.iter().flatten().map(|p| p.1), 6)
    } else {
        axis::Axis::linear(y0, y1, 6)
    };
    let mut builder = ChartBuilder::on(&body);
    builder
        .margin_left(8)
        .margin_top(8)
        .margin_bottom(4)
        // The last x label is centred on the right edge of the plot: room for half of it.
        .margin_right(48)
        .x_label_area_size(fonts.text * 3)
        .y_label_area_size(fonts.text * 6);
    let x_range = Ticked::new(RangedCoordf64::from(x_axis.lo..x_axis.hi), &x_axis);
    if y_axis.log {
        let y_range = Ticked::new(
            LogCoord::<f64>::from((y_axis.lo..y_axis.hi).log_scale()),
            &y_axis,
        );
        let chart = builder.build_cartesian_2d(x_range, y_range).map_err(err)?;
        // A logarithmic axis shows the positive values.
        let points = points
            .into_iter()
            .map(|p| {
                p.into_iter()
                    .filter(|q| q.1 > 0.0)
                    .map(|(x, y)| (x, y.max(y_axis.lo)))
                    .collect()
            })
            .collect();
        draw_chart(chart, panel, fonts, &x_axis, &y_axis, points)
    } else {
        let y_range = Ticked::new(RangedCoordf64::from(y_axis.lo..y_axis.hi), &y_axis);
        let chart = builder.build_cartesian_2d(x_range, y_range).map_err(err)?;
        draw_chart(chart, panel, fonts, &x_axis, &y_axis, points)
    }
}

/// A coordinate whose ticks are those of an [`axis::Axis`] (plotters' own choice of ticks on
/// `f64` ranges gives labels such as `2.168e-19`).
pub(crate) struct Ticked<R: Ranged<ValueType = f64>> {
    inner: R,
    ticks: Vec<f64>,
}

impl<R: Ranged<ValueType = f64>> Ticked<R> {
    fn new(inner: R, axis: &axis::Axis) -> Self {
        Ticked {
            inner,
            ticks: axis.ticks.clone(),
        }
    }
}

impl<R: Ranged<ValueType = f64>> Ranged for Ticked<R> {
    type ValueType = f64;
    type FormatOption = DefaultFormatting;

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn axis_pixel_range(&self, limit: (i32, i32)) -> std::ops::Range<i32> {
        self.inner.axis_pixel_range(limit)
    }
}

/// The mesh, the axis labels and the lines of a panel on its chart.
fn draw_chart<DB: DrawingBackend, Y>(
    mut chart: ChartContext<'_, DB, Cartesian2d<Ticked<RangedCoordf64>, Ticked<Y>>>,
    panel: &Panel2d<'_>,
    fonts: Fonts,
    x_axis: &axis::Axis,
    y_axis: &axis::Axis,
    points: Vec<Vec<(f64, f64)>>,
) -> Result<(), PlotError>
where
    Y: Ranged<ValueType = f64>,
{
    let x_fmt = |v: &f64| x_axis.label(*v);
    let y_fmt = |v: &f64| y_axis.label(*v);
    chart
        .configure_mesh()
        .x_desc(panel.x_label)
        .y_desc(panel.y_label)
        .label_style(("sans-serif", fonts.text))
        .axis_desc_style(("sans-serif", fonts.text))
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .bold_line_style(RGBColor(225, 225, 225))
        .draw()
        .map_err(err)?;
    let (sx, sy) = (
        (x_axis.hi - x_axis.lo).max(f64::MIN_POSITIVE),
        if y_axis.log {
            1.0
        } else {
            (y_axis.hi - y_axis.lo).max(f64::MIN_POSITIVE)
        },
    );
    let scaled = |p: (f64, f64)| (p.0 / sx, if y_axis.log { p.1.log10() } else { p.1 / sy });
    for (k, pts) in points.into_iter().enumerate() {
        let color = COLORS[k % COLORS.len()];
        let stride = (pts.len() / MAX_POINTS).max(1);
        let last = pts.last().copied();
        let pts: Vec<(f64, f64)> = pts
            .iter()
            .copied()
            .step_by(stride)
            .chain(last.filter(|_| stride > 1))
            .collect();
        // A thick polyline that turns back on itself is drawn with miter joins that shoot far
        // out of the panel (chattering joint velocities): such a line is drawn as several
        // paths, split where it turns by more than 90 degrees.
        let mut paths: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
        for (i, &p) in pts.iter().enumerate() {
            if i >= 2 {
                let (a, b, c) = (scaled(pts[i - 2]), scaled(pts[i - 1]), scaled(p));
                if (b.0 - a.0) * (c.0 - b.0) + (b.1 - a.1) * (c.1 - b.1) < 0.0 {
                    paths.push(vec![pts[i - 1]]);
                }
            }
            if let Some(path) = paths.last_mut() {
                path.push(p);
            }
        }
        chart
            .draw_series(
                paths
                    .into_iter()
                    .map(|path| PathElement::new(path, color.stroke_width(2))),
            )
            .map_err(err)?;
    }
    Ok(())
}

/// The most joints whose velocities get a line each in the figure of a trace; a robot with more
/// gets the largest and the smallest joint velocity at each time.
pub const MAX_JOINT_LINES: usize = 12;

/// The joint drawn with `l_a` (0-based): q7 in a shipped scenario; in a user's run the joint
/// that comes closest to its limit, or the last joint when the robot has no limits.
fn drawn_joint(trace: &Trace) -> usize {
    let n = trace.joints.max(1);
    if trace.scenario.is_some() && n >= 7 {
        return 6;
    }
    let Some(limits) = &trace.joint_limits else {
        return n - 1;
    };
    (0..n.min(limits.len()))
        .map(|k| {
            let [lo, hi] = limits[k];
            let margin = trace
                .rows
                .iter()
                .map(|r| (r.q[k] - lo).min(hi - r.q[k]))
                .fold(f64::INFINITY, f64::min);
            (k, margin)
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(n - 1, |(k, _)| k)
}

/// Draws the six panels of a trace on a drawing area.
pub fn draw<DB: DrawingBackend>(
    trace: &Trace,
    root: &DrawingArea<DB, Shift>,
) -> Result<(), PlotError> {
    register_font()?;
    root.fill(&WHITE).map_err(err)?;
    let root = root
        .titled(
            &figure_title(trace, trace.method.name()),
            ("sans-serif", 28),
        )
        .map_err(err)?;
    let panels = root.split_evenly((3, 2));
    let rows = &trace.rows;
    let t: Vec<f64> = rows.iter().map(|r| r.t).collect();
    let col =
        |f: &dyn Fn(&crate::simulation::TraceRow) -> f64| rows.iter().map(f).collect::<Vec<_>>();
    let panel = |area: &DrawingArea<DB, Shift>,
                 title: &str,
                 y_label: &str,
                 non_negative: bool,
                 series: Vec<(String, Vec<f64>)>| {
        let lines = series
            .into_iter()
            .map(|(label, y)| Line {
                label,
                x: t.clone(),
                y,
            })
            .collect();
        time_panel(area, title, y_label, non_negative, lines)
    };
    panel(
        &panels[0],
        "(a) end-effector errors",
        "|e_p| (m), |eps| (-)",
        true,
        vec![
            ("|dp - p| (m)".into(), col(&|r| r.ep_norm)),
            ("|eps| (quaternion)".into(), col(&|r| r.eo_norm)),
        ],
    )?;
    let [a, b] = trace.lateral_axes;
    panel(
        &panels[1],
        "(b) lateral velocity of the shaft at the trocar (F_r)",
        "v (m/s)",
        false,
        vec![
            (format!("v along {a}"), col(&|r| r.vr[0])),
            (format!("v along {b}"), col(&|r| r.vr[1])),
            (format!("commanded {a}"), col(&|r| r.dv_cmd[0])),
            (format!("commanded {b}"), col(&|r| r.dv_cmd[1])),
        ],
    )?;
    panel(
        &panels[2],
        "(c) manipulability",
        "w (-)",
        true,
        vec![
            ("w_r (S J^r_0e, the task)".into(), col(&|r| r.w_r)),
            ("w_i (J^B_0i)".into(), col(&|r| r.w_i)),
        ],
    )?;
    // The limits the QP step keeps, as constant lines: l_a's bounds and the drawn joint's range
    // with l_a and that joint, the joint speed limits with the joint velocities. The drawn
    // joint is q7 in a shipped scenario (the reference arm's J^r is singular at q7 = 0);
    // in a user's run, the joint that comes closest to its limit (the last joint when the
    // robot has no limits), with its range.
    let flat = |v: f64| vec![v; t.len()];
    let joint = drawn_joint(trace);
    let name = format!("q{}", joint + 1);
    let mut la_q = vec![
        ("l_a (m)".into(), col(&|r| r.l_a)),
        (format!("{name} (rad)"), col(&|r| r.q[joint])),
    ];
    if let Some([lo, hi]) = trace.depth_limits {
        la_q.push((format!("l_max = {hi} m"), flat(hi)));
        la_q.push((format!("l_min = {lo} m"), flat(lo)));
    }
    if trace.depth_limits.is_some() || trace.scenario.is_none() {
        if let Some([lo, hi]) = trace
            .joint_limits
            .as_ref()
            .and_then(|l| l.get(joint).copied())
        {
            la_q.push((format!("{name} max = {hi:.4} rad"), flat(hi)));
            la_q.push((format!("{name} min = {lo:.4} rad"), flat(lo)));
        }
    }
    panel(
        &panels[3],
        &format!("(d) l_a and {name}"),
        &format!("l_a (m), {name} (rad)"),
        false,
        la_q,
    )?;
    // One line a joint up to MAX_JOINT_LINES joints; beyond, the envelope over the joints.
    let mut qd: Vec<(String, Vec<f64>)> = if trace.joints <= MAX_JOINT_LINES {
        (0..trace.joints)
            .map(|k| (format!("qd{}", k + 1), col(&|r| r.qd[k])))
            .collect()
    } else {
        vec![
            (
                format!("max over the {} joints", trace.joints),
                col(&|r| r.qd.iter().copied().fold(f64::NEG_INFINITY, f64::max)),
            ),
            (
                format!("min over the {} joints", trace.joints),
                col(&|r| r.qd.iter().copied().fold(f64::INFINITY, f64::min)),
            ),
        ]
    };
    if let Some(speeds) = &trace.speed_limits {
        let mut distinct: Vec<f64> = speeds.clone();
        distinct.sort_by(f64::total_cmp);
        distinct.dedup();
        for v in distinct {
            qd.push((format!("+{v} rad/s (limit)"), flat(v)));
            qd.push((format!("-{v} rad/s (limit)"), flat(-v)));
        }
    }
    panel(&panels[4], "(e) joint velocities", "qd (rad/s)", false, qd)?;
    panel(
        &panels[5],
        "(f) distance trocar - link axis (rcm_drift)",
        "distance (m)",
        true,
        vec![("rcm_drift".into(), col(&|r| r.rcm_drift))],
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::{self, Method, Scenario, ScenarioConfig};

    fn short_run(scenario: Scenario, method: Method) -> Trace {
        let mut config = ScenarioConfig::new(scenario).with_method(method);
        config.duration = 0.2;
        simulation::run(&config, |_| {}).expect("the scenario runs")
    }

    /// A trace of a 64-joint chain (the most a description may have; axes x, y, z in turn,
    /// 0.1 m apart along y, the constraint on the last link): its figure and its views of the
    /// arm are drawn, the joint velocities as their envelope, the drawn joint the one that
    /// comes closest to its limit.
    #[test]
    fn a_trace_of_64_joints_is_drawn() {
        use crate::simulation::{ArmModel, StepRecord};
        use nalgebra::Vector3;
        use trocar_model::description::RobotDescription;
        use trocar_model::numeric::NumericModel;
        let n = trocar_model::description::MAX_JOINTS;
        let axes = ["[0, 1, 0]", "[0, 0, 1]", "[1, 0, 0]"];
        let mut text = String::from("[robot]\nname = \"long\"\n\n[parameters]\nl_a = 0.05\n\n");
        for k in 0..n {
            text += &format!(
                "[[joints]]\nname = \"j{}\"\ntype = \"revolute\"\nxyz = [0, 0.1, 0]\naxis = {}\nlimits = [-1, 1]\n\n",
                k + 1,
                axes[k % 3]
            );
        }
        text += "[end_effector]\nname = \"tool\"\nxyz = [0, 0.1, 0]\n\n[constraint]\nlink = 64\nxyz = [0, \"l_a\", 0]\nh = [\"x\", \"z\"]\n\n[task]\nselect = [\"x\", \"y\", \"z\", \"ry\"]\n";
        let d = RobotDescription::from_toml_str(&text, None).unwrap();
        let arm = ArmModel::from_model(&NumericModel::from_description(&d, &[]).unwrap()).unwrap();
        assert_eq!(arm.dof(), n);
        // Joint 40 swings to 0.9 rad (0.1 from its limit), the others to 0.02 k / 64.
        let dt = 0.01;
        let q_at = |t: f64| -> Vec<f64> {
            (0..n)
                .map(|k| {
                    if k == 39 {
                        0.9 * t
                    } else {
                        0.02 * t * k as f64 / n as f64
                    }
                })
                .collect()
        };
        let qd: Vec<f64> = (0..n)
            .map(|k| {
                if k == 39 {
                    0.9
                } else {
                    0.02 * k as f64 / n as f64
                }
            })
            .collect();
        let g0 = arm.link_frame(&q_at(0.0));
        let trocar = g0.translation + g0.rotation.column(1) * 0.05;
        let rows = (0..=100)
            .map(|s| {
                let t = s as f64 * dt;
                let q = q_at(t);
                arm.measure(&StepRecord {
                    t,
                    q: &q,
                    qd: &qd,
                    dt,
                    trocar: &trocar,
                    position: &Vector3::zeros(),
                    rotation: None,
                    w_r: 1.0,
                    w_i: 1.0,
                    kappa_r: 0.0,
                    dv_cmd: [0.0; 2],
                })
            })
            .collect();
        let trace = Trace {
            scenario: None,
            title: "long along a path".into(),
            arm,
            method: crate::simulation::Method::Dls,
            drift_correction: true,
            constrained_directions: 2,
            dt,
            joints: n,
            lateral_axes: ["x_r", "z_r"],
            joint_limits: Some(vec![[-1.0, 1.0]; n]),
            speed_limits: None,
            depth_limits: None,
            rows,
        };
        assert_eq!(drawn_joint(&trace), 39);
        let dir = std::env::temp_dir().join(format!("trocar-long-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        write_figure(&trace, dir.join("long.svg")).unwrap();
        let svg = std::fs::read_to_string(dir.join("long.svg")).unwrap();
        for words in [
            "(d) l_a and q40",
            "max over the 64 joints",
            "min over the 64 joints",
            "q40 max = 1.0000 rad",
        ] {
            assert!(svg.contains(words), "{words}");
        }
        assert!(!svg.contains(">\nqd1\n<"), "one line a joint");
        view3d::write_snapshot(&trace, dir.join("long-still.svg"), &[0.0, 1.0]).unwrap();
        let still = std::fs::read_to_string(dir.join("long-still.svg")).unwrap();
        assert!(still.contains("long along a path"));
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn comparison_is_written_for_three_methods_and_refused_otherwise() {
        let runs: Vec<Trace> = [Method::Pinv, Method::Dls, Method::Fi]
            .into_iter()
            .map(|m| short_run(Scenario::S1, m))
            .collect();
        let refs: Vec<&Trace> = runs.iter().collect();
        let dir = std::env::temp_dir().join(format!("trocar-comparison-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("cmp.svg");
        write_comparison(&refs, &path).expect("three runs of one scenario");
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.contains("pinv vs DLS vs FI"), "title");
        for name in ["pinv", "DLS", "FI"] {
            let legend = format!(">\n{name}\n</text>");
            assert_eq!(
                svg.matches(&legend).count(),
                4,
                "legend {name} in each panel"
            );
        }

        let none: Vec<&Trace> = Vec::new();
        let e = write_comparison(&none, dir.join("none.svg")).unwrap_err();
        assert!(e.0.contains("at least one run"), "{e}");
        assert!(!dir.join("none.svg").exists());

        let other = short_run(Scenario::S2, Method::Dls);
        let mixed = [&runs[0], &other];
        let e = write_comparison(&mixed, dir.join("mixed.svg")).unwrap_err();
        assert!(e.0.contains("one scenario"), "{e}");
        assert!(!dir.join("mixed.svg").exists());
        std::fs::remove_dir_all(&dir).ok();
    }

    /// An encoder's error is its message, not the debug form of the backend's error
    /// (`ImageError(IoError(Os { code: 2, kind: NotFound, … }))`).
    #[test]
    fn image_errors_are_in_words() {
        let run = short_run(Scenario::S1, Method::Dls);
        let missing = std::env::temp_dir()
            .join(format!("trocar-missing-{}", std::process::id()))
            .join("fig.png");
        let e = write_figure(&run, &missing).unwrap_err().to_string();
        assert!(e.contains("No such file or directory"), "{e}");
        assert!(!e.contains("Os {") && !e.contains("ImageError("), "{e}");
        let e = view3d::write_animation(&run, missing.with_extension("gif"), 2, |_| {})
            .unwrap_err()
            .to_string();
        assert!(!e.contains("Os {") && !e.contains("IOError("), "{e}");
    }
}
