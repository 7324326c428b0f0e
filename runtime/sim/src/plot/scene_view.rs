//! A scene of several arms in 3-D ([`crate::scene`]), as an animated GIF over its run
//! ([`write_scene_animation`]): on the left the whole scene (every arm's stick figure from its
//! base, its instrument's shaft and its port), on the right a close view of the body's side of the
//! ports — each shaft from its port to its tip, the tips' paths so far and, for every coupled
//! pair, the shortest segment between their shafts, the closest pair's in red with its length.

use super::view3d::{oblique_chart, ArmPose, ANIMATION_FRAMES, FRAME_DELAY_MS, VIEW_SIZE};
use super::{backend_err, bitmap_message, err, register_font, PlotError};
use crate::closed_chain::MechanismTrace;
use crate::scene::SceneGeometry;
use nalgebra::Vector3;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use trocar::distance::segment_distance;

/// The arms' colours, in the scene's order (then again).
const COLOURS: [RGBColor; 4] = [
    RGBColor(40, 90, 170),
    RGBColor(200, 110, 0),
    RGBColor(40, 140, 70),
    RGBColor(140, 60, 170),
];
const PORT: RGBColor = RGBColor(200, 0, 0);
const CLOSEST: RGBColor = RGBColor(220, 0, 0);
const PAIR: RGBColor = RGBColor(150, 150, 150);

/// Writes an animated GIF of the scene over its trace: [`ANIMATION_FRAMES`] frames evenly over
/// the rows (or `frames`), each with the tips' paths so far; `progress` gets the fraction done.
pub fn write_scene_animation(
    trace: &MechanismTrace,
    geometry: &SceneGeometry,
    path: impl AsRef<Path>,
    frames: usize,
    mut progress: impl FnMut(f64),
) -> Result<(), PlotError> {
    let drawn = Drawn::new(trace, geometry)?;
    let n = trace.rows.len();
    let frames = frames.clamp(1, n);
    let rows: Vec<usize> = if frames == 1 {
        vec![n - 1]
    } else {
        (0..frames).map(|f| f * (n - 1) / (frames - 1)).collect()
    };
    let root = BitMapBackend::gif(path.as_ref(), VIEW_SIZE, FRAME_DELAY_MS)
        .map_err(|e| PlotError(bitmap_message(&e)))?
        .into_drawing_area();
    for (f, &k) in rows.iter().enumerate() {
        drawn.frame(trace, k, &root)?;
        root.present().map_err(backend_err)?;
        progress((f + 1) as f64 / rows.len() as f64);
    }
    Ok(())
}

/// The default number of frames of [`write_scene_animation`].
pub const SCENE_FRAMES: usize = ANIMATION_FRAMES;

/// What every frame shares: the arms' poses at the rows drawn of the tips' paths, and the two
/// views' ranges.
struct Drawn<'a> {
    geometry: &'a SceneGeometry,
    /// Every arm's tip at each of `path_rows`.
    paths: Vec<Vec<Vector3<f64>>>,
    path_rows: Vec<usize>,
    /// Ranges of the whole scene and of the close view (cubes: equal scales).
    whole: [(f64, f64); 3],
    close: [(f64, f64); 3],
}

impl<'a> Drawn<'a> {
    fn new(trace: &MechanismTrace, geometry: &'a SceneGeometry) -> Result<Self, PlotError> {
        if trace.rows.is_empty() {
            return Err(PlotError("the trace has no rows".into()));
        }
        let width = trace.columns.len();
        if let Some(arm) = geometry
            .arms
            .iter()
            .find(|a| a.joints.iter().any(|&j| j >= width))
        {
            return Err(PlotError(format!(
                "the trace has {width} columns, fewer than the {} arm's joints need",
                arm.name
            )));
        }
        register_font()?;
        let n = trace.rows.len();
        let path_rows: Vec<usize> = (0..n).step_by(n.div_ceil(400).max(1)).collect();
        let paths: Vec<Vec<Vector3<f64>>> = geometry
            .arms
            .iter()
            .map(|a| {
                path_rows
                    .iter()
                    .map(|&k| a.pose(&trace.rows[k]).tip)
                    .collect()
            })
            .collect();
        let mut whole = Bounds::new();
        let mut close = Bounds::new();
        for k in (0..n).step_by(n.div_ceil(40).max(1)) {
            for arm in &geometry.arms {
                let pose = arm.pose(&trace.rows[k]);
                pose.points.iter().for_each(|p| whole.grow(p));
                close.grow(&pose.trocar);
                close.grow(&pose.tip);
            }
        }
        for p in paths.iter().flatten() {
            whole.grow(p);
            close.grow(p);
        }
        Ok(Drawn {
            geometry,
            paths,
            path_rows,
            whole: whole.cube(1.08, 0.05),
            close: close.cube(1.15, 0.02),
        })
    }

    /// The frame at row `k`.
    fn frame<DB: DrawingBackend>(
        &self,
        trace: &MechanismTrace,
        k: usize,
        root: &DrawingArea<DB, Shift>,
    ) -> Result<(), PlotError> {
        root.fill(&WHITE).map_err(err)?;
        let (w, h) = root.dim_in_pixel();
        let (top, rest) = root.split_vertically(30);
        let (body, legend) = rest.split_vertically(h.saturating_sub(30 + 26));
        let row = &trace.rows[k];
        let poses: Vec<ArmPose> = self.geometry.arms.iter().map(|a| a.pose(row)).collect();
        // Every coupled pair's shortest segment between the shafts inside the body.
        let pairs: Vec<(f64, Vector3<f64>, Vector3<f64>)> = self
            .geometry
            .couplings
            .iter()
            .map(|&(a, b)| {
                let (pa, ta, pb, tb) = (
                    &poses[a].trocar,
                    &poses[a].tip,
                    &poses[b].trocar,
                    &poses[b].tip,
                );
                let d = segment_distance(pa, ta, pb, tb);
                let (s, t) = d.witnesses[0];
                (d.distance, pa + (ta - pa) * s, pb + (tb - pb) * t)
            })
            .collect();
        let closest = pairs
            .iter()
            .enumerate()
            .min_by(|x, y| x.1 .0.total_cmp(&y.1 .0))
            .map(|(i, _)| i);
        let mut title = format!("{} — t = {:.2} s", self.geometry.name, row[0]);
        if let Some(i) = closest {
            title += &format!(", closest shafts {:.2} mm apart", pairs[i].0 * 1e3);
            if let Some(safety) = self.geometry.safety {
                title += &format!(" (safety {:.1} mm)", safety * 1e3);
            }
        }
        top.draw(&Text::new(title, (10, 6), ("sans-serif", 18).into_font()))
            .map_err(err)?;
        let upto = self.path_rows.partition_point(|&r| r <= k);
        let (left, right) = body.split_horizontally(w / 2);
        let view = View {
            poses: &poses,
            pairs: &pairs,
            closest,
            paths: self.paths.iter().map(|p| &p[..upto]).collect(),
        };
        view.draw(&left, "the scene (m)", self.whole, false)?;
        view.draw(
            &right,
            "inside the body: shafts from port to tip",
            self.close,
            true,
        )?;
        let font = ("sans-serif", 14).into_font();
        let mut x = 12;
        let mut entries: Vec<(String, RGBColor)> = self
            .geometry
            .arms
            .iter()
            .enumerate()
            .map(|(i, a)| (a.name.clone(), COLOURS[i % COLOURS.len()]))
            .collect();
        entries.push(("port".into(), PORT));
        if closest.is_some() {
            entries.push(("closest shafts".into(), CLOSEST));
        }
        for (label, colour) in entries {
            legend
                .draw(&PathElement::new(
                    vec![(x, 12), (x + 22, 12)],
                    colour.stroke_width(3),
                ))
                .map_err(err)?;
            legend
                .draw(&Text::new(label.clone(), (x + 28, 4), font.clone()))
                .map_err(err)?;
            x += 40 + 8 * label.len() as i32;
        }
        Ok(())
    }
}

/// One frame's poses, shortest segments and paths.
struct View<'a> {
    poses: &'a [ArmPose],
    pairs: &'a [(f64, Vector3<f64>, Vector3<f64>)],
    closest: Option<usize>,
    paths: Vec<&'a [Vector3<f64>]>,
}

impl View<'_> {
    /// An oblique view of `cube`; `close`: the shafts inside the body only, with the pairs'
    /// segments, else the whole arms.
    fn draw<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        caption: &str,
        cube: [(f64, f64); 3],
        close: bool,
    ) -> Result<(), PlotError> {
        let c = |p: &Vector3<f64>| (p.x, p.z, p.y);
        let digits = if cube[0].1 - cube[0].0 < 0.2 { 2 } else { 1 };
        let mut chart = oblique_chart(area, caption, cube, digits)?;
        let inside = |p: &Vector3<f64>| {
            (0..3).all(|a| {
                let r = cube[a];
                let v = [p.x, p.y, p.z][a];
                v >= r.0 && v <= r.1
            })
        };
        for (i, pose) in self.poses.iter().enumerate() {
            let colour = COLOURS[i % COLOURS.len()];
            if !close {
                chart
                    .draw_series(LineSeries::new(
                        pose.points.iter().map(c),
                        colour.stroke_width(3),
                    ))
                    .map_err(err)?;
                chart
                    .draw_series(LineSeries::new(
                        pose.shaft.iter().map(c),
                        colour.mix(0.6).stroke_width(4),
                    ))
                    .map_err(err)?;
            } else {
                chart
                    .draw_series(LineSeries::new(
                        self.paths[i].iter().filter(|p| inside(p)).map(c),
                        colour.mix(0.5).stroke_width(1),
                    ))
                    .map_err(err)?;
                chart
                    .draw_series(LineSeries::new(
                        [pose.trocar, pose.tip].iter().map(c),
                        colour.stroke_width(4),
                    ))
                    .map_err(err)?;
                chart
                    .draw_series(std::iter::once(Circle::new(
                        c(&pose.tip),
                        3,
                        colour.filled(),
                    )))
                    .map_err(err)?;
            }
            chart
                .draw_series([
                    Circle::new(c(&pose.trocar), 6, PORT.stroke_width(2)),
                    Circle::new(c(&pose.trocar), 2, PORT.filled()),
                ])
                .map_err(err)?;
        }
        if close {
            for (i, (_, a, b)) in self.pairs.iter().enumerate() {
                let style = if Some(i) == self.closest {
                    CLOSEST.stroke_width(3)
                } else {
                    PAIR.stroke_width(1)
                };
                chart
                    .draw_series(LineSeries::new([a, b].into_iter().map(c), style))
                    .map_err(err)?;
            }
        }
        Ok(())
    }
}

/// A box grown over points, made a cube about its centre.
struct Bounds {
    lo: Vector3<f64>,
    hi: Vector3<f64>,
}

impl Bounds {
    fn new() -> Self {
        Bounds {
            lo: Vector3::repeat(f64::INFINITY),
            hi: Vector3::repeat(f64::NEG_INFINITY),
        }
    }

    fn grow(&mut self, p: &Vector3<f64>) {
        self.lo = self.lo.inf(p);
        self.hi = self.hi.sup(p);
    }

    /// The cube about the centre whose half side is `margin` times the largest half extent, at
    /// least `least`.
    fn cube(&self, margin: f64, least: f64) -> [(f64, f64); 3] {
        let centre = (self.lo + self.hi) / 2.0;
        let half = ((self.hi - self.lo).amax() / 2.0 * margin).max(least);
        [0, 1, 2].map(|a| (centre[a] - half, centre[a] + half))
    }
}
