//! `frame_times.svg`: frame time over the run with the CPU phases stacked underneath.

use super::svg::{
    Axes, HALO, Mark, PLOT_HEIGHT, PLOT_LEFT, PLOT_TOP, PLOT_WIDTH, Svg, heading, legend,
    nice_step, no_data, subtitle, tick_label, title,
};
use super::{FrameRecord, Phase, ProfileError, RunInfo, percentile, write_file};
use std::io::Write;
use std::path::Path;

/// Fill colours of the stacked phases (Okabe–Ito, distinguishable with colour-vision
/// deficiencies); `present` is grey because it is mostly waiting.
pub(super) const PHASE_COLORS: [&str; Phase::COUNT] = [
    "#E69F00", "#56B4E9", "#009E73", "#F0E442", "#0072B2", "#BBBBBB",
];
const GPU_STROKE: &str = "stroke=\"#CC79A7\" stroke-width=\"1.5\" stroke-dasharray=\"4 2\"";
const FRAME_STROKE: &str = "stroke=\"#000000\" stroke-width=\"1\"";
const FRAME_MAX_STROKE: &str = "stroke=\"#888888\" stroke-width=\"0.75\"";
const MEDIAN_STROKE: &str = "stroke=\"#D55E00\" stroke-width=\"1.5\" stroke-dasharray=\"6 3\"";
const WARMUP_FILL: &str = "fill=\"#000000\" fill-opacity=\"0.08\"";

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
pub fn frame_times_svg(run: &RunInfo, frames: &[FrameRecord]) -> String {
    let title = title("Frame time", run);
    let mut svg = Svg::new(&title);
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
    heading(&mut svg, &title, &subtitle(run, frames, &note));
    if frames.is_empty() {
        no_data(&mut svg);
        return svg.finish();
    }

    let n = frames.len();
    let axes = Axes {
        x_range: (0.0, n as f64),
        y_range: (0.0, y_top),
    };
    let warmup_end = frames.iter().take_while(|f| f.warmup).count();
    let (x0, x1) = (axes.x(0.0), axes.x(warmup_end as f64));
    if warmup_end > 0 {
        svg.rect(x0, PLOT_TOP, x1 - x0, PLOT_HEIGHT, WARMUP_FILL);
    }
    axes.draw(
        &mut svg,
        nice_step(n as f64, 8).max(1.0),
        y_step,
        "frame",
        "ms",
    );

    let points = points(frames);
    draw_stack(&mut svg, &axes, &points);
    let bucketed = points.len() < n;
    draw_lines(&mut svg, &axes, &points, bucketed);
    let label_attrs = format!("fill=\"#D55E00\" {HALO}");
    if let Some(median) = median {
        let y = axes.y(median);
        svg.line(PLOT_LEFT, y, PLOT_LEFT + PLOT_WIDTH, y, MEDIAN_STROKE);
        let label = format!("median {median:.2} ms");
        svg.text(
            PLOT_LEFT + PLOT_WIDTH - 4.0,
            y - 5.0,
            "end",
            &label_attrs,
            &label,
        );
    }
    // Labels last, so that data never covers them.
    if x1 - x0 > 60.0 {
        let attrs = format!("fill=\"#666666\" {HALO}");
        svg.text(x0 + 4.0, PLOT_TOP + 14.0, "start", &attrs, "warm-up");
    }

    let fills = PHASE_COLORS.map(|c| format!("fill=\"{c}\""));
    let mut items: Vec<(Mark, &str)> = Phase::ALL
        .iter()
        .zip(&fills)
        .rev() // top of the stack first, as drawn
        .map(|(p, fill)| (Mark::Swatch(fill), p.name()))
        .collect();
    match bucketed {
        true => items.extend([
            (Mark::Line(FRAME_STROKE), "frame (mean)"),
            (Mark::Line(FRAME_MAX_STROKE), "frame (max)"),
        ]),
        false => items.push((Mark::Line(FRAME_STROKE), "frame")),
    }
    if frames.iter().any(|f| f.gpu_ms.is_some()) {
        items.push((Mark::Line(GPU_STROKE), "gpu"));
    }
    if median.is_some() {
        items.push((Mark::Line(MEDIAN_STROKE), "median"));
    }
    if warmup_end > 0 {
        items.push((Mark::Swatch(WARMUP_FILL), "warm-up"));
    }
    legend(&mut svg, &items);
    svg.finish()
}

/// The phases as stacked areas, `input` at the bottom.
fn draw_stack(svg: &mut Svg, axes: &Axes, points: &[Point]) {
    let mut below = vec![0.0; points.len()];
    for (k, color) in PHASE_COLORS.iter().enumerate() {
        let above: Vec<f64> = points
            .iter()
            .zip(&below)
            .map(|(p, b)| b + p.phase_ms[k])
            .collect();
        let to_svg = |(p, v): (&Point, &f64)| (axes.x(p.x), axes.y(*v));
        let mut outline: Vec<(f64, f64)> = points.iter().zip(&above).map(to_svg).collect();
        outline.extend(points.iter().zip(&below).rev().map(to_svg));
        svg.area(&outline, &format!("fill=\"{color}\" fill-opacity=\"0.85\""));
        below = above;
    }
}

/// Frame time (mean, and max per point when frames are averaged) and GPU time.
fn draw_lines(svg: &mut Svg, axes: &Axes, points: &[Point], bucketed: bool) {
    let line = |get: fn(&Point) -> f64| -> Vec<(f64, f64)> {
        points
            .iter()
            .map(|p| (axes.x(p.x), axes.y(get(p))))
            .collect()
    };
    if bucketed {
        svg.polyline(&line(|p| p.frame_max_ms), FRAME_MAX_STROKE);
    }
    svg.polyline(&line(|p| p.frame_ms), FRAME_STROKE);
    for mut segment in gpu_segments(points) {
        // A lone point draws nothing; widen it to a one-frame dash.
        if let [(x, v)] = segment[..] {
            segment = vec![(x - 0.5, v), (x + 0.5, v)];
        }
        let svg_points: Vec<(f64, f64)> = segment
            .iter()
            .map(|&(x, v)| (axes.x(x), axes.y(v)))
            .collect();
        svg.polyline(&svg_points, GPU_STROKE);
    }
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
    let text = frame_times_svg(run, frames);
    write_file(path, |w| w.write_all(text.as_bytes()))
}
