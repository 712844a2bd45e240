//! The chart furniture shared by the SVG plots, drawn with `plotters` on its SVG backend:
//! canvas, heading, axes with grid and ticks, legend, footnote.
//!
//! plotters is built without default features: no font files are read (its "naive" text
//! layout estimates widths, and the SVG viewer sets the text), nothing links to the system.

use super::{FrameRecord, ProfileError, RunInfo};
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

pub(super) const WIDTH: u32 = 900;
pub(super) const HEIGHT: u32 = 460;

/// Plot rectangle inside the canvas, in pixels: room for the heading above, tick labels left
/// and below, the legend on the right and the footnote at the bottom.
pub(super) const PLOT_LEFT: i32 = 64;
pub(super) const PLOT_TOP: i32 = 72;
pub(super) const PLOT_WIDTH: i32 = 690;
pub(super) const PLOT_HEIGHT: i32 = 290;
const X_LABEL_AREA: i32 = 44;

pub(super) const TEXT: RGBColor = RGBColor(0x22, 0x22, 0x22);
pub(super) const GREY_TEXT: RGBColor = RGBColor(0x66, 0x66, 0x66);
const GRID: RGBColor = RGBColor(0xe4, 0xe4, 0xe4);

pub(super) type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
pub(super) type Chart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;
pub(super) type DrawResult<T = ()> = Result<T, DrawingAreaErrorKind<std::io::Error>>;

/// A text style of `px` CSS pixels. plotters writes `font-size` as its size divided by 1.24
/// (its em-to-pixel factor), so the size asked for is scaled up by that much.
pub(super) fn font(px: f64, color: &RGBColor) -> TextStyle<'static> {
    ("sans-serif", px * 1.24).into_font().color(color)
}

/// Draws a `WIDTH`×`HEIGHT` white canvas with `draw` and returns the SVG text, with `title`
/// as its `<title>` (plotters writes none; viewers show it as the document name).
pub(super) fn render(
    title: &str,
    draw: impl FnOnce(&Area) -> DrawResult,
) -> Result<String, ProfileError> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE)
            .and_then(|()| draw(&root))
            .and_then(|()| root.present())
            .map_err(|e| ProfileError::Plot {
                title: title.to_string(),
                message: e.to_string(),
            })?;
    }
    // After the opening tag, which ends the first line.
    let at = svg.find('\n').map_or(svg.len(), |i| i + 1);
    svg.insert_str(at, &format!("<title>{}</title>\n", escape(title)));
    Ok(svg)
}

/// XML text for the `<title>` written here; plotters escapes what it writes itself.
pub(super) fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in printable(text).chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// `text` with control characters replaced by `?`: XML 1.0 does not allow them, and plotters
/// passes them through. Caller text (scenario, scene path, device) goes through here.
pub(super) fn printable(text: &str) -> String {
    text.chars()
        .map(|c| match c {
            c if c.is_control() && !matches!(c, '\t' | '\n' | '\r') => '?',
            c => c,
        })
        .collect()
}

/// Text at pixel `at` of `area`, positioned by `anchor`.
pub(super) fn text(
    area: &Area,
    s: &str,
    at: (i32, i32),
    anchor: Pos,
    style: &TextStyle,
) -> DrawResult {
    area.draw(&Text::new(printable(s), at, style.pos(anchor)))
}

pub(super) const TOP_LEFT: Pos = Pos {
    h_pos: HPos::Left,
    v_pos: VPos::Top,
};
pub(super) const LEFT: Pos = Pos {
    h_pos: HPos::Left,
    v_pos: VPos::Center,
};

/// A label drawn over data, vertically centred on `at.1` and starting, centred or ending at
/// `at.0` as `h_pos` says: a white, slightly transparent box under it keeps it legible.
pub(super) fn label_over_data(
    area: &Area,
    s: &str,
    at: (i32, i32),
    h_pos: HPos,
    color: &RGBColor,
) -> DrawResult {
    let style = font(12.0, color);
    let (w, h) = area.estimate_text_size(s, &style)?;
    let (w, h) = (w as i32 + 4, h as i32 + 2);
    let x0 = match h_pos {
        HPos::Left => at.0 - 2,
        HPos::Center => at.0 - w / 2,
        HPos::Right => at.0 - w + 2,
    };
    let y0 = at.1 - h / 2;
    area.draw(&Rectangle::new(
        [(x0, y0), (x0 + w, y0 + h)],
        WHITE.mix(0.8).filled(),
    ))?;
    let anchor = Pos {
        h_pos,
        v_pos: VPos::Center,
    };
    text(area, s, at, anchor, &style)
}

/// Title and two grey subtitle lines above the plot.
pub(super) fn heading(area: &Area, title: &str, subtitles: [&str; 2]) -> DrawResult {
    let bold = ("sans-serif", 16.0 * 1.24, FontStyle::Bold)
        .into_font()
        .color(&TEXT);
    text(area, title, (PLOT_LEFT, 8), TOP_LEFT, &bold)?;
    for (i, line) in subtitles.iter().enumerate() {
        let y = 30 + 16 * i as i32;
        text(
            area,
            line,
            (PLOT_LEFT, y),
            TOP_LEFT,
            &font(12.0, &GREY_TEXT),
        )?;
    }
    Ok(())
}

/// A grey explanatory paragraph at the bottom of the canvas, wrapped to its width (at most
/// [`FOOTNOTE_LINES`] lines).
pub(super) fn footnote(area: &Area, paragraph: &str) -> DrawResult {
    let top = PLOT_TOP + PLOT_HEIGHT + X_LABEL_AREA + 4;
    for (i, line) in wrap(paragraph, FOOTNOTE_COLUMNS)
        .iter()
        .take(FOOTNOTE_LINES)
        .enumerate()
    {
        let y = top + 14 * i as i32;
        text(
            area,
            line,
            (PLOT_LEFT, y),
            TOP_LEFT,
            &font(11.0, &GREY_TEXT),
        )?;
    }
    Ok(())
}

/// Characters per footnote line: 11 px sans-serif averages under 6 px a character, and the
/// line runs from the plot's left edge to the canvas's right edge (836 px).
const FOOTNOTE_COLUMNS: usize = 140;
pub(super) const FOOTNOTE_LINES: usize = 3;

/// `text` broken at spaces into lines of at most `columns` characters (longer words stand
/// alone).
pub(super) fn wrap(text: &str, columns: usize) -> Vec<String> {
    let mut lines: Vec<String> = vec![];
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(line) if line.chars().count() + 1 + word.chars().count() <= columns => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

/// Centred "no frames" in place of the plot.
pub(super) fn no_data(area: &Area) -> DrawResult {
    let centre = (PLOT_LEFT + PLOT_WIDTH / 2, PLOT_TOP + PLOT_HEIGHT / 2);
    let anchor = Pos::new(HPos::Center, VPos::Center);
    text(area, "no frames", centre, anchor, &font(12.0, &TEXT))
}

/// Axes over the plot rectangle for `x` × `y`, with horizontal grid lines and tick labels
/// every `x_step` / `y_step`, and the axis names.
pub(super) fn axes<'a, 'b>(
    area: &'a Area<'b>,
    (x, x_step): ((f64, f64), f64),
    (y, y_step): ((f64, f64), f64),
    x_desc: &str,
    y_desc: &str,
) -> DrawResult<Chart<'a, 'b>> {
    let right = WIDTH as i32 - PLOT_LEFT - PLOT_WIDTH;
    let bottom = HEIGHT as i32 - PLOT_TOP - PLOT_HEIGHT - X_LABEL_AREA;
    let mut chart = ChartBuilder::on(area)
        .margin_top(PLOT_TOP)
        .margin_right(right)
        .margin_bottom(bottom)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(PLOT_LEFT)
        .build_cartesian_2d(x.0..x.1, y.0..y.1)?;
    let x_label = |v: &f64| tick_label(*v, x_step);
    let y_label = |v: &f64| tick_label(*v, y_step);
    // plotters picks "nice" ticks itself, at most this many: with the span a whole number of
    // steps, these are the multiples of the step.
    let count = |(lo, hi): (f64, f64), step: f64| ((hi - lo) / step).round() as usize + 1;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .bold_line_style(GRID)
        .light_line_style(TRANSPARENT)
        .axis_style(TEXT)
        .x_labels(count(x, x_step))
        .y_labels(count(y, y_step))
        .x_label_formatter(&x_label)
        .y_label_formatter(&y_label)
        .label_style(font(12.0, &TEXT))
        .axis_desc_style(font(12.0, &TEXT))
        .x_desc(x_desc)
        .y_desc(y_desc)
        .draw()?;
    Ok(chart)
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

/// `v` with as many decimals as `step` needs.
pub(super) fn tick_label(v: f64, step: f64) -> String {
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    format!("{v:.decimals$}")
}

/// The two subtitle lines: the run's description (scene, size, mode, device), and the
/// frame count with `notes`.
pub(super) fn subtitles(run: &RunInfo, frames: &[FrameRecord], notes: &[String]) -> [String; 2] {
    let warmup = frames.iter().filter(|f| f.warmup).count();
    let mut parts = vec![format!("{} frames ({warmup} warm-up)", frames.len())];
    parts.extend(notes.iter().filter(|n| !n.is_empty()).cloned());
    [run.description(), parts.join(", ")]
}

/// `"<kind> — <scenario>"`, or just `kind` without a scenario.
pub(super) fn title(kind: &str, run: &RunInfo) -> String {
    if run.scenario.is_empty() {
        kind.to_string()
    } else {
        format!("{kind} — {}", run.scenario)
    }
}

/// How a legend entry is drawn.
pub(super) enum Mark {
    /// Filled square.
    Swatch(RGBAColor),
    /// Short line.
    Line(ShapeStyle),
    /// Short dashed line.
    Dashed(ShapeStyle),
}

/// Vertical legend right of the plot.
pub(super) fn legend(area: &Area, items: &[(Mark, &str)]) -> DrawResult {
    let x = PLOT_LEFT + PLOT_WIDTH + 14;
    for (i, (mark, label)) in items.iter().enumerate() {
        let y = PLOT_TOP + 4 + 18 * i as i32;
        match mark {
            Mark::Swatch(color) => area.draw(&Rectangle::new(
                [(x, y - 6), (x + 12, y + 6)],
                color.filled(),
            ))?,
            Mark::Line(style) => area.draw(&PathElement::new(vec![(x, y), (x + 14, y)], *style))?,
            Mark::Dashed(style) => {
                for dash in [(x, x + 4), (x + 6, x + 10), (x + 12, x + 14)] {
                    area.draw(&PathElement::new(vec![(dash.0, y), (dash.1, y)], *style))?;
                }
            }
        }
        text(area, label, (x + 20, y), LEFT, &font(12.0, &TEXT))?;
    }
    Ok(())
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
    fn tick_labels() {
        assert_eq!(tick_label(0.5, 0.5), "0.5");
        assert_eq!(tick_label(1000.0, 500.0), "1000");
        assert_eq!(tick_label(0.4, 0.2), "0.4");
    }

    #[test]
    fn escapes_markup_and_control_characters() {
        assert_eq!(escape("a<b & \"c\"'"), "a&lt;b &amp; &quot;c&quot;&apos;");
        assert_eq!(escape("bell\u{7}"), "bell?");
        assert_eq!(printable("tab\tbell\u{7}"), "tab\tbell?");
    }

    #[test]
    fn wrap_breaks_at_spaces() {
        assert_eq!(wrap("aa bb cc", 5), ["aa bb", "cc"]);
        assert_eq!(wrap("a verylongword b", 4), ["a", "verylongword", "b"]);
        assert!(wrap("", 10).is_empty());
    }

    /// plotters chooses the ticks; with the span a whole number of steps they must be exactly
    /// the multiples of the step, or the labels (formatted for the step) would lie.
    #[test]
    fn ticks_are_the_multiples_of_the_step() {
        for (top, step) in [
            (150.0, 50.0),
            (0.8, 0.2),
            (30.0, 10.0),
            (25.0, 5.0),
            (4.0, 1.0),
        ] {
            let svg = render("t", |area| {
                axes(area, ((1000.0, 1007.0), 1.0), ((0.0, top), step), "x", "y").map(|_| ())
            })
            .unwrap();
            let texts = crate::profile::tests::svg_texts(&svg);
            let count = (top / step).round() as usize;
            for i in 0..=count {
                let label = tick_label(i as f64 * step, step);
                assert!(
                    texts.contains(&label),
                    "{top}/{step}: no {label} in {texts:?}"
                );
            }
            // Negative control: no label between two steps.
            let between = tick_label(step / 2.0, step / 10.0);
            assert!(
                !texts.contains(&between),
                "{top}/{step}: {between} in {texts:?}"
            );
        }
    }

    #[test]
    fn font_size_is_written_as_asked() {
        let svg = render("t", |area| {
            text(area, "x", (0, 0), TOP_LEFT, &font(12.0, &TEXT))
        })
        .unwrap();
        assert!(svg.contains("font-size=\"12\""), "{svg}");
        assert!(svg.contains("<title>t</title>"), "{svg}");
    }
}
