//! A minimal SVG writer and the chart furniture (axes, ticks, legend, heading) shared by the
//! plots. Only caller text goes through [`escape`]; attribute strings are our own constants.

use super::{FrameRecord, RunInfo};
use std::fmt::{self, Write};

pub(super) const WIDTH: f64 = 900.0;
pub(super) const HEIGHT: f64 = 400.0;

/// Plot rectangle inside the canvas: room for the heading above, tick labels left and
/// below, and the legend on the right.
pub(super) const PLOT_LEFT: f64 = 64.0;
pub(super) const PLOT_TOP: f64 = 56.0;
pub(super) const PLOT_WIDTH: f64 = 690.0;
pub(super) const PLOT_HEIGHT: f64 = 290.0;

pub(super) const TEXT: &str = "#222222";
pub(super) const GRID: &str = "#e4e4e4";
/// Text attributes for labels drawn over data: a white outline keeps them legible.
pub(super) const HALO: &str = "stroke=\"#ffffff\" stroke-width=\"3\" paint-order=\"stroke\"";

pub(super) fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // Control characters other than tab and newlines are not allowed in XML 1.0.
            c if c.is_control() && !matches!(c, '\t' | '\n' | '\r') => out.push('?'),
            c => out.push(c),
        }
    }
    out
}

pub(super) struct Svg {
    out: String,
}

impl Svg {
    /// Starts a white canvas whose `<title>` is `title`.
    pub(super) fn new(title: &str) -> Self {
        let mut svg = Svg { out: String::new() };
        svg.put(format_args!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{HEIGHT}\" \
             viewBox=\"0 0 {WIDTH} {HEIGHT}\" font-family=\"sans-serif\" font-size=\"12\" \
             fill=\"{TEXT}\">\n<title>{}</title>\n",
            escape(title)
        ));
        svg.rect(0.0, 0.0, WIDTH, HEIGHT, "fill=\"#ffffff\"");
        svg
    }

    fn put(&mut self, args: fmt::Arguments) {
        // Writing into a String cannot fail.
        let _ = self.out.write_fmt(args);
    }

    pub(super) fn rect(&mut self, x: f64, y: f64, w: f64, h: f64, attrs: &str) {
        self.put(format_args!(
            "<rect x=\"{x:.1}\" y=\"{y:.1}\" width=\"{:.1}\" height=\"{:.1}\" {attrs}/>\n",
            w.max(0.0),
            h.max(0.0)
        ));
    }

    pub(super) fn line(&mut self, x1: f64, y1: f64, x2: f64, y2: f64, attrs: &str) {
        self.put(format_args!(
            "<line x1=\"{x1:.1}\" y1=\"{y1:.1}\" x2=\"{x2:.1}\" y2=\"{y2:.1}\" {attrs}/>\n"
        ));
    }

    pub(super) fn polyline(&mut self, points: &[(f64, f64)], attrs: &str) {
        self.out.push_str("<polyline fill=\"none\" points=\"");
        for (i, (x, y)) in points.iter().enumerate() {
            let sep = if i == 0 { "" } else { " " };
            self.put(format_args!("{sep}{x:.1},{y:.1}"));
        }
        self.put(format_args!("\" {attrs}/>\n"));
    }

    /// Closed polygon through `points` as a `<path>`.
    pub(super) fn area(&mut self, points: &[(f64, f64)], attrs: &str) {
        let mut d = String::new();
        for (i, (x, y)) in points.iter().enumerate() {
            let cmd = if i == 0 { "M" } else { " L" };
            let _ = write!(d, "{cmd}{x:.1},{y:.1}");
        }
        d.push_str(" Z");
        self.path(&d, attrs);
    }

    /// A `<path>` with path data `d`.
    pub(super) fn path(&mut self, d: &str, attrs: &str) {
        self.put(format_args!("<path d=\"{d}\" {attrs}/>\n"));
    }

    /// Text at (x, y) (baseline); `anchor` is `start`, `middle` or `end`.
    pub(super) fn text(&mut self, x: f64, y: f64, anchor: &str, attrs: &str, text: &str) {
        self.put(format_args!(
            "<text x=\"{x:.1}\" y=\"{y:.1}\" text-anchor=\"{anchor}\" {attrs}>{}</text>\n",
            escape(text)
        ));
    }

    pub(super) fn finish(mut self) -> String {
        self.out.push_str("</svg>\n");
        self.out
    }
}

/// Linear map from data ranges to the plot rectangle.
pub(super) struct Axes {
    pub(super) x_range: (f64, f64),
    pub(super) y_range: (f64, f64),
}

impl Axes {
    pub(super) fn x(&self, v: f64) -> f64 {
        let (lo, hi) = self.x_range;
        PLOT_LEFT + (v - lo) / (hi - lo) * PLOT_WIDTH
    }

    /// Values outside the range are clamped to the plot edge.
    pub(super) fn y(&self, v: f64) -> f64 {
        let (lo, hi) = self.y_range;
        let t = ((v - lo) / (hi - lo)).clamp(0.0, 1.0);
        PLOT_TOP + PLOT_HEIGHT * (1.0 - t)
    }

    /// Grid lines, axis lines, ticks with labels every `x_step` / `y_step`, axis labels.
    pub(super) fn draw(
        &self,
        svg: &mut Svg,
        x_step: f64,
        y_step: f64,
        x_label: &str,
        y_label: &str,
    ) {
        let bottom = PLOT_TOP + PLOT_HEIGHT;
        let right = PLOT_LEFT + PLOT_WIDTH;
        let grid = format!("stroke=\"{GRID}\" stroke-width=\"1\"");
        let axis = format!("stroke=\"{TEXT}\" stroke-width=\"1\"");
        for v in ticks(self.y_range, y_step) {
            let y = self.y(v);
            svg.line(PLOT_LEFT, y, right, y, &grid);
            svg.line(PLOT_LEFT - 4.0, y, PLOT_LEFT, y, &axis);
            svg.text(PLOT_LEFT - 7.0, y + 4.0, "end", "", &tick_label(v, y_step));
        }
        for v in ticks(self.x_range, x_step) {
            let x = self.x(v);
            svg.line(x, bottom, x, bottom + 4.0, &axis);
            svg.text(x, bottom + 17.0, "middle", "", &tick_label(v, x_step));
        }
        svg.line(PLOT_LEFT, PLOT_TOP, PLOT_LEFT, bottom, &axis);
        svg.line(PLOT_LEFT, bottom, right, bottom, &axis);
        svg.text(
            PLOT_LEFT + PLOT_WIDTH / 2.0,
            bottom + 36.0,
            "middle",
            "",
            x_label,
        );
        let (x, y) = (16.0, PLOT_TOP + PLOT_HEIGHT / 2.0);
        let rotate = format!("transform=\"rotate(-90 {x} {y})\"");
        svg.text(x, y, "middle", &rotate, y_label);
    }
}

/// A step of 1, 2 or 5 × 10ᵏ giving about `target` intervals over `span`.
pub(super) fn nice_step(span: f64, target: usize) -> f64 {
    if !(span.is_finite() && span > 0.0) {
        return 1.0;
    }
    let raw = span / target.max(1) as f64;
    let magnitude = 10f64.powf(raw.log10().floor());
    let nice = match raw / magnitude {
        r if r <= 1.0 => 1.0,
        r if r <= 2.0 => 2.0,
        r if r <= 5.0 => 5.0,
        _ => 10.0,
    };
    nice * magnitude
}

/// Multiples of `step` within `range` (with a little tolerance for rounding).
pub(super) fn ticks(range: (f64, f64), step: f64) -> Vec<f64> {
    let (lo, hi) = range;
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    (first..=last).map(|i| i as f64 * step).collect()
}

/// `v` with as many decimals as `step` needs.
pub(super) fn tick_label(v: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// Title and a grey subtitle above the plot.
pub(super) fn heading(svg: &mut Svg, title: &str, subtitle: &str) {
    svg.text(
        PLOT_LEFT,
        22.0,
        "start",
        "font-size=\"16\" font-weight=\"bold\"",
        title,
    );
    svg.text(PLOT_LEFT, 40.0, "start", "fill=\"#666666\"", subtitle);
}

/// Centred "no frames" in place of the plot.
pub(super) fn no_data(svg: &mut Svg) {
    let (x, y) = (PLOT_LEFT + PLOT_WIDTH / 2.0, PLOT_TOP + PLOT_HEIGHT / 2.0);
    svg.text(x, y, "middle", "", "no frames");
}

/// `"<scenario-free description>, N frames (W warm-up)"`.
pub(super) fn subtitle(run: &RunInfo, frames: &[FrameRecord], extra: &str) -> String {
    let warmup = frames.iter().filter(|f| f.warmup).count();
    let mut parts = vec![];
    let description = run.description();
    if !description.is_empty() {
        parts.push(description);
    }
    parts.push(format!("{} frames ({warmup} warm-up)", frames.len()));
    if !extra.is_empty() {
        parts.push(extra.to_string());
    }
    parts.join(", ")
}

/// `"<kind> — <scenario>"`, or just `kind` without a scenario.
pub(super) fn title(kind: &str, run: &RunInfo) -> String {
    if run.scenario.is_empty() {
        kind.to_string()
    } else {
        format!("{kind} — {}", run.scenario)
    }
}

pub(super) enum Mark<'a> {
    /// Filled square, with the fill attributes given.
    Swatch(&'a str),
    /// Short line, with the stroke attributes given.
    Line(&'a str),
}

/// Vertical legend right of the plot.
pub(super) fn legend(svg: &mut Svg, items: &[(Mark, &str)]) {
    let x = PLOT_LEFT + PLOT_WIDTH + 14.0;
    for (i, (mark, label)) in items.iter().enumerate() {
        let y = PLOT_TOP + 8.0 + 18.0 * i as f64;
        match mark {
            Mark::Swatch(attrs) => svg.rect(x, y - 9.0, 12.0, 12.0, attrs),
            Mark::Line(attrs) => svg.line(x, y - 3.0, x + 14.0, y - 3.0, attrs),
        }
        svg.text(x + 20.0, y + 1.0, "start", "", label);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_are_one_two_five() {
        assert_eq!(nice_step(10.0, 5), 2.0);
        assert_eq!(nice_step(33.0, 5), 10.0);
        assert_eq!(nice_step(0.7, 5), 0.2);
        assert_eq!(nice_step(4000.0, 8), 500.0);
        assert_eq!(nice_step(0.0, 5), 1.0);
    }

    #[test]
    fn ticks_cover_the_range() {
        assert_eq!(ticks((0.0, 10.0), 2.0), vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        assert_eq!(ticks((7.5, 9.1), 0.5).len(), 4);
        assert_eq!(tick_label(0.5, 0.5), "0.5");
        assert_eq!(tick_label(1000.0, 500.0), "1000");
    }

    #[test]
    fn escapes_markup() {
        assert_eq!(escape("a<b & \"c\"'"), "a&lt;b &amp; &quot;c&quot;&apos;");
        assert_eq!(escape("bell\u{7}"), "bell?");
    }
}
