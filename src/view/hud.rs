//! The on-screen overlay: frame-time graph, edit cost, samples touched, bytes copied to the GPU,
//! GPU time; the status line; and the key help.

use crate::gpu::OverlayVertex;
use crate::gpu::font::{ADVANCE, LINE_HEIGHT, push_rect, push_text};
use std::collections::VecDeque;

/// Frames kept in the graph.
const HISTORY: usize = 240;
const TEXT: [u8; 4] = [230, 232, 238, 255];
const DIM: [u8; 4] = [150, 155, 165, 255];
const PANEL: [u8; 4] = [10, 12, 16, 190];

/// Every key binding, as shown by the help overlay (H or F1); docs/viewer.md and the README's key
/// table describe the same keys.
pub const KEY_HELP: &[(&str, &str)] = &[
    (
        "left drag on a point",
        "move it in the view plane (X/Y/Z while dragging: along an axis)",
    ),
    ("left drag elsewhere", "orbit"),
    (
        "middle drag / right drag / shift+left drag",
        "orbit / pan / pan",
    ),
    ("wheel", "zoom to the cursor"),
    (
        "click a point",
        "select it (ERBS: selects its local curve/patch too)",
    ),
    (
        "G / R / S",
        "grab / rotate / scale the selected local curve or patch (G also a point)",
    ),
    (
        "  X / Y / Z, digits, Enter",
        "axis constraint, typed value (distance, degrees, factor), confirm",
    ),
    ("  Esc / right click", "cancel the transform"),
    (
        "I",
        "insert a knot at the cursor on the selected curve or surface (U/V direction)",
    ),
    (
        "  on ERBS",
        "refine at the cursor: a new local (row/column of patches) in the selected local's level",
    ),
    (
        "X",
        "turn the selected ERBS local into an ERBS of its own (3 locals per direction, same shape)",
    ),
    (
        "E / Shift+E",
        "elevate the degree of the selected curve or surface (in u / in v)",
    ),
    (
        "Alt+drag on a point / Shift+W",
        "change its weight (up: heavier) / type its weight; a polynomial object becomes rational",
    ),
    (
        "B",
        "convert the selected Catmull-Rom or Bezier spline to a bspline_curve",
    ),
    (
        "J / O",
        "continuity badges at joins / osculating circle, curvature, torsion at the cursor",
    ),
    (
        "M",
        "surface map: Gaussian, mean, max and min principal curvature, zebra, off",
    ),
    ("Ctrl+Z / Ctrl+Shift+Z (Ctrl+Y)", "undo / redo"),
    ("Ctrl+S", "save the scene file"),
    ("F / A / Home", "frame selection / frame all / reset camera"),
    (
        "C / L / W",
        "control nets / local curves / wireframe (off, isolines, full)",
    ),
    ("N / T / K", "normals / Frenet frames / curvature combs"),
    (
        "D",
        "level of detail on/off (dense surfaces drawn from a strided subset)",
    ),
    ("P", "performance overlay"),
    ("H or F1", "this help"),
    ("Esc", "deselect"),
    ("Ctrl+Q or close the window", "quit"),
];

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
    pub visible: bool,
}

impl Hud {
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

    /// Overlay vertices for a `width × height` image.
    pub fn build(&self, width: f32, height: f32, status: &str, help: bool) -> Vec<OverlayVertex> {
        let mut v = Vec::new();
        let scale = 2.0;
        let line = LINE_HEIGHT as f32 * scale + 2.0;
        // The help panel covers the overlay's corner; it shows alone.
        if self.visible && !help {
            let mean = self.mean();
            let fps = if mean > 0.0 { 1000.0 / mean } else { 0.0 };
            let gpu = self
                .gpu_ms
                .map_or("n/a".to_string(), |g| format!("{g:.2} ms"));
            let lines = [
                format!("frame {mean:.2} ms ({fps:.0} fps)   GPU {gpu}"),
                format!(
                    "edit {:.1} us   {} samples   {:.1} KB to GPU",
                    self.edit_us,
                    self.samples_touched,
                    self.bytes as f64 / 1024.0
                ),
                lod_line(self.triangles),
            ];
            let (gw, gh) = (HISTORY as f32 * 2.0, 60.0);
            push_rect(
                &mut v,
                8.0,
                8.0,
                gw.max(560.0) + 16.0,
                lines.len() as f32 * line + gh + 24.0,
                PANEL,
            );
            for (k, l) in lines.iter().enumerate() {
                push_text(&mut v, l, 16.0, 14.0 + k as f32 * line, scale, TEXT);
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
                    push_rect(
                        &mut v,
                        gx,
                        gy + gh - gh * ms / full,
                        gw,
                        1.0,
                        [90, 90, 100, 255],
                    );
                }
            }
            push_text(
                &mut v,
                &format!("{full:.0} ms"),
                gx + gw + 6.0,
                gy,
                2.0,
                DIM,
            );
            for (k, &ms) in self.frames.iter().enumerate() {
                let h = (gh * ms / full).min(gh);
                let c = if ms > 33.3 {
                    [235, 80, 70, 255]
                } else if ms > 16.7 {
                    [235, 190, 60, 255]
                } else {
                    [90, 200, 120, 255]
                };
                push_rect(&mut v, gx + k as f32 * 2.0, gy + gh - h, 2.0, h, c);
            }
        }
        if !status.is_empty() {
            let y = height - line - 10.0;
            push_rect(&mut v, 0.0, y - 6.0, width, line + 12.0, PANEL);
            push_text(&mut v, status, 12.0, y, scale, TEXT);
        }
        if help {
            push_help(&mut v, width, height);
        }
        v
    }
}

/// The level-of-detail line: surface triangles drawn and what the full grids would take.
fn lod_line((drawn, full): (u64, u64)) -> String {
    let k = |n: u64| {
        if n >= 1_000_000 {
            format!("{:.2} M", n as f64 / 1e6)
        } else if n >= 1000 {
            format!("{:.1} k", n as f64 / 1e3)
        } else {
            n.to_string()
        }
    };
    if drawn == full {
        format!("LOD full: {} triangles", k(full))
    } else {
        format!("LOD: {} of {} triangles", k(drawn), k(full))
    }
}

/// The key help, laid out to fit a `width × height` window: two columns at 2× scale with the
/// descriptions word-wrapped to the space left, or at 1× when even that does not fit.
fn push_help(v: &mut Vec<OverlayVertex>, width: f32, height: f32) {
    let title = "prespline keys (H or F1 closes)";
    let key_chars = KEY_HELP.iter().map(|(k, _)| k.len()).max().unwrap_or(0) + 3;
    let margin = 20.0;
    let layout = |scale: f32| {
        let advance = ADVANCE as f32 * scale;
        let line = LINE_HEIGHT as f32 * scale + 2.0;
        let panel_w = (width - 2.0 * margin).max(0.0);
        let desc_chars = ((panel_w - 24.0) / advance).floor() as usize;
        let desc_chars = desc_chars.saturating_sub(key_chars);
        let rows: Vec<(&str, Vec<String>)> = KEY_HELP
            .iter()
            .map(|&(k, d)| (k, wrap(d, desc_chars.max(12))))
            .collect();
        let lines = rows.iter().map(|(_, d)| d.len()).sum::<usize>() as f32 + 1.5;
        (
            scale,
            advance,
            line,
            panel_w,
            desc_chars,
            rows,
            lines * line + 20.0,
        )
    };
    let mut l = layout(2.0);
    if l.4 < 24 || l.6 > height - 2.0 * margin {
        l = layout(1.0);
    }
    let (scale, advance, line, panel_w, _, rows, panel_h) = l;
    let (x, y) = (margin, ((height - panel_h) * 0.5).max(0.0));
    push_rect(v, x, y, panel_w, panel_h, [8, 10, 14, 225]);
    push_text(v, title, x + 12.0, y + 10.0, scale, TEXT);
    let mut row = 1.5f32;
    for (key, desc) in rows {
        let ty = y + 10.0 + row * line;
        push_text(v, key, x + 12.0, ty, scale, DIM);
        for (k, part) in desc.iter().enumerate() {
            let dx = x + 12.0 + key_chars as f32 * advance;
            push_text(v, part, dx, ty + k as f32 * line, scale, TEXT);
        }
        row += desc.len() as f32;
    }
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

    /// Every vertex of the help overlay inside the window.
    fn fits(width: f32, height: f32) -> bool {
        let mut v = Vec::new();
        push_help(&mut v, width, height);
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
    fn wrap_breaks_at_words() {
        assert_eq!(wrap("a bb ccc dd", 5), vec!["a bb", "ccc", "dd"]);
        assert_eq!(wrap("word", 2), vec!["word"]);
    }
}
