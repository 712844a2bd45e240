//! The on-screen overlay: frame-time graph, edit cost, samples touched, bytes copied to the GPU,
//! GPU time; the status line; and the key help.

use super::keymap::KEY_HELP;
use crate::gpu::OverlayVertex;
use crate::gpu::font::{Font, TextSize, push_rect};
use std::collections::VecDeque;

/// Frames kept in the graph.
const HISTORY: usize = 240;
/// The frame-time graph's size in pixels: two per frame, and its height.
const GRAPH_W: f32 = HISTORY as f32 * 2.0;
const GRAPH_H: f32 = 60.0;
/// Colour of overlay text.
pub const TEXT: [u8; 4] = [230, 232, 238, 255];
const DIM: [u8; 4] = [150, 155, 165, 255];
/// Opaque, so neither the scene nor other overlays show through the text.
const PANEL: [u8; 4] = crate::render::analysis::PANEL;
/// The help's panel (opaque too).
pub const HELP_PANEL: [u8; 4] = [8, 10, 14, 255];

/// Numbers shown in the overlay.
#[derive(Debug, Clone, Default)]
pub struct Hud {
    frames: VecDeque<f32>,
    pub edit_us: f64,
    pub samples_touched: usize,
    pub bytes: usize,
    pub gpu_ms: Option<f64>,
    /// Surface triangles drawn last frame and at full resolution (level of detail).
    pub triangles: (u64, u64),
    /// Last frame came from the static layer: surface triangles drawn and those a full
    /// redraw draws (`None`: a full redraw).
    pub retained: Option<(u64, u64)>,
    /// Last frame built the static layer (a full redraw, then the dragged part again).
    pub layer_built: bool,
    pub visible: bool,
}

impl Hud {
    #[must_use]
    pub fn new() -> Self {
        Self {
            visible: true,
            ..Self::default()
        }
    }

    pub fn push_frame(&mut self, ms: f64) {
        if self.frames.len() == HISTORY {
            self.frames.pop_front();
        }
        self.frames.push_back(ms as f32);
    }

    fn mean(&self) -> f64 {
        let n = self.frames.len().min(60);
        if n == 0 {
            return 0.0;
        }
        self.frames
            .iter()
            .rev()
            .take(n)
            .map(|&x| x as f64)
            .sum::<f64>()
            / n as f64
    }

    /// The HUD lines: frame time, edit cost and bytes copied, level of detail, redraw.
    #[must_use]
    pub fn lines(&self) -> [String; 4] {
        let mean = self.mean();
        let fps = if mean > 0.0 { 1000.0 / mean } else { 0.0 };
        let gpu = self
            .gpu_ms
            .map_or("n/a".to_string(), |g| format!("{g:.2} ms"));
        [
            format!("frame {mean:.2} ms ({fps:.0} fps)   GPU {gpu}"),
            format!(
                "edit {:.1} us   {} samples   {:.1} KB to GPU",
                self.edit_us,
                self.samples_touched,
                self.bytes as f64 / 1024.0
            ),
            lod_line(self.triangles),
            redraw_line(self.retained, self.layer_built),
        ]
    }

    /// Overlay vertices of the performance panel (when visible and the help is not shown)
    /// and the status line, for a `width × height` image. The help comes separately
    /// ([`help_overlay`]), to be drawn last.
    #[must_use]
    pub fn build(
        &self,
        font: &Font,
        width: f32,
        height: f32,
        status: &str,
        help: bool,
    ) -> Vec<OverlayVertex> {
        let mut v = Vec::new();
        // The help panel covers the overlay's corner; it shows alone.
        if self.visible && !help {
            self.push_panel(&mut v, font);
        }
        push_status(&mut v, font, width, height, status);
        v
    }

    /// The performance panel's rectangle `[x, y, width, height]` in pixels (top-left origin)
    /// when it is shown: framing keeps the model out of it.
    #[must_use]
    pub fn panel_rect(&self, font: &Font) -> Option<[f32; 4]> {
        self.visible.then(|| {
            let size = TextSize::Normal;
            let line = font.metrics(size).line_height as f32 + 2.0;
            let lines = self.lines();
            let text_w = lines
                .iter()
                .map(|l| font.text_size(l, size)[0])
                .fold(0.0f32, f32::max);
            let [label_w, _] = font.text_size("1000 ms", size);
            [
                8.0,
                8.0,
                text_w.max(GRAPH_W + 6.0 + label_w) + 16.0,
                lines.len() as f32 * line + GRAPH_H + 24.0,
            ]
        })
    }

    fn push_panel(&self, v: &mut Vec<OverlayVertex>, font: &Font) {
        let size = TextSize::Normal;
        let line = font.metrics(size).line_height as f32 + 2.0;
        let lines = self.lines();
        let (gw, gh) = (GRAPH_W, GRAPH_H);
        if let Some([x, y, w, h]) = self.panel_rect(font) {
            push_rect(v, x, y, w, h, PANEL);
        }
        for (k, l) in lines.iter().enumerate() {
            font.push_text(v, l, 16.0, 14.0 + k as f32 * line, size, TEXT);
        }
        // Frame-time graph: one bar per frame. Full scale is 33 ms, or the next of 50, 100,
        // 200, 500, 1000 ms above the slowest recent frame (software rendering is slow), so
        // bars are never pegged; reference lines at 16.7 and 33.3 ms and at full scale.
        let (gx, gy) = (16.0, 16.0 + lines.len() as f32 * line);
        let slowest = self.frames.iter().copied().fold(0.0f32, f32::max);
        let full = [33.3f32, 50.0, 100.0, 200.0, 500.0, 1000.0]
            .into_iter()
            .find(|&f| slowest <= f)
            .unwrap_or(slowest);
        for ms in [16.7f32, 33.3, full] {
            if ms <= full {
                push_rect(v, gx, gy + gh - gh * ms / full, gw, 1.0, [90, 90, 100, 255]);
            }
        }
        font.push_text(v, &format!("{full:.0} ms"), gx + gw + 6.0, gy, size, DIM);
        for (k, &ms) in self.frames.iter().enumerate() {
            let h = (gh * ms / full).min(gh);
            let c = if ms > 33.3 {
                [235, 80, 70, 255]
            } else if ms > 16.7 {
                [235, 190, 60, 255]
            } else {
                [90, 200, 120, 255]
            };
            push_rect(v, gx + k as f32 * 2.0, gy + gh - h, 2.0, h, c);
        }
    }
}

/// The part of a `size` window (pixels) that the overlays leave free, `[left, right, top,
/// bottom]` (top-left origin): above the status line's band (`status` pixels high), and of
/// the parts beside and below the performance `panel` (`[x, y, width, height]`, while shown)
/// the larger, never less than half the window either way. Framing (open, F, A) fills it.
#[must_use]
pub fn free_rect(size: [f64; 2], panel: Option<[f32; 4]>, status: f64) -> [f64; 4] {
    let [w, h] = size;
    let bottom = (h - status).max(h * 0.5);
    match panel {
        None => [0.0, w, 0.0, bottom],
        Some([x, y, pw, ph]) => {
            let (right, below) = (f64::from(x + pw) + 4.0, f64::from(y + ph) + 4.0);
            let beside = [right.min(w * 0.5), w, 0.0, bottom];
            let under = [0.0, w, below.min(bottom * 0.5), bottom];
            let area = |r: [f64; 4]| (r[1] - r[0]) * (r[3] - r[2]);
            if area(beside) > area(under) {
                beside
            } else {
                under
            }
        }
    }
}

/// The status line's band height at the bottom of the window, in pixels (one line).
#[must_use]
pub fn status_band(font: &Font) -> f64 {
    font.metrics(TextSize::Normal).line_height as f64 + 16.0
}

/// Left margin of the status text, in pixels.
pub const STATUS_MARGIN: f32 = 12.0;

/// The status line at the bottom of a `width × height` image on an opaque band: one line, or
/// two when it is longer ([`status_lines`]).
fn push_status(v: &mut Vec<OverlayVertex>, font: &Font, width: f32, height: f32, status: &str) {
    if status.is_empty() {
        return;
    }
    let size = TextSize::Normal;
    let lines = status_lines(font, width, status);
    let line = font.metrics(size).line_height as f32;
    let y = status_top(font, height, lines.len());
    push_rect(
        v,
        0.0,
        y - 6.0,
        width,
        lines.len() as f32 * line + 12.0,
        PANEL,
    );
    for (k, l) in lines.iter().enumerate() {
        font.push_text(v, l, STATUS_MARGIN, y + k as f32 * line, size, TEXT);
    }
}

/// Top of the status text of `lines` lines in an image `height` pixels high.
#[must_use]
pub fn status_top(font: &Font, height: f32, lines: usize) -> f32 {
    let line = font.metrics(TextSize::Normal).line_height as f32;
    (height - lines as f32 * line - 10.0).round()
}

/// The status message as shown in a `width`-pixel window: one line when it fits, else
/// word-wrapped onto two, else its middle elided (`…`) so that the start and the end (where
/// the advice is) both show. The viewer writes an elided message to stderr whole.
#[must_use]
pub fn status_lines(font: &Font, width: f32, status: &str) -> Vec<String> {
    let fit = font
        .chars_fitting(width - 2.0 * STATUS_MARGIN, TextSize::Normal)
        .max(8);
    let status = status.replace('\n', " ");
    if status.chars().count() <= fit {
        return vec![status];
    }
    let wrapped = wrap_chars(&status, fit);
    if wrapped.len() <= 2 {
        return wrapped;
    }
    // Elide the middle: the first line as wrapped, the second "… " and the message's end.
    let first = wrapped[0].clone();
    let chars: Vec<char> = status.chars().collect();
    let keep = fit - 2;
    let start = chars.len() - keep;
    let mut tail: String = chars[start..].iter().collect();
    // Start the tail at a word where the cut falls inside one (and the tail has a space).
    if chars[start - 1] != ' '
        && let Some(space) = tail.find(' ')
    {
        tail = tail[space..].to_string();
    }
    vec![first, format!("… {}", tail.trim_start())]
}

/// Whether the window shows `status` with its middle elided ([`status_lines`]).
#[must_use]
pub fn status_elided(font: &Font, width: f32, status: &str) -> bool {
    status_lines(font, width, status)
        .last()
        .is_some_and(|l| l.starts_with("… "))
}

/// Greedy word wrap to lines of at most `width` characters; a word longer than a line is cut.
fn wrap_chars(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = vec![String::new()];
    for word in text.split(' ') {
        let mut word: Vec<char> = word.chars().collect();
        loop {
            let last = lines.last_mut().expect("never empty");
            let used = last.chars().count();
            let gap = usize::from(used > 0);
            if used + gap + word.len() <= width {
                if gap == 1 {
                    last.push(' ');
                }
                last.extend(word.iter());
                break;
            }
            if used > 0 {
                lines.push(String::new());
                continue;
            }
            // A word longer than a whole line: cut it.
            let rest = word.split_off(width);
            last.extend(word.iter());
            word = rest;
            lines.push(String::new());
        }
    }
    lines
}

/// A triangle count, short.
fn count_text(n: u64) -> String {
    if n >= 1_000_000 {
        format!("{:.2} M", n as f64 / 1e6)
    } else if n >= 1000 {
        format!("{:.1} k", n as f64 / 1e3)
    } else {
        n.to_string()
    }
}

/// `redraw: retained, N of M triangles` for a frame drawn from the static layer (N ≤ M: the
/// dragged part and what lies after it in draw order, of a full frame's M), `redraw: layer
/// built, …` for the frame that made the layer (a full frame, then the dragged part again, so
/// N > M there), else `redraw: full`.
fn redraw_line(retained: Option<(u64, u64)>, layer_built: bool) -> String {
    match retained {
        Some((n, m)) if layer_built => format!(
            "redraw: layer built, {} triangles (a full frame of {} and the dragged part again)",
            count_text(n),
            count_text(m)
        ),
        Some((n, m)) => format!(
            "redraw: retained, {} of {} triangles",
            count_text(n),
            count_text(m)
        ),
        None => "redraw: full".into(),
    }
}

/// The level-of-detail line: surface triangles drawn and what the full grids would take.
fn lod_line((drawn, full): (u64, u64)) -> String {
    let k = count_text;
    if full == 0 {
        "LOD: no surfaces".into()
    } else if drawn == full {
        format!("LOD full: {} triangles", k(full))
    } else {
        format!("LOD: {} of {} triangles", k(drawn), k(full))
    }
}

/// The key help, laid out to fit a `width × height` image on an opaque panel: two columns
/// at the normal text size with the descriptions word-wrapped to the space left, or at the
/// small size when even that does not fit. Draw it last, above every other overlay.
#[must_use]
pub fn help_overlay(font: &Font, width: f32, height: f32) -> Vec<OverlayVertex> {
    let mut v = Vec::new();
    let title = "prespline keys (H or F1 closes)";
    let key_chars = KEY_HELP
        .iter()
        .map(|(k, _)| k.chars().count())
        .max()
        .unwrap_or(0)
        + 3;
    let layout = help_layout(font, width, height, key_chars);
    let HelpLayout {
        size,
        rows,
        panel: [x, y, panel_w, panel_h],
    } = layout;
    let m = font.metrics(size);
    let (advance, line) = (m.advance as f32, m.line_height as f32 + 2.0);
    push_rect(&mut v, x, y, panel_w, panel_h, HELP_PANEL);
    font.push_text(&mut v, title, x + 12.0, y + 10.0, size, TEXT);
    let mut row = 1.5f32;
    for (key, desc) in rows {
        let ty = y + 10.0 + row * line;
        font.push_text(&mut v, key, x + 12.0, ty, size, DIM);
        for (k, part) in desc.iter().enumerate() {
            let dx = x + 12.0 + key_chars as f32 * advance;
            font.push_text(&mut v, part, dx, ty + k as f32 * line, size, TEXT);
        }
        row += desc.len() as f32;
    }
    v
}

/// Where the help goes and at which size.
struct HelpLayout {
    size: TextSize,
    rows: Vec<(&'static str, Vec<String>)>,
    /// x, y, width, height in pixels.
    panel: [f32; 4],
}

/// The normal size when its wrapped rows fit the window, else the small one.
fn help_layout(font: &Font, width: f32, height: f32, key_chars: usize) -> HelpLayout {
    let margin = 20.0;
    let at = |size: TextSize| {
        let m = font.metrics(size);
        let (advance, line) = (m.advance as f32, m.line_height as f32 + 2.0);
        let panel_w = (width - 2.0 * margin).max(0.0);
        let desc_chars =
            (((panel_w - 24.0) / advance).floor().max(0.0) as usize).saturating_sub(key_chars);
        let rows: Vec<(&str, Vec<String>)> = KEY_HELP
            .iter()
            .map(|&(k, d)| (k, wrap(d, desc_chars.max(12))))
            .collect();
        let lines = rows.iter().map(|(_, d)| d.len()).sum::<usize>() as f32 + 1.5;
        let panel_h = lines * line + 20.0;
        let fits = desc_chars >= 24 && panel_h <= height - 2.0 * margin;
        let y = ((height - panel_h) * 0.5).max(0.0).round();
        let layout = HelpLayout {
            size,
            rows,
            panel: [margin, y, panel_w, panel_h],
        };
        (layout, fits)
    };
    let (normal, fits) = at(TextSize::Normal);
    if fits { normal } else { at(TextSize::Small).0 }
}

/// Greedy word wrap to lines of at most `width` characters (longer words stay whole).
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in text.split(' ') {
        let last = lines.last_mut().expect("never empty");
        if last.is_empty() {
            last.push_str(word);
        } else if last.len() + 1 + word.len() <= width {
            last.push(' ');
            last.push_str(word);
        } else {
            lines.push(word.to_string());
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_redraw_line_says_how_the_frame_was_drawn() {
        assert_eq!(
            redraw_line(Some((1900, 522_200)), false),
            "redraw: retained, 1.9 k of 522.2 k triangles"
        );
        assert_eq!(redraw_line(None, false), "redraw: full");
        // The frame that builds the layer draws more than a full frame, and says why.
        assert_eq!(
            redraw_line(Some((23_600, 19_000)), true),
            "redraw: layer built, 23.6 k triangles (a full frame of 19.0 k and the dragged part again)"
        );
        assert_eq!(lod_line((0, 0)), "LOD: no surfaces");
        assert_eq!(lod_line((10, 10)), "LOD full: 10 triangles");
        let hud = Hud {
            retained: Some((12, 2_000_000)),
            ..Hud::new()
        };
        assert_eq!(hud.lines()[3], "redraw: retained, 12 of 2.00 M triangles");
    }

    /// Every vertex of the help overlay inside the window.
    fn fits(width: f32, height: f32) -> bool {
        let v = help_overlay(&Font::new(1.0), width, height);
        !v.is_empty()
            && v.iter()
                .all(|p| (0.0..=width).contains(&p.pos[0]) && (0.0..=height).contains(&p.pos[1]))
    }

    #[test]
    fn help_fits_common_windows() {
        for (w, h) in [
            (1280.0, 720.0),
            (960.0, 600.0),
            (800.0, 600.0),
            (1920.0, 1080.0),
        ] {
            assert!(fits(w, h), "help overflows {w}x{h}");
        }
        // Negative control: a window narrower than the key column cannot hold it.
        assert!(!fits(200.0, 150.0));
    }

    #[test]
    fn status_fits_wraps_or_elides_the_middle_keeping_the_end() {
        let font = Font::new(1.0);
        let width = 800.0;
        let fit = font.chars_fitting(width - 2.0 * STATUS_MARGIN, TextSize::Normal);
        assert_eq!(status_lines(&font, width, "saved"), vec!["saved"]);
        let two = "word ".repeat(fit / 5 + 3);
        let lines = status_lines(&font, width, two.trim());
        assert_eq!(lines.len(), 2);
        assert_eq!(lines.join(" "), two.trim());
        let long = format!(
            "s: cannot save: {} is not a rational function, so save it as a .json scene instead",
            "the ERBS surface ".repeat(12)
        );
        let lines = status_lines(&font, width, &long);
        assert_eq!(lines.len(), 2);
        assert!(lines[0].starts_with("s: cannot save:"), "{lines:?}");
        assert!(lines[1].starts_with("… "), "{lines:?}");
        assert!(
            lines[1].ends_with("save it as a .json scene instead"),
            "{lines:?}"
        );
        assert!(lines.iter().all(|l| l.chars().count() <= fit), "{lines:?}");
        // A single word longer than the line is cut, not lost at the edge.
        let word = "x".repeat(fit + 5);
        let lines = status_lines(&font, width, &word);
        assert!(lines.iter().all(|l| l.chars().count() <= fit));
        assert_eq!(lines.concat(), word);
    }

    #[test]
    fn wrap_breaks_at_words() {
        assert_eq!(wrap("a bb ccc dd", 5), vec!["a bb", "ccc", "dd"]);
        assert_eq!(wrap("word", 2), vec!["word"]);
    }
}
