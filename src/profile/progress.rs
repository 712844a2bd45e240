//! Progress of long runs on stderr, through `indicatif`: on a terminal an in-place bar (or a
//! spinner when the total is unknown) with the count, the current rate and the time left;
//! off a terminal (a pipe, a file, CI) nothing at all, like other Rust command-line tools.
//!
//! ```no_run
//! use prespline::profile::Progress;
//!
//! let progress = Progress::new("pre-evaluating", Some(262_144)).unit("samples");
//! for _ in 0..64 {
//!     progress.inc(4096);
//! }
//! progress.finish();
//! ```

use super::table::human_count;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};

/// Redraws per second at most; each [`inc`](Progress::inc) in between costs an atomic add and
/// a clock read.
const REFRESH_HZ: u8 = 10;

/// Loads (parsing, pre-evaluation) that take longer than this show progress on a terminal.
pub const LOAD_PROGRESS_AFTER: std::time::Duration = std::time::Duration::from_secs(1);

/// A progress line for one piece of work, e.g. `Progress::new("bench drag", Some(130))
/// .unit("frames")`, drawn as
/// `bench drag [=========>          ] 52/130 frames (40%), 113 frames/s, 1s left`.
///
/// Dropping it unfinished (an error ended the work) clears the line, so that the error
/// message stands alone.
pub struct Progress {
    bar: ProgressBar,
    finished: bool,
    /// [`delayed`](Self::delayed): when it started, after how long it shows, and whether it
    /// does yet.
    reveal: Option<(std::time::Instant, std::time::Duration)>,
    revealed: std::sync::atomic::AtomicBool,
}

impl Progress {
    /// Draws on stderr when stderr is a terminal, and never otherwise. `label` names the
    /// work; `total` is the count at completion, if known.
    #[must_use]
    pub fn new(label: &str, total: Option<u64>) -> Self {
        Self::with_target(label, total, ProgressDrawTarget::stderr_with_hz(REFRESH_HZ))
    }

    /// Never draws: for callers that want no progress whatever stderr is.
    #[must_use]
    pub fn hidden(label: &str, total: Option<u64>) -> Self {
        Self::with_target(label, total, ProgressDrawTarget::hidden())
    }

    /// As [`new`](Self::new), but drawn only once the work has taken `after` (a load that
    /// ends within a second prints nothing).
    #[must_use]
    pub fn delayed(label: &str, total: Option<u64>, after: std::time::Duration) -> Self {
        let mut p = Self::with_target(label, total, ProgressDrawTarget::hidden());
        p.reveal = Some((std::time::Instant::now(), after));
        p
    }

    /// Shows a [`delayed`](Self::delayed) line once its time has come (on a terminal only).
    fn maybe_reveal(&self) {
        use std::sync::atomic::Ordering;
        let Some((start, after)) = self.reveal else {
            return;
        };
        if self.revealed.load(Ordering::Relaxed) || start.elapsed() < after {
            return;
        }
        if !self.revealed.swap(true, Ordering::Relaxed) {
            self.bar
                .set_draw_target(ProgressDrawTarget::stderr_with_hz(REFRESH_HZ));
        }
    }

    fn with_target(label: &str, total: Option<u64>, target: ProgressDrawTarget) -> Self {
        let bar = ProgressBar::with_draw_target(total, target).with_prefix(label.to_string());
        let progress = Progress {
            bar,
            finished: false,
            reveal: None,
            revealed: std::sync::atomic::AtomicBool::new(false),
        };
        progress.set_style("items");
        progress
    }

    /// Names what is counted (plural: "frames", "objects", "samples"); "items" by default.
    #[must_use]
    pub fn unit(self, unit: &str) -> Self {
        self.set_style(unit);
        self
    }

    fn set_style(&self, unit: &str) {
        let template = match self.bar.length() {
            Some(_) => {
                "{prefix} [{bar:30}] {human_pos}/{human_len} {unit} ({percent}%), {rate}, {eta} left"
            }
            None => "{spinner} {prefix} {human_pos} {unit}, {rate}, {elapsed}",
        };
        let (unit, rate_unit) = (unit.to_string(), unit.to_string());
        // The template is a constant with known keys, so it always parses.
        let style = ProgressStyle::with_template(template)
            .expect("valid progress template")
            .progress_chars("=> ")
            .with_key(
                "unit",
                move |_: &ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = w.write_str(&unit);
                },
            )
            .with_key(
                "rate",
                move |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = write!(w, "{}", rate(s.per_sec(), &rate_unit));
                },
            );
        self.bar.set_style(style);
    }

    /// Adds `n` to the count done.
    pub fn inc(&self, n: u64) {
        self.bar.inc(n);
        self.maybe_reveal();
    }

    /// Sets the count done.
    pub fn set(&self, done: u64) {
        self.bar.set_position(done);
        self.maybe_reveal();
    }

    /// The count done so far.
    pub fn done(&self) -> u64 {
        self.bar.position()
    }

    /// Whether nothing is drawn (stderr is no terminal, or [`hidden`](Self::hidden)).
    pub fn is_hidden(&self) -> bool {
        self.bar.is_hidden()
    }

    /// Draws the final state and leaves it on screen.
    pub fn finish(mut self) {
        self.finished = true;
        self.bar.finish();
    }
}

/// The command line's progress sink: loads that take longer than [`LOAD_PROGRESS_AFTER`] show
/// a line on a terminal, nothing otherwise.
#[derive(Debug, Clone, Copy, Default)]
pub struct TerminalProgress;

impl crate::progress::ProgressSink for TerminalProgress {
    fn start(
        &self,
        label: &str,
        total: Option<u64>,
        unit: &str,
    ) -> Box<dyn crate::progress::ProgressTask + '_> {
        Box::new(Progress::delayed(label, total, LOAD_PROGRESS_AFTER).unit(unit))
    }
}

impl crate::progress::ProgressTask for Progress {
    fn inc(&self, n: u64) {
        Progress::inc(self, n);
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        if !self.finished {
            self.bar.finish_and_clear();
        }
    }
}

/// `113 frames/s`, `3.9 frames/s`, `0.50 frames/s`, `3.4 M samples/s`: two or three
/// significant digits, with an SI suffix from 1000 on.
fn rate(per_sec: f64, unit: &str) -> String {
    let value = match per_sec {
        r if !r.is_finite() || r <= 0.0 => "0".to_string(),
        r if r < 1.0 => format!("{r:.2}"),
        r if r < 100.0 => format!("{r:.1}"),
        r if r < 1000.0 => format!("{r:.0}"),
        r => human_count(r),
    };
    format!("{value} {unit}/s")
}

#[cfg(test)]
mod tests {
    use super::*;
    use indicatif::TermLike;
    use std::io;
    use std::sync::{Arc, Mutex};

    /// A one-line terminal: writes append to the line, clearing empties it. What it holds at
    /// the end is what a person would see.
    #[derive(Debug, Default, Clone)]
    struct Screen(Arc<Mutex<String>>);

    impl Screen {
        fn current(&self) -> String {
            self.0.lock().unwrap().trim_end().to_string()
        }
    }

    impl TermLike for Screen {
        fn width(&self) -> u16 {
            120
        }
        fn move_cursor_up(&self, _: usize) -> io::Result<()> {
            Ok(())
        }
        fn move_cursor_down(&self, _: usize) -> io::Result<()> {
            Ok(())
        }
        fn move_cursor_right(&self, _: usize) -> io::Result<()> {
            Ok(())
        }
        fn move_cursor_left(&self, _: usize) -> io::Result<()> {
            Ok(())
        }
        fn write_line(&self, s: &str) -> io::Result<()> {
            self.write_str(s)
        }
        fn write_str(&self, s: &str) -> io::Result<()> {
            self.0.lock().unwrap().push_str(s);
            Ok(())
        }
        fn clear_line(&self) -> io::Result<()> {
            self.0.lock().unwrap().clear();
            Ok(())
        }
        fn flush(&self) -> io::Result<()> {
            Ok(())
        }
    }

    fn on_screen(label: &str, total: Option<u64>) -> (Progress, Screen) {
        let screen = Screen::default();
        let target = ProgressDrawTarget::term_like(Box::new(screen.clone()));
        (Progress::with_target(label, total, target), screen)
    }

    #[test]
    fn bar_shows_count_percent_and_rate() {
        let (p, screen) = on_screen("bench drag", Some(130));
        let p = p.unit("frames");
        assert!(!p.is_hidden());
        p.inc(52);
        assert!(
            screen.current().contains("] 52/130 frames (40%), "),
            "{}",
            screen.current()
        );
        p.finish();
        let line = screen.current();
        assert!(line.starts_with("bench drag ["), "{line}");
        assert!(line.contains("] 130/130 frames (100%), "), "{line}");
        assert!(line.contains(" frames/s, "), "{line}");
    }

    #[test]
    fn spinner_without_total() {
        let (p, screen) = on_screen("parsing", None);
        let p = p.unit("objects");
        p.inc(3);
        p.inc(4);
        assert_eq!(p.done(), 7);
        p.finish();
        let line = screen.current();
        assert!(line.contains("parsing 7 objects, "), "{line}");
        assert!(line.contains(" objects/s, "), "{line}");
    }

    #[test]
    fn dropping_unfinished_clears_the_line() {
        let (p, screen) = on_screen("bench", Some(10));
        p.set(5);
        drop(p);
        assert_eq!(screen.current(), "");
        // Negative control: a finished bar stays.
        let (p, screen) = on_screen("bench", Some(10));
        p.set(10);
        p.finish();
        assert!(screen.current().contains("10/10"), "{}", screen.current());
    }

    #[test]
    fn hidden_draws_nothing_but_counts() {
        let p = Progress::hidden("bench", Some(10));
        assert!(p.is_hidden());
        p.inc(4);
        assert_eq!(p.done(), 4);
        p.finish();
    }

    #[test]
    fn rate_units() {
        assert_eq!(rate(113.4, "frames"), "113 frames/s");
        assert_eq!(rate(3.4e6, "samples"), "3.4 M samples/s");
        assert_eq!(rate(0.5, "frames"), "0.50 frames/s");
        assert_eq!(rate(3.94, "frames"), "3.9 frames/s");
        assert_eq!(rate(f64::NAN, "frames"), "0 frames/s");
    }
}
