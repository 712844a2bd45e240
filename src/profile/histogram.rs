//! `histogram.svg`: distribution of the measured frame times with p50 and p99 marked.

use super::chart::{self, Area, DrawResult, Mark, PLOT_TOP, nice_step, tick_label};
use super::{
    FrameRecord, LOW_1PCT_MEANING, PERCENTILE_MEANING, ProfileError, RunInfo, percentile,
    slowest_mean, write_file,
};
use plotters::prelude::*;
use plotters::style::text_anchor::HPos;
use std::io::Write;
use std::path::Path;

const BINS: usize = 50;
const BAR: RGBColor = RGBColor(0x56, 0xB4, 0xE9);
const P50: RGBColor = RGBColor(0x00, 0x00, 0x00);
const P99: RGBColor = RGBColor(0xD5, 0x5E, 0x00);

/// What the markers and the 1 % low mean, as one paragraph for the footnote.
fn footnote() -> String {
    format!("p50, p99: {PERCENTILE_MEANING}. 1% low: {LOW_1PCT_MEANING}.")
}

/// The SVG text of `histogram.svg`. Uses the measured frames, or all frames when every
/// frame is warm-up.
pub fn histogram_svg(run: &RunInfo, frames: &[FrameRecord]) -> Result<String, ProfileError> {
    let title = chart::title("Frame-time histogram", run);
    chart::render(&title, |area| draw_histogram(area, &title, run, frames))
}

fn draw_histogram(area: &Area, title: &str, run: &RunInfo, frames: &[FrameRecord]) -> DrawResult {
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
    chart::footnote(area, &footnote())?;
    let (Some(&min), Some(&max)) = (values.first(), values.last()) else {
        let [description, counts] = chart::subtitles(run, frames, &[]);
        chart::heading(area, title, [&description, &counts])?;
        return chart::no_data(area);
    };
    let (p50, p99) = (percentile(&values, 50.0), percentile(&values, 99.0));
    let low_1pct = slowest_mean(&values, 0.01);

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
    notes.push(format!("1% low {low_1pct:.2} ms"));
    if overflow > 0 {
        notes.push(format!(
            "{overflow} frame(s) above {} ms not shown (max {max:.1} ms)",
            tick_label(axis_hi, x_step)
        ));
    }
    let [description, frame_counts] = chart::subtitles(run, frames, &notes);
    chart::heading(area, title, [&description, &frame_counts])?;

    let tallest = counts.iter().copied().max().unwrap_or(0) as f64;
    let y_step = nice_step(tallest, 5).max(1.0);
    let y_top = ((tallest / y_step).ceil() * y_step).max(y_step);
    let x = ((axis_lo, axis_hi), x_step);
    let mut plot = chart::axes(area, x, ((0.0, y_top), y_step), "frame time (ms)", "frames")?;

    let bars = counts
        .iter()
        .enumerate()
        .filter(|(_, c)| **c > 0)
        .map(|(i, &count)| {
            let x0 = axis_lo + i as f64 * bin_width;
            let mut bar = Rectangle::new([(x0, 0.0), (x0 + bin_width, count as f64)], BAR.filled());
            // A pixel's gap between neighbouring bars.
            bar.set_margin(0, 0, 0, 1);
            bar
        });
    plot.draw_series(bars)?;
    // Labels on separate rows so that close p50 and p99 markers stay readable.
    for (row, (name, value, color)) in [("p50", p50, P50), ("p99", p99, P99)]
        .into_iter()
        .enumerate()
    {
        let line = [(value, 0.0), (value, y_top)];
        plot.draw_series(DashedLineSeries::new(line, 5, 3, color.stroke_width(2)))?;
        let (px, _) = plot.backend_coord(&(value, 0.0));
        let y = PLOT_TOP + 10 + 18 * row as i32;
        let right = chart::PLOT_LEFT + chart::PLOT_WIDTH - 120;
        let (lx, h_pos) = if px > right {
            (px - 5, HPos::Right)
        } else {
            (px + 5, HPos::Left)
        };
        let label = format!("{name} {value:.2} ms");
        chart::label_over_data(area, &label, (lx, y), h_pos, &color)?;
    }
    chart::legend(
        area,
        &[
            (Mark::Swatch(BAR.mix(1.0)), "frames"),
            (Mark::Dashed(P50.stroke_width(2)), "p50"),
            (Mark::Dashed(P99.stroke_width(2)), "p99"),
        ],
    )?;
    Ok(())
}

pub fn write_histogram_svg(
    path: &Path,
    run: &RunInfo,
    frames: &[FrameRecord],
) -> Result<(), ProfileError> {
    let text = histogram_svg(run, frames)?;
    write_file(path, |w| w.write_all(text.as_bytes()))
}
