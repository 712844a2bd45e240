//! Plain-text tables for the terminal: [`Summary::table`] and [`compare`].

use super::{
    GPU_MEANING, LOW_1PCT_MEANING, OTHER_MEANING, PERCENTILE_MEANING, Phase, RunInfo, Section,
    Stats, Summary,
};
use comfy_table::CellAlignment;

/// Rows of cells rendered with the first column left-aligned and the others right-aligned,
/// two spaces apart, a dashed rule under the header and no borders (comfy-table with every
/// border component but the header rule removed).
struct TextTable {
    table: comfy_table::Table,
}

/// comfy-table's 19 border components, in its order; a space means "not drawn". Only
/// `HeaderLines` (the sixth) is set: the rule under the header.
const HEADER_RULE_ONLY: &str = "     -             ";

impl TextTable {
    fn new(header: &[&str]) -> Self {
        let mut table = comfy_table::Table::new();
        table
            .load_preset(HEADER_RULE_ONLY)
            .set_header(header.to_vec());
        for column in table.column_iter_mut() {
            // The gap before a column is its left padding: none before the first.
            let (padding, alignment) = match column.index {
                0 => ((0, 0), CellAlignment::Left),
                _ => ((2, 0), CellAlignment::Right),
            };
            column.set_padding(padding);
            column.set_cell_alignment(alignment);
        }
        TextTable { table }
    }

    fn row(&mut self, cells: Vec<String>) {
        self.table.add_row(cells);
    }

    /// The table, each line without trailing spaces and ending in a newline.
    fn render(&self) -> String {
        let mut out = self.table.trim_fmt();
        out.push('\n');
        out
    }
}

fn ms(v: f64) -> String {
    format!("{v:.3}")
}

fn stats_cells(label: &str, s: &Stats) -> Vec<String> {
    let mut cells = vec![label.to_string(), s.count.to_string()];
    cells.extend([s.mean, s.p50, s.p90, s.p95, s.p99, s.max, s.low_1pct].map(ms));
    cells
}

/// Bytes with a binary unit, e.g. `1.50 MiB`.
pub(super) fn human_bytes(bytes: f64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = bytes;
    let mut unit = 0;
    while v >= 1024.0 && unit + 1 < UNITS.len() {
        v /= 1024.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{v:.0} B")
    } else {
        format!("{v:.2} {}", UNITS[unit])
    }
}

/// A count with an SI suffix, e.g. `65.5 k`.
pub(super) fn human_count(count: f64) -> String {
    const UNITS: [&str; 5] = ["", " k", " M", " G", " T"];
    let mut v = count;
    let mut unit = 0;
    while v >= 1000.0 && unit + 1 < UNITS.len() {
        v /= 1000.0;
        unit += 1;
    }
    if unit == 0 {
        format!("{v:.0}")
    } else {
        format!("{v:.1}{}", UNITS[unit])
    }
}

impl Summary {
    /// Terminal table of the measured frames (times in ms): frame, each phase, "other" and
    /// GPU, then bytes and samples per frame and a warm-up line. Ends with a newline.
    #[must_use]
    pub fn table(&self) -> String {
        let Some(m) = &self.measured else {
            let mut out = format!("no measured frames ({} frames, all warm-up)\n", self.frames);
            if let Some(w) = &self.warmup {
                out.push_str(&warmup_line(w));
            }
            return out;
        };
        let mut t = TextTable::new(&[
            "phase (ms)",
            "count",
            "mean",
            "p50",
            "p90",
            "p95",
            "p99",
            "max",
            "1% low",
        ]);
        t.row(stats_cells("frame", &m.frame_ms));
        for (phase, s) in m.phase_ms.iter() {
            t.row(stats_cells(&format!("  {phase}"), s));
        }
        t.row(stats_cells("  (other)", &m.other_ms));
        match &m.gpu_ms {
            Some(g) => t.row(stats_cells("gpu", g)),
            None => t.row(vec!["gpu".into(), "0".into()]),
        }
        let mut out = t.render();
        out.push_str(&format!(
            "{:.1} fps over {} frames ({:.2} s)\n",
            m.fps, m.frames, m.duration_s
        ));
        out.push_str(&format!(
            "bytes/frame    {} (total {})\n",
            human_bytes(m.bytes_per_frame),
            human_bytes(m.bytes_uploaded as f64)
        ));
        out.push_str(&format!(
            "samples/frame  {} (total {})\n",
            human_count(m.samples_per_frame),
            human_count(m.samples_touched as f64)
        ));
        out.push_str(&format!(
            "triangles/frame {} (surface triangles drawn)\n",
            human_count(m.triangles_per_frame)
        ));
        let apart = self.layer_builds.as_ref();
        if m.retained_frames > 0 || m.layer_builds > 0 || apart.is_some() {
            out.push_str(&format!(
                "retained       {} of {} frames above drawn from the static layer\n",
                m.retained_frames, m.frames
            ));
        }
        if let Some(b) = apart {
            out.push_str(&format!(
                "layer builds   {} frame{}, mean {} ms, max {} ms (excluded above: a full redraw \
                 that saves the static layer, once per gesture)\n",
                b.frames,
                if b.frames == 1 { "" } else { "s" },
                ms(b.frame_ms.mean),
                ms(b.frame_ms.max)
            ));
        } else if m.layer_builds > 0 {
            out.push_str(&format!(
                "layer builds   {} of {} frames above (edits left the layer stale: each drew \
                 in full and saved it again)\n",
                m.layer_builds, m.frames
            ));
        }
        if let Some(w) = &self.warmup {
            out.push_str(&warmup_line(w));
        }
        out
    }
}

impl Summary {
    /// The content of `summary.txt`: what ran ([`RunInfo::header`]), [`table`](Self::table),
    /// a blank line, then [`definitions`].
    #[must_use]
    pub fn report(&self, run: &RunInfo) -> String {
        format!("{}\n{}\n{}", run.header(), self.table(), definitions())
    }
}

/// What the rows and columns of [`Summary::table`] mean, one name per line:
/// `delta    edits applied to the samples`.
#[must_use]
pub fn definitions() -> String {
    let mut rows: Vec<(&str, &str)> = Phase::ALL.map(|p| (p.name(), p.meaning())).to_vec();
    rows.extend([
        ("(other)", OTHER_MEANING),
        ("gpu", GPU_MEANING),
        ("p50..p99", PERCENTILE_MEANING),
        ("1% low", LOW_1PCT_MEANING),
    ]);
    rows.iter()
        .map(|(name, meaning)| format!("{name:<10}{meaning}\n"))
        .collect()
}

fn warmup_line(w: &Section) -> String {
    format!(
        "warm-up        {} frames, mean {} ms, max {} ms (excluded above)\n",
        w.frames,
        ms(w.frame_ms.mean),
        ms(w.frame_ms.max)
    )
}

/// Side-by-side table of two runs' measured frames, e.g. `compare("incremental", &inc,
/// "naive", &naive)`: mean and p99 of frame, phase and GPU times, and bytes and samples per
/// frame, each with the ratio B/A (above 1: B is slower or moves more data).
pub fn compare(a_name: &str, a: &Summary, b_name: &str, b: &Summary) -> String {
    let mut t = TextTable::new(&["ms", "mean A", "mean B", "B/A", "p99 A", "p99 B", "B/A"]);
    let (ma, mb) = (a.measured.as_ref(), b.measured.as_ref());
    let row = |label: &str, sa: Option<&Stats>, sb: Option<&Stats>| {
        let mean = |s: Option<&Stats>| s.map(|s| s.mean);
        let p99 = |s: Option<&Stats>| s.map(|s| s.p99);
        let mut cells = vec![label.to_string()];
        cells.extend(value_pair(mean(sa), mean(sb), ms));
        cells.extend(value_pair(p99(sa), p99(sb), ms));
        cells
    };
    t.row(row(
        "frame",
        ma.map(|m| &m.frame_ms),
        mb.map(|m| &m.frame_ms),
    ));
    for phase in Phase::ALL {
        t.row(row(
            &format!("  {phase}"),
            ma.map(|m| &m.phase_ms[phase]),
            mb.map(|m| &m.phase_ms[phase]),
        ));
    }
    t.row(row(
        "  (other)",
        ma.map(|m| &m.other_ms),
        mb.map(|m| &m.other_ms),
    ));
    t.row(row(
        "gpu",
        ma.and_then(|m| m.gpu_ms.as_ref()),
        mb.and_then(|m| m.gpu_ms.as_ref()),
    ));
    let per_frame = |label: &str, get: fn(&Section) -> f64, fmt: fn(f64) -> String| {
        let mut cells = vec![label.to_string()];
        cells.extend(value_pair(ma.map(get), mb.map(get), fmt));
        cells
    };
    t.row(per_frame("bytes/frame", |m| m.bytes_per_frame, human_bytes));
    t.row(per_frame(
        "samples/frame",
        |m| m.samples_per_frame,
        human_count,
    ));
    t.row(per_frame(
        "triangles/frame",
        |m| m.triangles_per_frame,
        human_count,
    ));
    t.row(per_frame(
        "layer builds",
        |m| m.layer_builds as f64,
        human_count,
    ));
    format!("A = {a_name}, B = {b_name}\n{}", t.render())
}

/// `[a, b, b/a]` cells; `-` for a missing value or an undefined ratio.
fn value_pair(a: Option<f64>, b: Option<f64>, fmt: fn(f64) -> String) -> [String; 3] {
    let cell = |v: Option<f64>| v.map_or_else(|| "-".to_string(), fmt);
    let ratio = match (a, b) {
        (Some(a), Some(b)) if a > 0.0 => format!("{:.2}x", b / a),
        (Some(a), Some(b)) if a == 0.0 && b == 0.0 => "1.00x".to_string(),
        _ => "-".to_string(),
    };
    [cell(a), cell(b), ratio]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_columns_are_aligned() {
        let mut t = TextTable::new(&["name", "value"]);
        t.row(vec!["a".into(), "1.000".into()]);
        t.row(vec!["longer".into(), "10.000".into()]);
        let text = t.render();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "name     value");
        assert_eq!(lines[1], "-".repeat(14));
        assert_eq!(lines[2], "a        1.000");
        assert_eq!(lines[3], "longer  10.000");
    }

    #[test]
    fn human_units() {
        assert_eq!(human_bytes(512.0), "512 B");
        assert_eq!(human_bytes(1536.0), "1.50 KiB");
        assert_eq!(human_bytes(3.0 * 1024.0 * 1024.0), "3.00 MiB");
        assert_eq!(human_count(999.0), "999");
        assert_eq!(human_count(65_536.0), "65.5 k");
    }

    #[test]
    fn ratios() {
        assert_eq!(value_pair(Some(2.0), Some(6.0), ms)[2], "3.00x");
        assert_eq!(value_pair(Some(0.0), Some(1.0), ms)[2], "-");
        assert_eq!(value_pair(None, Some(1.0), ms), ["-", "1.000", "-"]);
    }
}
