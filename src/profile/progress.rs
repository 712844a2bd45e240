//! Throttled progress line for long runs: `frame 1200/5000 (24%), 8.3 ms/frame`.

use std::io::{self, IsTerminal, Stderr, Write};
use std::time::{Duration, Instant};

/// Default time between two progress lines.
pub const PROGRESS_INTERVAL: Duration = Duration::from_millis(250);

/// Prints a progress line at most every `interval` (4 per second by default).
///
/// On a terminal the line is redrawn in place (`\r`); otherwise each update is a new line, so
/// a forced progress in a log stays readable. Write errors are ignored: progress is cosmetic
/// and must never stop a run.
pub struct Progress<W: Write = Stderr> {
    out: Option<W>,
    in_place: bool,
    total: Option<usize>,
    interval: Duration,
    last_print: Instant,
    last_done: usize,
    last_len: usize,
}

impl Progress<Stderr> {
    /// Prints to stderr only when stderr is a terminal. `total` is the number of frames, if
    /// known.
    pub fn new(total: Option<usize>) -> Self {
        let terminal = io::stderr().is_terminal();
        Self::stderr(total, terminal)
    }

    /// Prints to stderr when `enabled` (e.g. a `--progress` flag), in place on a terminal.
    pub fn stderr(total: Option<usize>, enabled: bool) -> Self {
        let in_place = io::stderr().is_terminal();
        Progress::to_writer(enabled.then(io::stderr), total, in_place)
    }
}

impl<W: Write> Progress<W> {
    /// Prints to `out` (nothing when `None`), redrawing in place when `in_place`.
    pub fn to_writer(out: Option<W>, total: Option<usize>, in_place: bool) -> Self {
        Progress {
            out,
            in_place,
            total,
            interval: PROGRESS_INTERVAL,
            last_print: Instant::now(),
            last_done: 0,
            last_len: 0,
        }
    }

    pub fn with_interval(mut self, interval: Duration) -> Self {
        self.interval = interval;
        self
    }

    /// Reports that `done` frames are complete. Cheap when it does not print: one clock read.
    pub fn update(&mut self, done: usize) {
        if self.out.is_none() {
            return;
        }
        let now = Instant::now();
        if now.duration_since(self.last_print) >= self.interval {
            self.print(done, now);
        }
    }

    /// Prints the final state and ends the line.
    pub fn finish(&mut self, done: usize) {
        if self.out.is_none() {
            return;
        }
        if done != self.last_done || self.last_len == 0 {
            self.print(done, Instant::now());
        }
        if self.in_place
            && let Some(out) = &mut self.out
        {
            let _ = writeln!(out);
            let _ = out.flush();
        }
        self.out = None;
    }

    fn print(&mut self, done: usize, now: Instant) {
        // Rate over the last interval rather than the whole run: shows the current pace.
        let frames = done.saturating_sub(self.last_done);
        let ms_per_frame = (frames > 0)
            .then(|| now.duration_since(self.last_print).as_secs_f64() * 1e3 / frames as f64);
        let line = progress_line(done, self.total, ms_per_frame);
        let Some(out) = &mut self.out else { return };
        let _ = if self.in_place {
            let pad = self.last_len.saturating_sub(line.len());
            write!(out, "\r{line}{:pad$}", "")
        } else {
            writeln!(out, "{line}")
        };
        let _ = out.flush();
        self.last_len = line.len();
        self.last_print = now;
        self.last_done = done;
    }
}

/// `frame 1200/5000 (24%), 8.3 ms/frame`; parts that are unknown are left out.
pub fn progress_line(done: usize, total: Option<usize>, ms_per_frame: Option<f64>) -> String {
    let mut line = format!("frame {done}");
    if let Some(total) = total.filter(|&t| t > 0) {
        let percent = done.min(total) * 100 / total;
        line.push_str(&format!("/{total} ({percent}%)"));
    }
    if let Some(ms) = ms_per_frame {
        line.push_str(&format!(", {ms:.1} ms/frame"));
    }
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_format() {
        assert_eq!(
            progress_line(1200, Some(5000), Some(8.31)),
            "frame 1200/5000 (24%), 8.3 ms/frame"
        );
        assert_eq!(progress_line(7, None, None), "frame 7");
    }

    #[test]
    fn throttles_and_finishes() {
        let mut buf = Vec::new();
        {
            let mut p = Progress::to_writer(Some(&mut buf), Some(100), false)
                .with_interval(Duration::from_secs(3600));
            for done in 1..=100 {
                p.update(done);
            }
            p.finish(100);
        }
        let text = String::from_utf8(buf).unwrap();
        // The hour-long interval suppresses every update; only `finish` prints.
        assert_eq!(text.lines().count(), 1, "{text}");
        assert!(text.starts_with("frame 100/100 (100%)"), "{text}");
    }

    #[test]
    fn disabled_prints_nothing() {
        let mut p = Progress::<Vec<u8>>::to_writer(None, Some(10), false);
        p.update(5);
        p.finish(10);
        assert!(p.out.is_none());
    }
}
