//! The arm in 3-D: a stick figure of a simulated serial robot (joint origins from forward
//! kinematics of the trace's `q`), its instrument shaft through the trocar, the trocar and the
//! tip's path, from two viewpoints side by side — an oblique 3-D view of the whole arm
//! (plotters' 3-D chart) and a top view (`x`–`y`, equal scales) close to the trocar. Written as a
//! still image at chosen times ([`write_snapshot`], SVG or PNG) or as an animated GIF
//! ([`write_animation`]).
//!
//! The robot is the one the trace ran ([`Trace::arm`]: a shipped scenario's robot or the
//! description a user's trajectory drove, any number of joints); the reference tip path is drawn
//! beside the tip's; the trocar marker is the point of the shaft at
//! the trace's `l_a`, the point of the link nearest the tracked trocar (they are `rcm_drift`
//! apart, the trace's measured drift).

use super::{err, register_font, write_image, Figure, PlotError};
pub use crate::simulation::ArmModel;
use crate::simulation::{Trace, TraceRow};
use nalgebra::Vector3;
use plotters::coord::ranged3d::Cartesian3d;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Size of a still image or an animation frame in pixels (two panels side by side).
pub const VIEW_SIZE: (u32, u32) = (900, 470);

/// Number of frames of an animation ([`write_animation`]) when the trace has that many rows.
pub const ANIMATION_FRAMES: usize = 50;

/// Delay between two frames of an animation, in milliseconds.
pub const FRAME_DELAY_MS: u32 = 120;

/// Most points of the drawn tip path (the trace's rows are thinned evenly to at most this).
const PATH_POINTS: usize = 1500;

/// One drawn configuration of the arm, in base coordinates (m).
#[derive(Clone, Debug, PartialEq)]
pub struct ArmPose {
    /// The stick figure: the base origin, the origin of every link frame `F_1 … F_n`, then the
    /// tool tip (`n + 2` points; joints at the same place give repeated points).
    pub points: Vec<Vector3<f64>>,
    /// The instrument shaft: the constrained link's axis from its point at `l_a = 0` to the
    /// next joint origin (the tool tip when the constrained link is the last one) or to the
    /// trocar, whichever is farther along the axis.
    pub shaft: [Vector3<f64>; 2],
    /// The trocar: the point of the shaft at `l_a`.
    pub trocar: Vector3<f64>,
    /// The tool tip, `p_0e`.
    pub tip: Vector3<f64>,
}

impl ArmModel {
    /// The arm at joint values `q` (the first [`ArmModel::dof`] entries are used) with the
    /// trocar at `l_a` along the shaft.
    ///
    /// # Panics
    /// If `q` has fewer than [`ArmModel::dof`] entries.
    pub fn pose(&self, q: &[f64], l_a: f64) -> ArmPose {
        let n = self.joints.len();
        let q = &q[..n];
        let frames = self.frames(q);
        let tip = self.tip(q).translation;
        let mut points = Vec::with_capacity(n + 2);
        points.push(Vector3::zeros());
        points.extend(frames.iter().map(|g| g.translation));
        points.push(tip);
        let g_0i = &frames[self.link - 1];
        let along = |l: f64| self.shaft.constraint_pose(g_0i, l).translation;
        let next = if self.link < n {
            frames[self.link].translation
        } else {
            tip
        };
        let end = self.shaft.offset(g_0i, &next).max(l_a);
        ArmPose {
            points,
            shaft: [along(0.0_f64.min(l_a)), along(end)],
            trocar: along(l_a),
            tip,
        }
    }

    /// The arm at a trace row.
    pub fn pose_at(&self, row: &TraceRow) -> ArmPose {
        self.pose(&row.q, row.l_a)
    }
}

/// Everything drawn of a trace, computed once: the poses of the rows and the tip path.
struct Scene<'a> {
    title: String,
    model: &'a ArmModel,
    /// Indices of the rows whose tips make the path, and the tips.
    path: Vec<(usize, Vector3<f64>)>,
    /// The reference tip positions of the same rows.
    reference: Vec<(usize, Vector3<f64>)>,
    /// Ranges of the oblique view (a cube: equal scales).
    cube: [(f64, f64); 3],
    /// Ranges of the top view near the trocar (`x`, `y`; equal scales on the panel).
    close: [(f64, f64); 2],
}

impl<'a> Scene<'a> {
    fn new(trace: &'a Trace) -> Result<Self, PlotError> {
        if trace.rows.is_empty() {
            return Err(PlotError("the trace has no rows".into()));
        }
        register_font()?;
        let model = &trace.arm;
        if model.dof() != trace.joints || trace.rows.iter().any(|r| r.q.len() != trace.joints) {
            return Err(PlotError(format!(
                "the robot has {} joints, the trace {}",
                model.dof(),
                trace.joints
            )));
        }
        let stride = trace.rows.len().div_ceil(PATH_POINTS).max(1);
        let mut path: Vec<(usize, Vector3<f64>)> = (0..trace.rows.len())
            .step_by(stride)
            .map(|k| (k, model.pose_at(&trace.rows[k]).tip))
            .collect();
        let last = trace.rows.len() - 1;
        if path.last().map(|p| p.0) != Some(last) {
            path.push((last, model.pose_at(&trace.rows[last]).tip));
        }
        // Bounds: every stick figure of a few rows and the whole path.
        let (mut lo, mut hi) = (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        );
        let (mut clo, mut chi) = (lo, hi);
        let grow = |p: &Vector3<f64>, lo: &mut Vector3<f64>, hi: &mut Vector3<f64>| {
            *lo = lo.inf(p);
            *hi = hi.sup(p);
        };
        for k in (0..trace.rows.len()).step_by(trace.rows.len().div_ceil(40).max(1)) {
            let pose = model.pose_at(&trace.rows[k]);
            for p in &pose.points {
                grow(p, &mut lo, &mut hi);
            }
            for p in pose.shaft.iter().chain([&pose.trocar, &pose.tip]) {
                grow(p, &mut clo, &mut chi);
            }
        }
        let reference: Vec<(usize, Vector3<f64>)> = path
            .iter()
            .map(|&(k, _)| (k, Vector3::from(trace.rows[k].reference)))
            .collect();
        for (_, p) in path.iter().chain(&reference) {
            grow(p, &mut lo, &mut hi);
            grow(p, &mut clo, &mut chi);
        }
        let centre = (lo + hi) / 2.0;
        let half = ((hi - lo).amax() / 2.0 * 1.08).max(0.05);
        let cube = [0, 1, 2].map(|a| (centre[a] - half, centre[a] + half));
        let ccentre = (clo + chi) / 2.0;
        let chalf = ((chi - clo).xy().amax() / 2.0 * 1.15).max(0.02);
        let close = [0, 1].map(|a| (ccentre[a] - chalf, ccentre[a] + chalf));
        Ok(Scene {
            title: match trace.scenario.map(|s| s.name()) {
                Some("panda-laparoscope") => "Panda laparoscope".to_string(),
                Some("panda-laparoscope-limits") => "Panda laparoscope, limits".to_string(),
                Some("exp421") => "experiment 4.2.1, reference arm".to_string(),
                Some(s) => format!("scenario {s}, reference arm"),
                None => trace.title.clone(),
            },
            model,
            path,
            reference,
            cube,
            close,
        })
    }

    /// The tip path up to row `upto` (inclusive).
    fn path_until(&self, upto: usize) -> Vec<Vector3<f64>> {
        until(&self.path, upto)
    }

    /// The reference path up to row `upto` (inclusive).
    fn reference_until(&self, upto: usize) -> Vec<Vector3<f64>> {
        until(&self.reference, upto)
    }
}

/// The points of `path` up to row `upto` (inclusive).
fn until(path: &[(usize, Vector3<f64>)], upto: usize) -> Vec<Vector3<f64>> {
    path.iter()
        .take_while(|(k, _)| *k <= upto)
        .map(|(_, p)| *p)
        .collect()
}

impl Scene<'_> {}

const ARM: RGBColor = RGBColor(60, 80, 120);
const SHAFT: RGBColor = RGBColor(230, 120, 0);
const TROCAR: RGBColor = RGBColor(200, 0, 0);
const PATH: RGBColor = RGBColor(30, 150, 50);
const REFERENCE: RGBColor = RGBColor(150, 60, 200);

/// The row nearest to time `t`.
fn row_at(trace: &Trace, t: f64) -> usize {
    let k = ((t - trace.rows[0].t) / trace.dt).round().max(0.0) as usize;
    k.min(trace.rows.len() - 1)
}

/// Draws the figure: the arm at `rows` (the last one solid, earlier ones faded) and the tip
/// path up to the last of them.
fn draw<DB: DrawingBackend>(
    scene: &Scene,
    trace: &Trace,
    rows: &[usize],
    root: &DrawingArea<DB, Shift>,
) -> Result<(), PlotError> {
    root.fill(&WHITE).map_err(err)?;
    let (w, h) = root.dim_in_pixel();
    let (top, rest) = root.split_vertically(30);
    let (body, legend) = rest.split_vertically(h.saturating_sub(30 + 26));
    let last = *rows.last().unwrap_or(&0);
    let times = rows
        .iter()
        .map(|&k| format!("{:.1}", trace.rows[k].t))
        .collect::<Vec<_>>()
        .join(", ");
    top.draw(&Text::new(
        format!("{} — t = {times} s", scene.title),
        (10, 6),
        ("sans-serif", 18).into_font(),
    ))
    .map_err(err)?;
    let poses: Vec<ArmPose> = rows
        .iter()
        .map(|&k| scene.model.pose_at(&trace.rows[k]))
        .collect();
    let paths = Paths {
        tip: scene.path_until(last),
        reference: scene.reference_until(last),
    };
    let (left, right) = body.split_horizontally(w / 2);
    oblique(scene, &poses, &paths, &left)?;
    top_view(scene, &poses, &paths, &right)?;
    // The legend, in the colours of the drawing.
    let font = ("sans-serif", 14).into_font();
    let mut x = 12;
    for (label, colour) in [
        ("arm (joint origins)", ARM),
        ("instrument shaft", SHAFT),
        ("trocar", TROCAR),
        ("tip path", PATH),
        ("reference", REFERENCE),
    ] {
        legend
            .draw(&PathElement::new(
                vec![(x, 12), (x + 22, 12)],
                colour.stroke_width(3),
            ))
            .map_err(err)?;
        legend
            .draw(&Text::new(label, (x + 28, 4), font.clone()))
            .map_err(err)?;
        x += 36 + 8 * label.len() as i32;
    }
    if rows.len() > 1 {
        legend
            .draw(&Text::new(
                "earlier times fainter",
                (x + 10, 4),
                font.color(&RGBColor(110, 110, 110)),
            ))
            .map_err(err)?;
    }
    Ok(())
}

/// The colour `c` faded towards white for the `k`-th of `n` poses (the last one full).
fn fade(c: RGBColor, k: usize, n: usize) -> RGBColor {
    let f = if n <= 1 {
        1.0
    } else {
        0.3 + 0.7 * k as f64 / (n - 1) as f64
    };
    let mix = |v: u8| (255.0 - (255.0 - f64::from(v)) * f) as u8;
    RGBColor(mix(c.0), mix(c.1), mix(c.2))
}

/// The tip's path and its reference, as far as drawn.
struct Paths {
    tip: Vec<Vector3<f64>>,
    reference: Vec<Vector3<f64>>,
}

/// The oblique view of the whole arm. Plotters' 3-D charts have `y` up: the chart's
/// `(x, y, z)` is the base's `(x, z, y)`, and the axes are named after the base's.
fn oblique<DB: DrawingBackend>(
    scene: &Scene,
    poses: &[ArmPose],
    paths: &Paths,
    area: &DrawingArea<DB, Shift>,
) -> Result<(), PlotError> {
    let c = |p: &Vector3<f64>| (p.x, p.z, p.y);
    let mut chart = oblique_chart(area, "oblique view (m)", scene.cube, 1)?;
    // The reference over the tip's path, thinner: where the tip follows it, a line within.
    chart
        .draw_series(LineSeries::new(
            paths.tip.iter().map(c),
            PATH.stroke_width(3),
        ))
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(
            paths.reference.iter().map(c),
            REFERENCE.stroke_width(1),
        ))
        .map_err(err)?;
    let n = poses.len();
    for (k, pose) in poses.iter().enumerate() {
        chart
            .draw_series(LineSeries::new(
                pose.points.iter().map(c),
                fade(ARM, k, n).stroke_width(3),
            ))
            .map_err(err)?;
        chart
            .draw_series(
                pose.points
                    .iter()
                    .map(|p| Circle::new(c(p), 3, fade(ARM, k, n).filled())),
            )
            .map_err(err)?;
        chart
            .draw_series(LineSeries::new(
                pose.shaft.iter().map(c),
                fade(SHAFT, k, n).stroke_width(4),
            ))
            .map_err(err)?;
        chart
            .draw_series([
                Circle::new(c(&pose.trocar), 6, fade(TROCAR, k, n).stroke_width(2)),
                Circle::new(c(&pose.trocar), 2, fade(TROCAR, k, n).filled()),
            ])
            .map_err(err)?;
    }
    Ok(())
}

/// An oblique 3-D chart of `cube` (ranges of `x`, `y`, `z`, m) with its axes, their tick labels
/// (`digits` decimals) and names drawn. Plotters' 3-D charts have `y` up: the chart's
/// `(x, y, z)` is the drawn frame's `(x, z, y)`.
pub(super) fn oblique_chart<'a, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    cube: [(f64, f64); 3],
    digits: usize,
) -> Result<
    ChartContext<'a, DB, Cartesian3d<RangedCoordf64, RangedCoordf64, RangedCoordf64>>,
    PlotError,
> {
    let [xr, yr, zr] = cube;
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 15))
        .margin(8)
        .build_cartesian_3d(xr.0..xr.1, zr.0..zr.1, yr.0..yr.1)
        .map_err(err)?;
    chart.with_projection(|mut p| {
        p.yaw = 0.75;
        p.pitch = 0.3;
        p.scale = 0.86;
        p.into_matrix()
    });
    let fmt = move |v: &f64| format!("{v:.digits$}");
    chart
        .configure_axes()
        .label_style(("sans-serif", 11))
        .x_formatter(&fmt)
        .y_formatter(&fmt)
        .z_formatter(&fmt)
        .x_labels(4)
        .y_labels(4)
        .z_labels(4)
        .max_light_lines(1)
        .light_grid_style(RGBColor(235, 235, 235))
        // Opaque (plotters' default is translucent black, which some SVG renderers draw black).
        .axis_panel_style(RGBColor(236, 236, 236))
        .draw()
        .map_err(err)?;
    // Axis names beside the edges that carry the tick labels (with this projection: `x` along
    // the far left edge, `y` along the right edge, `z` up the left edge).
    let name = ("sans-serif", 13).into_font().color(&BLACK);
    let (span, mid) = (xr.1 - xr.0, |r: (f64, f64)| (r.0 + r.1) / 2.0);
    for (label, at) in [
        ("x (m)", (mid(xr), zr.0 - 0.1 * span, yr.1 + 0.2 * span)),
        ("y (m)", (xr.1 + 0.2 * span, zr.0 - 0.1 * span, mid(yr))),
        ("z (m)", (xr.0, zr.1 + 0.12 * span, yr.1)),
    ] {
        chart
            .draw_series(std::iter::once(Text::new(label, at, name.clone())))
            .map_err(err)?;
    }
    Ok(chart)
}

/// The top view (`x`–`y`, equal scales) close to the trocar.
fn top_view<DB: DrawingBackend>(
    scene: &Scene,
    poses: &[ArmPose],
    paths: &Paths,
    area: &DrawingArea<DB, Shift>,
) -> Result<(), PlotError> {
    let [xr, yr] = scene.close;
    // Equal scales: the plotting area is made square.
    let (w, h) = area.dim_in_pixel();
    let side = (w as i32 - 70).min(h as i32 - 50).max(50) as u32;
    let (area, _) = area.split_horizontally(side + 70);
    let (area, _) = area.split_vertically(side + 50);
    let mut chart = ChartBuilder::on(&area)
        .caption("top view near the trocar", ("sans-serif", 15))
        .margin_right(14)
        .margin_top(4)
        .x_label_area_size(34)
        .y_label_area_size(56)
        .build_cartesian_2d(xr.0..xr.1, yr.0..yr.1)
        .map_err(err)?;
    let digits = if xr.1 - xr.0 < 0.1 { 3 } else { 2 };
    let fmt = move |v: &f64| format!("{v:.digits$}");
    chart
        .configure_mesh()
        .x_desc("x (m)")
        .y_desc("y (m)")
        .x_labels(5)
        .y_labels(5)
        .label_style(("sans-serif", 11))
        .axis_desc_style(("sans-serif", 13))
        .x_label_formatter(&fmt)
        .y_label_formatter(&fmt)
        .light_line_style(RGBColor(240, 240, 240))
        .draw()
        .map_err(err)?;
    let c = |p: &Vector3<f64>| (p.x, p.y);
    // Plotters pins points outside the chart to its border: lines are clipped here instead.
    let clipped = |points: &[Vector3<f64>], style: ShapeStyle| {
        points
            .windows(2)
            .filter_map(|w| clip((c(&w[0]), c(&w[1])), xr, yr))
            .map(|(a, b)| PathElement::new(vec![a, b], style))
            .collect::<Vec<_>>()
    };
    chart
        .draw_series(clipped(&paths.tip, PATH.stroke_width(3)))
        .map_err(err)?;
    chart
        .draw_series(clipped(&paths.reference, REFERENCE.stroke_width(1)))
        .map_err(err)?;
    let n = poses.len();
    for (k, pose) in poses.iter().enumerate() {
        chart
            .draw_series(clipped(&pose.points, fade(ARM, k, n).stroke_width(3)))
            .map_err(err)?;
        chart
            .draw_series(clipped(&pose.shaft, fade(SHAFT, k, n).stroke_width(4)))
            .map_err(err)?;
        chart
            .draw_series([
                Circle::new(c(&pose.tip), 3, fade(PATH, k, n).filled()),
                Circle::new(c(&pose.trocar), 6, fade(TROCAR, k, n).stroke_width(2)),
                Circle::new(c(&pose.trocar), 2, fade(TROCAR, k, n).filled()),
            ])
            .map_err(err)?;
    }
    Ok(())
}

/// The part of the segment `(a, b)` inside the rectangle `x × y` (Liang–Barsky), if any.
fn clip(
    (a, b): ((f64, f64), (f64, f64)),
    x: (f64, f64),
    y: (f64, f64),
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0_f64, 1.0_f64);
    for (p, q) in [
        (-dx, a.0 - x.0),
        (dx, x.1 - a.0),
        (-dy, a.1 - y.0),
        (dy, y.1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else if p < 0.0 {
            t0 = t0.max(q / p);
        } else {
            t1 = t1.min(q / p);
        }
    }
    (t0 <= t1).then(|| {
        let at = |t: f64| (a.0 + t * dx, a.1 + t * dy);
        (at(t0), at(t1))
    })
}

/// The default times of a still image: the start, the middle and the end of the trace.
pub fn default_snapshot_times(trace: &Trace) -> Vec<f64> {
    let (t0, t1) = (
        trace.rows.first().map_or(0.0, |r| r.t),
        trace.rows.last().map_or(0.0, |r| r.t),
    );
    vec![t0, (t0 + t1) / 2.0, t1]
}

/// Writes a still image of the arm at `times` (s; each drawn at the nearest row; the last
/// solid, earlier ones fainter) with the tip path up to the last of them, from two viewpoints.
/// The format follows the extension (`.svg` or `.png`). Errors for a time outside the trace.
pub fn write_snapshot(
    trace: &Trace,
    path: impl AsRef<Path>,
    times: &[f64],
) -> Result<(), PlotError> {
    let path = path.as_ref();
    let scene = Scene::new(trace)?;
    let end = trace.rows.last().map_or(0.0, |r| r.t);
    let mut rows = Vec::with_capacity(times.len());
    for &t in times {
        if !(t >= trace.rows[0].t - trace.dt / 2.0 && t <= end + trace.dt / 2.0) {
            return Err(PlotError(format!(
                "time {t} s is outside the trace (0 to {end} s)"
            )));
        }
        rows.push(row_at(trace, t));
    }
    if rows.is_empty() {
        return Err(PlotError("no time to draw".into()));
    }
    rows.sort_unstable();
    rows.dedup();
    write_image(
        path,
        VIEW_SIZE,
        &Snapshot {
            scene: &scene,
            trace,
            rows: &rows,
        },
    )
}

/// A still of the arm at some rows of a trace ([`draw`]).
struct Snapshot<'a> {
    scene: &'a Scene<'a>,
    trace: &'a Trace,
    rows: &'a [usize],
}

impl Figure for Snapshot<'_> {
    fn draw_on<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), PlotError> {
        draw(self.scene, self.trace, self.rows, root)
    }
}

/// The rows an animation of `frames` frames shows: evenly spaced from the first row to the
/// last (fewer when the trace has fewer rows).
pub fn animation_rows(trace: &Trace, frames: usize) -> Vec<usize> {
    let n = trace.rows.len();
    let frames = frames.min(n).max(1);
    if frames == 1 {
        return vec![n.saturating_sub(1)];
    }
    (0..frames)
        .map(|f| (f * (n - 1) + (frames - 1) / 2) / (frames - 1))
        .collect()
}

/// Writes an animated GIF of the arm over the trace: [`animation_rows`] frames, each with the
/// tip path so far, from two viewpoints; `progress` is called with the fraction done.
pub fn write_animation(
    trace: &Trace,
    path: impl AsRef<Path>,
    frames: usize,
    mut progress: impl FnMut(f64),
) -> Result<(), PlotError> {
    let scene = Scene::new(trace)?;
    let rows = animation_rows(trace, frames);
    let root = BitMapBackend::gif(path.as_ref(), VIEW_SIZE, FRAME_DELAY_MS)
        .map_err(|e| PlotError(super::bitmap_message(&e)))?
        .into_drawing_area();
    for (f, &k) in rows.iter().enumerate() {
        draw(&scene, trace, &[k], &root)?;
        root.present().map_err(super::backend_err)?;
        progress((f + 1) as f64 / rows.len() as f64);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulation::{self, Scenario, ScenarioConfig, L_A0, Q0};
    use nalgebra::SVector;
    use trocar_model::description::RobotDescription;
    use trocar_model::numeric::NumericModel;

    fn short_run(scenario: Scenario, duration: f64) -> Trace {
        let mut config = ScenarioConfig::new(scenario);
        config.duration = duration;
        simulation::run(&config, |_| {}).expect("the scenario runs")
    }

    /// The reference arm's joint origins at `q = (q1, 0, …, 0)`, read off its description
    /// (`dia10_like_zy.toml`: every joint frame aligned with the base at zero) and turned by
    /// the torso about `z`.
    #[test]
    fn stick_figure_is_the_joint_origins() {
        let d = RobotDescription::preset("dia10_like_zy").unwrap();
        let model =
            ArmModel::from_model(&NumericModel::from_description(&d, &[]).unwrap()).unwrap();
        assert_eq!(model.dof(), 8);
        let q1 = 0.3_f64;
        let mut q = [0.0; 8];
        q[0] = q1;
        let pose = model.pose(&q, L_A0);
        let at_zero = [
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            [0.194, 0.0, 1.037],
            [0.194, 0.38, 1.037],
            [0.194, 0.38, 1.037],
            [0.194, 0.77, 1.037],
            [0.194, 0.77, 1.037],
            [0.194, 1.10, 1.037],
            [0.194, 1.10, 1.037],
            [0.194, 1.31, 1.037],
        ];
        assert_eq!(pose.points.len(), at_zero.len());
        let (s, c) = q1.sin_cos();
        for (p, e) in pose.points.iter().zip(at_zero) {
            let expected = Vector3::new(c * e[0] - s * e[1], s * e[0] + c * e[1], e[2]);
            assert!((p - expected).norm() < 1e-12, "{p} vs {expected}");
        }
        // The trocar is on link 6 at l_a from F_6, along y_6; the shaft runs to F_7.
        let f6 = Vector3::new(c * 0.194 - s * 0.77, s * 0.194 + c * 0.77, 1.037);
        let y6 = Vector3::new(-s, c, 0.0);
        assert!((pose.trocar - (f6 + y6 * L_A0)).norm() < 1e-12);
        assert!((pose.shaft[0] - f6).norm() < 1e-12);
        assert!((pose.shaft[1] - (f6 + y6 * 0.33)).norm() < 1e-12);
    }

    /// Distance from `p` to the segment `[a, b]`.
    fn to_segment(p: &Vector3<f64>, [a, b]: &[Vector3<f64>; 2]) -> f64 {
        let d = b - a;
        let s = ((p - a).dot(&d) / d.norm_squared()).clamp(0.0, 1.0);
        (p - (a + d * s)).norm()
    }

    /// Scenario 2 keeps the trocar where link 6 was at `l_a = 0.15` at `q0`: every drawn shaft
    /// passes through that point, and the drawn tip is the typed chain's forward kinematics.
    #[test]
    fn drawn_shaft_passes_through_the_fixed_trocar() {
        let trace = short_run(Scenario::S2, 2.0);
        let model = &trace.arm;
        let d = RobotDescription::preset("dia10_like_zy").unwrap();
        let chain = NumericModel::<f64>::from_description(&d, &[])
            .unwrap()
            .to_chain::<8>()
            .unwrap();
        let g6 = chain.link_frame(6, &SVector::from(Q0));
        let trocar = g6.translation + g6.rotation.column(1) * L_A0;
        let moved = trace.rows.last().unwrap();
        assert!(
            (moved.q[0] - Q0[0]).abs() + (moved.q[2] - Q0[2]).abs() > 1e-3,
            "the arm moves"
        );
        for row in trace.rows.iter().step_by(50) {
            let pose = model.pose_at(row);
            assert!(to_segment(&trocar, &pose.shaft) < 1e-6, "t = {}", row.t);
            assert!((pose.trocar - trocar).norm() < 1e-6, "t = {}", row.t);
            let tip = chain
                .forward_kinematics(&SVector::from_column_slice(&row.q))
                .translation;
            assert!((pose.points.last().unwrap() - tip).norm() < 1e-12);
            assert_eq!(pose.tip, *pose.points.last().unwrap());
        }
    }

    /// The Panda's shaft is its last link: it runs from the flange through the trocar to the tip.
    #[test]
    fn panda_shaft_reaches_the_tip_through_the_trocar() {
        let trace = short_run(Scenario::Panda, 0.5);
        let model = &trace.arm;
        for row in trace.rows.iter().step_by(40) {
            let pose = model.pose_at(row);
            assert!((pose.shaft[1] - pose.tip).norm() < 1e-9);
            assert!(to_segment(&pose.trocar, &pose.shaft) < 1e-12);
            assert!(row.rcm_drift < 1e-6);
        }
    }

    fn temp(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("trocar-view3d-{}-{name}", std::process::id()))
    }

    #[test]
    fn animation_has_the_requested_frames() {
        let trace = short_run(Scenario::S4, 0.2);
        let path = temp("anim.gif");
        let mut reported = Vec::new();
        write_animation(&trace, &path, 7, |f| reported.push(f)).unwrap();
        let file = std::fs::File::open(&path).unwrap();
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::Indexed);
        let mut decoder = options.read_info(file).unwrap();
        assert_eq!(
            (u32::from(decoder.width()), u32::from(decoder.height())),
            VIEW_SIZE
        );
        let mut frames = 0;
        while let Some(frame) = decoder.read_next_frame().unwrap() {
            assert_eq!(frame.delay, (FRAME_DELAY_MS / 10) as u16);
            frames += 1;
        }
        std::fs::remove_file(&path).unwrap();
        assert_eq!(frames, 7);
        assert_eq!(reported.len(), 7);
        assert_eq!(reported.last(), Some(&1.0));
    }

    #[test]
    fn clip_keeps_the_part_inside() {
        let unit = (0.0, 1.0);
        assert_eq!(
            clip(((-1.0, 0.5), (2.0, 0.5)), unit, unit),
            Some(((0.0, 0.5), (1.0, 0.5)))
        );
        assert_eq!(clip(((-1.0, 2.0), (2.0, 2.0)), unit, unit), None);
        assert_eq!(
            clip(((0.2, 0.3), (0.4, 0.5)), unit, unit),
            Some(((0.2, 0.3), (0.4, 0.5)))
        );
        let ((x0, y0), (x1, y1)) = clip(((0.5, -1.0), (0.5, 0.5)), unit, unit).unwrap();
        assert_eq!((x0, y0, x1, y1), (0.5, 0.0, 0.5, 0.5));
    }

    #[test]
    fn animation_rows_span_the_trace() {
        let trace = short_run(Scenario::S4, 0.2);
        let n = trace.rows.len();
        let rows = animation_rows(&trace, 7);
        assert_eq!(rows.len(), 7);
        assert_eq!((rows[0], rows[6]), (0, n - 1));
        assert!(rows.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(animation_rows(&trace, 10 * n).len(), n);
    }

    #[test]
    fn snapshot_is_written_and_refuses_times_outside_the_trace() {
        let trace = short_run(Scenario::S4, 0.2);
        let png = temp("still.png");
        write_snapshot(&trace, &png, &default_snapshot_times(&trace)).unwrap();
        let bytes = std::fs::read(&png).unwrap();
        std::fs::remove_file(&png).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        let e = write_snapshot(&trace, temp("late.png"), &[0.0, 5.0]).unwrap_err();
        assert!(e.0.contains("time 5 s is outside the trace"), "{e}");
        assert!(!temp("late.png").exists());
    }
}
