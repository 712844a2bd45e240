//! Frame-time profiling: per-frame phase timings, statistics and output files.
//!
//! Knows nothing about splines or Vulkan: the caller marks phases and reports byte and sample
//! counts; this module measures wall time, computes statistics and writes the reports.
//!
//! # Model
//!
//! A run is a sequence of frames ([`FrameRecord`]). Each frame has CPU [`Phase`]s (`input`,
//! `delta`, `upload`, `record`, `submit`, `present`), an optional GPU time that arrives later
//! ([`Recorder::set_gpu_ms`]), a frame time (start of this frame to start of the next), byte and
//! sample counters, and a warm-up flag. The first `warmup_frames` frames are warm-up: they are
//! left out of the main statistics and summarised separately.
//!
//! # Definitions
//!
//! - **Percentiles** use the nearest-rank method: the p-th percentile of n sorted values is the
//!   value at 1-based rank `ceil(p/100 · n)` (at least 1). It is always an observed value, and
//!   at least p % of the frames took no longer than it.
//! - **1 % low** is the mean of the slowest 1 % of the frames, in ms: the `ceil(n/100)` largest
//!   values (so the maximum when n ≤ 100). It is the games' "1 % low FPS" turned into times,
//!   where lower is better like every other column.
//! - **other** is the part of a frame covered by no phase (`frame_ms` − sum of phases, at
//!   least 0): idle time, or work the caller has not instrumented.
//!
//! # Use in a frame loop
//!
//! ```no_run
//! use prespline::profile::{Phase, Recorder, RunInfo, Summary, write_all};
//!
//! let mut rec = Recorder::with_capacity(10, 1000);
//! for _ in 0..1000 {
//!     rec.begin_frame();
//!     rec.phase_start(Phase::Input); /* poll events, turn them into edits */
//!     rec.phase_start(Phase::Delta); /* apply edits to the sample grids */
//!     rec.add_samples(4096);
//!     rec.phase_start(Phase::Upload); /* copy dirty ranges */
//!     rec.add_bytes(65536);
//!     rec.time(Phase::Record, || { /* record commands */ });
//!     rec.end_frame();
//!     // When a timestamp query for frame `i` becomes available: rec.set_gpu_ms(i, ms);
//! }
//! let run = RunInfo { scenario: "drag".into(), ..RunInfo::default() };
//! eprint!("{}", Summary::from_frames(rec.frames()).table());
//! write_all("out/profile".as_ref(), &run, rec.frames()).expect("profile written");
//! ```
//!
//! # Files written by [`write_all`]
//!
//! - `frames.csv`: [`write_frames_csv`]; one row per frame.
//! - `summary.json`: [`write_summary_json`]; run info and [`Summary`].
//! - `summary.txt`: [`Summary::report`]: the table of [`Summary::table`], then what each
//!   phase, the percentiles and "1% low" mean.
//! - `trace.json`: [`write_trace_json`]; Chrome trace (chrome://tracing, ui.perfetto.dev).
//! - `frame_times.svg`: [`write_frame_times_svg`]; frame time over the run, phases stacked,
//!   with a footnote naming what each phase measures.
//! - `histogram.svg`: [`write_histogram_svg`]; frame-time distribution with p50/p99 marked and
//!   the 1 % low stated, with a footnote defining them.
//!
//! The SVGs are drawn with `plotters` (SVG backend only), `frames.csv` through `csv`, the
//! tables through `comfy-table`; [`Progress`] draws with `indicatif`.

mod chart;
mod csv;
mod histogram;
mod phase;
mod plot;
mod progress;
mod recorder;
mod stats;
mod summary;
mod table;
mod trace;

pub use csv::{CSV_HEADER, write_frames_csv, write_frames_csv_to};
pub use histogram::{histogram_svg, write_histogram_svg};
pub use phase::{GPU_MEANING, OTHER_MEANING, Phase, PhaseMap};
pub use plot::{frame_times_svg, write_frame_times_svg};
pub use progress::{LOAD_PROGRESS_AFTER, Progress, TerminalProgress};
pub use recorder::{FrameRecord, Recorder};
pub use stats::{LOW_1PCT_MEANING, PERCENTILE_MEANING, Stats, percentile, slowest_mean};
pub use summary::{
    RunInfo, Section, Summary, SummaryFile, read_summary_json, summary_json, write_summary_json,
};
pub use table::{compare, definitions};
pub use trace::{write_trace_json, write_trace_json_to};

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

/// File names used by [`write_all`].
pub const FRAMES_CSV: &str = "frames.csv";
pub const SUMMARY_JSON: &str = "summary.json";
pub const SUMMARY_TXT: &str = "summary.txt";
pub const TRACE_JSON: &str = "trace.json";
pub const FRAME_TIMES_SVG: &str = "frame_times.svg";
pub const HISTOGRAM_SVG: &str = "histogram.svg";

/// A profile file could not be written or read; the message names the path.
#[derive(Debug, thiserror::Error)]
pub enum ProfileError {
    #[error("cannot write {}: {source}", path.display())]
    Write { path: PathBuf, source: io::Error },
    #[error("cannot read {}: {source}", path.display())]
    Read { path: PathBuf, source: io::Error },
    #[error("cannot draw {title}: {message}")]
    Plot { title: String, message: String },
    #[error("{}: not a profile summary: {source}", path.display())]
    Parse {
        path: PathBuf,
        source: serde_json::Error,
    },
}

/// Writes every report into `dir` (created if missing) and returns the paths written, in the
/// order listed in the module documentation.
pub fn write_all(
    dir: &Path,
    run: &RunInfo,
    frames: &[FrameRecord],
) -> Result<Vec<PathBuf>, ProfileError> {
    std::fs::create_dir_all(dir).map_err(|source| ProfileError::Write {
        path: dir.to_owned(),
        source,
    })?;
    let summary = Summary::from_frames(frames);
    let path = |name: &str| dir.join(name);

    let paths = vec![
        path(FRAMES_CSV),
        path(SUMMARY_JSON),
        path(SUMMARY_TXT),
        path(TRACE_JSON),
        path(FRAME_TIMES_SVG),
        path(HISTOGRAM_SVG),
    ];
    write_frames_csv(&paths[0], frames)?;
    write_summary_json(&paths[1], run, &summary)?;
    write_file(&paths[2], |w| w.write_all(summary.report(run).as_bytes()))?;
    write_trace_json(&paths[3], run, frames)?;
    write_frame_times_svg(&paths[4], run, frames)?;
    write_histogram_svg(&paths[5], run, frames)?;
    Ok(paths)
}

/// Creates `path` and fills it through a buffered writer, attaching the path to any error.
fn write_file(
    path: &Path,
    body: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> Result<(), ProfileError> {
    let write = || -> io::Result<()> {
        let mut w = BufWriter::new(File::create(path)?);
        body(&mut w)?;
        // Flush explicitly: BufWriter's drop swallows the last write error.
        w.flush()
    };
    write().map_err(|source| ProfileError::Write {
        path: path.to_owned(),
        source,
    })
}

#[cfg(test)]
mod tests;
