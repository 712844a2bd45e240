//! `histogram.svg`: distribution of the measured frame times with p50 and p99 marked.

use super::svg::{
    Axes, HALO, Mark, PLOT_HEIGHT, PLOT_LEFT, PLOT_TOP, PLOT_WIDTH, Svg, heading, legend,
    nice_step, no_data, subtitle, tick_label, title,
};
use super::{FrameRecord, ProfileError, RunInfo, percentile, write_file};
use std::fmt::Write as _;
use std::io::Write;
use std::path::Path;

const BINS: usize = 50;
const BAR_FILL: &str = "fill=\"#56B4E9\" stroke=\"#ffffff\" stroke-width=\"0.5\"";
const P50_STROKE: &str = "stroke=\"#000000\" stroke-width=\"1.5\" stroke-dasharray=\"6 3\"";
const P99_STROKE: &str = "stroke=\"#D55E00\" stroke-width=\"1.5\" stroke-dasharray=\"6 3\"";

/// The SVG text of `histogram.svg`. Uses the measured frames, or all frames when every
/// frame is warm-up.
pub fn histogram_svg(run: &RunInfo, frames: &[FrameRecord]) -> String {
    let title = title("Frame-time histogram", run);
    let mut svg = Svg::new(&title);
    let finite = |f: &&FrameRecord| f.frame_ms.is_finite();
    let mut values: Vec<f64> = frames
        .iter()
        .filter(|f| !f.warmup)
        .filter(finite)
        .map(|f| f.frame_ms)
        .collect();
    let mut notes = vec![];
    if values.is_empty() {
        values = frames.iter().filter(finite).map(|f| f.frame_ms).collect();
        notes.push("warm-up included".to_string());
    } else {
        notes.push("warm-up excluded".to_string());
    }
    values.sort_by(f64::total_cmp);
    let (Some(&min), Some(&max)) = (values.first(), values.last()) else {
        heading(&mut svg, &title, &subtitle(run, frames, ""));
        no_data(&mut svg);
        return svg.finish();
    };
    let (p50, p99) = (percentile(&values, 50.0), percentile(&values, 99.0));

    // Show the body and the p99 tail; rare hitches far beyond would squeeze the body into a
    // few bins, so they are counted in the subtitle instead.
    let (mut lo, mut hi) = (min, max.min(p99 + 2.0 * (p99 - p50)).max(p99));
    if hi - lo < 1e-6 {
        (lo, hi) = ((lo - 0.5).max(0.0), hi + 0.5);
    }
    let x_step = nice_step(hi - lo, 8);
    let axis_lo = (lo / x_step).floor() * x_step;
    let axis_hi = ((hi / x_step).ceil() * x_step).max(axis_lo + x_step);
    let bin_width = (axis_hi - axis_lo) / BINS as f64;
    let mut counts = [0usize; BINS];
    let mut overflow = 0;
    for &v in &values {
        if v > axis_hi {
            overflow += 1;
        } else {
            let bin = ((v - axis_lo) / bin_width).floor().max(0.0) as usize;
            counts[bin.min(BINS - 1)] += 1;
        }
    }
    if overflow > 0 {
        notes.push(format!(
            "{overflow} frame(s) above {} ms not shown (max {max:.1} ms)",
            tick_label(axis_hi, x_step)
        ));
    }
    heading(&mut svg, &title, &subtitle(run, frames, &notes.join(", ")));

    let tallest = counts.iter().copied().max().unwrap_or(0) as f64;
    let y_step = nice_step(tallest, 5).max(1.0);
    let y_top = ((tallest / y_step).ceil() * y_step).max(y_step);
    let axes = Axes {
        x_range: (axis_lo, axis_hi),
        y_range: (0.0, y_top),
    };
    axes.draw(&mut svg, x_step, y_step, "frame time (ms)", "frames");

    // All bars in one path: one element instead of fifty.
    let mut bars = String::new();
    for (i, &count) in counts.iter().enumerate().filter(|(_, c)| **c > 0) {
        let x0 = axes.x(axis_lo + i as f64 * bin_width);
        let x1 = axes.x(axis_lo + (i + 1) as f64 * bin_width);
        let (y0, y1) = (axes.y(0.0), axes.y(count as f64));
        let _ = write!(bars, "M{x0:.1},{y0:.1} V{y1:.1} H{x1:.1} V{y0:.1} Z ");
    }
    svg.path(bars.trim_end(), BAR_FILL);
    // Labels on separate rows so that close p50 and p99 markers stay readable.
    for (row, (name, value, stroke, color)) in [
        ("p50", p50, P50_STROKE, "#000000"),
        ("p99", p99, P99_STROKE, "#D55E00"),
    ]
    .into_iter()
    .enumerate()
    {
        let x = axes.x(value);
        svg.line(x, PLOT_TOP, x, PLOT_TOP + PLOT_HEIGHT, stroke);
        let y = PLOT_TOP + 14.0 + 16.0 * row as f64;
        let (lx, anchor) = match x > PLOT_LEFT + PLOT_WIDTH - 120.0 {
            true => (x - 4.0, "end"),
            false => (x + 4.0, "start"),
        };
        let attrs = format!("fill=\"{color}\" {HALO}");
        svg.text(lx, y, anchor, &attrs, &format!("{name} {value:.2} ms"));
    }
    legend(
        &mut svg,
        &[
            (Mark::Swatch(BAR_FILL), "frames"),
            (Mark::Line(P50_STROKE), "p50"),
            (Mark::Line(P99_STROKE), "p99"),
        ],
    );
    svg.finish()
}

pub fn write_histogram_svg(
    path: &Path,
    run: &RunInfo,
    frames: &[FrameRecord],
) -> Result<(), ProfileError> {
    let text = histogram_svg(run, frames);
    write_file(path, |w| w.write_all(text.as_bytes()))
}
