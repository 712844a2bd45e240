//! `frame_times.svg`: frame time over the run with the CPU phases stacked underneath.

use super::chart::{
    self, Area, Chart, DrawResult, GREY_TEXT, Mark, PLOT_TOP, PLOT_WIDTH, TEXT, TOP_LEFT, font,
    nice_step, tick_label,
};
use super::{
    FrameRecord, GPU_MEANING, OTHER_MEANING, Phase, ProfileError, RunInfo, percentile, write_file,
};
use plotters::prelude::*;
use plotters::style::text_anchor::HPos;
use std::io::Write;
use std::path::Path;

/// Fill colours of the stacked phases (Okabe–Ito, distinguishable with colour-vision
/// deficiencies); `present` is grey because it is mostly waiting.
pub(super) const PHASE_COLORS: [RGBColor; Phase::COUNT] = [
    RGBColor(0xE6, 0x9F, 0x00),
    RGBColor(0x56, 0xB4, 0xE9),
    RGBColor(0x00, 0x9E, 0x73),
    RGBColor(0xF0, 0xE4, 0x42),
    RGBColor(0x00, 0x72, 0xB2),
    RGBColor(0xBB, 0xBB, 0xBB),
];
const GPU: RGBColor = RGBColor(0xCC, 0x79, 0xA7);
const FRAME_MAX: RGBColor = RGBColor(0x88, 0x88, 0x88);
const MEDIAN: RGBColor = RGBColor(0xD5, 0x5E, 0x00);
/// Dash and gap lengths in pixels.
const DASH: (u32, u32) = (5, 3);

/// What the phases, "other" and "gpu" mean, as one paragraph for the footnote.
fn phase_footnote() -> String {
    let phases: Vec<String> = Phase::ALL
        .iter()
        .map(|p| format!("{p} = {}", p.meaning()))
        .collect();
    format!(
        "Phases: {}; other = {OTHER_MEANING}; gpu = {GPU_MEANING}.",
        phases.join("; ")
    )
}

/// The y axis stops at this multiple of the measured p99 (clipping, with a note) so that one
/// warm-up stall or hitch does not flatten every other frame to the x axis.
const Y_CAP_OVER_P99: f64 = 3.0;

/// Frames averaged into one plotted point: at most one point per pixel column keeps the file
/// small for long runs.
#[derive(Clone)]
struct Point {
    /// Centre, in frame-index units.
    x: f64,
    phase_ms: [f64; Phase::COUNT],
    frame_ms: f64,
    frame_max_ms: f64,
    gpu_ms: Option<f64>,
}

fn points(frames: &[FrameRecord]) -> Vec<Point> {
    let n = frames.len();
    let columns = n.min(PLOT_WIDTH as usize);
    let mut points: Vec<Point> = (0..columns)
        .map(|b| {
            let (lo, hi) = (b * n / columns, (b + 1) * n / columns);
            let group = &frames[lo..hi];
            let mean = |get: &dyn Fn(&FrameRecord) -> f64| {
                group.iter().map(get).sum::<f64>() / group.len() as f64
            };
            let gpu: Vec<f64> = group.iter().filter_map(|f| f.gpu_ms).collect();
            Point {
                x: (lo + hi) as f64 / 2.0,
                phase_ms: Phase::ALL.map(|p| mean(&|f| f.phase_ms[p])),
                frame_ms: mean(&|f| f.frame_ms),
                frame_max_ms: group.iter().map(|f| f.frame_ms).fold(0.0, f64::max),
                gpu_ms: (!gpu.is_empty()).then(|| gpu.iter().sum::<f64>() / gpu.len() as f64),
            }
        })
        .collect();
    // A single point has no width; stretch it across the plot.
    if let [single] = &points[..] {
        let first = Point {
            x: 0.0,
            ..single.clone()
        };
        let last = Point {
            x: n as f64,
            ..single.clone()
        };
        points = vec![first, last];
    }
    points
}

/// Largest value a frame puts on the plot.
fn frame_peak(f: &FrameRecord) -> f64 {
    f.frame_ms.max(f.cpu_ms()).max(f.gpu_ms.unwrap_or(0.0))
}

/// The y axis: top, tick step, and a note on clipped frames (empty if none).
fn y_axis(frames: &[FrameRecord], measured_p99: Option<f64>) -> (f64, f64, String) {
    let peak = frames
        .iter()
        .map(frame_peak)
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let limit = match measured_p99 {
        Some(p99) => peak.min(Y_CAP_OVER_P99 * p99),
        None => peak,
    };
    let step = nice_step(limit, 5);
    let top = ((limit / step).ceil() * step).max(step);
    let note = match frames.iter().filter(|f| frame_peak(f) > top).count() {
        0 => String::new(),
        c => format!(
            "{c} frame(s) above {} ms clipped (max {peak:.1} ms)",
            tick_label(top, step)
        ),
    };
    (top, step, note)
}

/// The SVG text of `frame_times.svg`.
pub fn frame_times_svg(run: &RunInfo, frames: &[FrameRecord]) -> Result<String, ProfileError> {
    let title = chart::title("Frame time", run);
    chart::render(&title, |area| draw_frame_times(area, &title, run, frames))
}

fn draw_frame_times(area: &Area, title: &str, run: &RunInfo, frames: &[FrameRecord]) -> DrawResult {
    let mut measured: Vec<f64> = frames
        .iter()
        .filter(|f| !f.warmup && f.frame_ms.is_finite())
        .map(|f| f.frame_ms)
        .collect();
    measured.sort_by(f64::total_cmp);
    let (median, p99) = match measured.is_empty() {
        true => (None, None),
        false => (
            Some(percentile(&measured, 50.0)),
            Some(percentile(&measured, 99.0)),
        ),
    };
    let (y_top, y_step, note) = y_axis(frames, p99);
    let [description, counts] = chart::subtitles(run, frames, &[note]);
    chart::heading(area, title, [&description, &counts])?;
    chart::footnote(area, &phase_footnote())?;
    if frames.is_empty() {
        return chart::no_data(area);
    }

    let n = frames.len() as f64;
    let x_step = nice_step(n, 8).max(1.0);
    let mut plot = chart::axes(
        area,
        ((0.0, n), x_step),
        ((0.0, y_top), y_step),
        "frame",
        "ms",
    )?;
    let warmup_end = frames.iter().take_while(|f| f.warmup).count() as f64;
    if warmup_end > 0.0 {
        let shade = BLACK.mix(0.08).filled();
        plot.draw_series([Rectangle::new([(0.0, 0.0), (warmup_end, y_top)], shade)])?;
    }
    let points = points(frames);
    draw_stack(&mut plot, &points, y_top)?;
    let bucketed = points.len() < frames.len();
    draw_lines(&mut plot, &points, bucketed, y_top)?;
    if let Some(median) = median {
        let style = MEDIAN.stroke_width(2);
        let line = [(0.0, median), (n, median)];
        plot.draw_series(DashedLineSeries::new(line, DASH.0, DASH.1, style))?;
        let (x, y) = plot.backend_coord(&(n, median));
        chart::label_over_data(
            area,
            &format!("median {median:.2} ms"),
            (x - 4, y - 10),
            HPos::Right,
            &MEDIAN,
        )?;
    }
    // Labels last, so that data never covers them.
    let (x0, x1) = (
        plot.backend_coord(&(0.0, 0.0)).0,
        plot.backend_coord(&(warmup_end, 0.0)).0,
    );
    if x1 - x0 > 60 {
        chart::text(
            area,
            "warm-up",
            (x0 + 4, PLOT_TOP + 4),
            TOP_LEFT,
            &font(12.0, &GREY_TEXT),
        )?;
    }
    chart::legend(
        area,
        &legend_items(frames, bucketed, median.is_some(), warmup_end > 0.0),
    )
}

fn legend_items(
    frames: &[FrameRecord],
    bucketed: bool,
    median: bool,
    warmup: bool,
) -> Vec<(Mark, &'static str)> {
    let mut items: Vec<(Mark, &str)> = Phase::ALL
        .iter()
        .zip(PHASE_COLORS)
        .rev() // top of the stack first, as drawn
        .map(|(p, color)| (Mark::Swatch(color.mix(0.85)), p.name()))
        .collect();
    match bucketed {
        true => items.extend([
            (Mark::Line(TEXT.stroke_width(1)), "frame (mean)"),
            (Mark::Line(FRAME_MAX.stroke_width(1)), "frame (max)"),
        ]),
        false => items.push((Mark::Line(TEXT.stroke_width(1)), "frame")),
    }
    if frames.iter().any(|f| f.gpu_ms.is_some()) {
        items.push((Mark::Dashed(GPU.stroke_width(2)), "gpu"));
    }
    if median {
        items.push((Mark::Dashed(MEDIAN.stroke_width(2)), "median"));
    }
    if warmup {
        items.push((Mark::Swatch(BLACK.mix(0.08)), "warm-up"));
    }
    items
}

/// The phases as stacked areas, `input` at the bottom; values above the axis are clipped.
fn draw_stack(plot: &mut Chart, points: &[Point], y_top: f64) -> DrawResult {
    let mut below = vec![0.0; points.len()];
    for (k, color) in PHASE_COLORS.iter().enumerate() {
        let above: Vec<f64> = points
            .iter()
            .zip(&below)
            .map(|(p, b)| b + p.phase_ms[k])
            .collect();
        let clip = |(p, v): (&Point, &f64)| (p.x, v.min(y_top));
        let mut outline: Vec<(f64, f64)> = points.iter().zip(&above).map(clip).collect();
        outline.extend(points.iter().zip(&below).rev().map(clip));
        plot.draw_series([Polygon::new(outline, color.mix(0.85).filled())])?;
        below = above;
    }
    Ok(())
}

/// Frame time (mean, and max per point when frames are averaged) and GPU time.
fn draw_lines(plot: &mut Chart, points: &[Point], bucketed: bool, y_top: f64) -> DrawResult {
    let line = |get: fn(&Point) -> f64| points.iter().map(move |p| (p.x, get(p).min(y_top)));
    if bucketed {
        plot.draw_series(LineSeries::new(
            line(|p| p.frame_max_ms),
            FRAME_MAX.stroke_width(1),
        ))?;
    }
    plot.draw_series(LineSeries::new(line(|p| p.frame_ms), TEXT.stroke_width(1)))?;
    for mut segment in gpu_segments(points) {
        // A lone point draws nothing; widen it to a one-frame dash.
        if let [(x, v)] = segment[..] {
            segment = vec![(x - 0.5, v), (x + 0.5, v)];
        }
        let clipped = segment.into_iter().map(|(x, v)| (x, v.min(y_top)));
        plot.draw_series(DashedLineSeries::new(
            clipped,
            DASH.0,
            DASH.1,
            GPU.stroke_width(2),
        ))?;
    }
    Ok(())
}

/// Runs of consecutive points that have a GPU time; frames without one break the line.
fn gpu_segments(points: &[Point]) -> Vec<Vec<(f64, f64)>> {
    let mut segments = vec![];
    let mut current = vec![];
    for p in points {
        match p.gpu_ms {
            Some(v) => current.push((p.x, v)),
            None if !current.is_empty() => segments.push(std::mem::take(&mut current)),
            None => {}
        }
    }
    if !current.is_empty() {
        segments.push(current);
    }
    segments
}

pub fn write_frame_times_svg(
    path: &Path,
    run: &RunInfo,
    frames: &[FrameRecord],
) -> Result<(), ProfileError> {
    let text = frame_times_svg(run, frames)?;
    write_file(path, |w| w.write_all(text.as_bytes()))
}
