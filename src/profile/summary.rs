//! Run statistics ([`Summary`]) and their JSON file.

use super::{FrameRecord, PhaseMap, ProfileError, Stats, write_file};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

/// What was run; filled by the caller and stored verbatim in `summary.json` and the trace.
/// Empty strings mean "not applicable".
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct RunInfo {
    /// Benchmark scenario, e.g. `"drag-surface"`.
    pub scenario: String,
    /// Scene file or built-in scene name.
    pub scene: String,
    /// Problem size as text, e.g. `"512x512 samples"`.
    pub size: String,
    /// Frames requested, warm-up included.
    pub frames: usize,
    pub warmup_frames: usize,
    /// GPU / device name.
    pub device: String,
    /// Update strategy, e.g. `"incremental"` or `"naive"`.
    pub mode: String,
    /// Anything else worth keeping with the numbers (window size, present mode, commit...).
    pub extra: BTreeMap<String, serde_json::Value>,
}

impl RunInfo {
    /// Adds a free-form key/value.
    pub fn with(mut self, key: impl Into<String>, value: impl Into<serde_json::Value>) -> Self {
        self.extra.insert(key.into(), value.into());
        self
    }

    /// The lines that head `summary.txt`: the scenario on the scene, the size, the mode and
    /// every extra (redraw mode, target…), then the device.
    #[must_use]
    pub fn header(&self) -> String {
        let mut what = format!("{} on {}", self.scenario, self.scene);
        for part in [&self.size, &self.mode] {
            if !part.is_empty() {
                what.push_str(&format!(", {part}"));
            }
        }
        let extras: Vec<String> = self
            .extra
            .iter()
            .map(|(k, v)| match v {
                serde_json::Value::String(s) => format!("{k} {s}"),
                other => format!("{k} {other}"),
            })
            .collect();
        let mut out = format!(
            "run: {what}; {} frames + {} warm-up\n",
            self.frames, self.warmup_frames
        );
        if !extras.is_empty() {
            out.push_str(&format!("     {}\n", extras.join(", ")));
        }
        if !self.device.is_empty() {
            out.push_str(&format!("device: {}\n", self.device));
        }
        out
    }

    /// One line naming the run, for titles: the non-empty descriptive fields joined by " · ".
    pub fn description(&self) -> String {
        [&self.scene, &self.size, &self.mode, &self.device]
            .into_iter()
            .filter(|s| !s.is_empty())
            .map(String::as_str)
            .collect::<Vec<_>>()
            .join(" · ")
    }
}

/// Statistics of one group of frames (measured or warm-up). Times in ms.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Section {
    pub frames: usize,
    /// Sum of the frame times, in seconds.
    pub duration_s: f64,
    /// Frames per second over the section: `frames / duration_s`.
    pub fps: f64,
    pub frame_ms: Stats,
    pub phase_ms: PhaseMap<Stats>,
    /// Frame time covered by no phase; see [`FrameRecord::other_ms`].
    pub other_ms: Stats,
    /// Over the frames that have a GPU time; `None` when none has.
    pub gpu_ms: Option<Stats>,
    pub bytes_uploaded: u64,
    pub samples_touched: u64,
    pub bytes_per_frame: f64,
    pub samples_per_frame: f64,
    /// Surface triangles drawn per frame (a retained frame counts what it drew again).
    #[serde(default)]
    pub triangles_per_frame: f64,
    /// Frames drawn from a gesture's static layer.
    #[serde(default)]
    pub retained_frames: usize,
    /// Frames that built a static layer (see [`Summary::layer_builds`]).
    #[serde(default)]
    pub layer_builds: usize,
}

impl Section {
    /// `None` for no frames.
    #[must_use]
    pub fn from_frames(frames: &[&FrameRecord]) -> Option<Section> {
        let n = frames.len();
        let frame_ms = Stats::from_values(frames.iter().map(|f| f.frame_ms))?;
        // Phase and "other" times are finite for recorded frames, so their sets are never
        // empty when the frame times are not; the fallback only covers hand-made NaNs.
        let stats_of = |get: &dyn Fn(&FrameRecord) -> f64| {
            Stats::from_values(frames.iter().map(|f| get(f))).unwrap_or(Stats::EMPTY)
        };
        let duration_s = frames.iter().map(|f| f.frame_ms).sum::<f64>() / 1e3;
        let bytes_uploaded = frames.iter().map(|f| f.bytes_uploaded).sum();
        let samples_touched = frames.iter().map(|f| f.samples_touched).sum();
        let triangles: u64 = frames.iter().map(|f| f.triangles).sum();
        Some(Section {
            frames: n,
            duration_s,
            fps: if duration_s > 0.0 {
                n as f64 / duration_s
            } else {
                0.0
            },
            frame_ms,
            phase_ms: PhaseMap::from_fn(|p| stats_of(&|f| f.phase_ms[p])),
            other_ms: stats_of(&FrameRecord::other_ms),
            gpu_ms: Stats::from_values(frames.iter().filter_map(|f| f.gpu_ms)),
            bytes_uploaded,
            samples_touched,
            bytes_per_frame: bytes_uploaded as f64 / n as f64,
            samples_per_frame: samples_touched as f64 / n as f64,
            triangles_per_frame: triangles as f64 / n as f64,
            retained_frames: frames.iter().filter(|f| f.retained).count(),
            layer_builds: frames.iter().filter(|f| f.layer_built).count(),
        })
    }
}

/// Statistics of a run: measured frames and warm-up frames separately.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// All frames, warm-up included.
    pub frames: usize,
    pub warmup_frames: usize,
    /// Totals over all frames, warm-up included.
    pub bytes_uploaded: u64,
    pub samples_touched: u64,
    /// Frames not flagged warm-up, but for those that built a static layer when they are
    /// fewer than the others (a build per gesture; where most frames build one, as under
    /// `bench --naive`, building is the steady state and stays in); `None` if there are none.
    /// Percentiles then describe the steady gesture.
    pub measured: Option<Section>,
    /// Frames flagged warm-up; `None` if there are none.
    pub warmup: Option<Section>,
    /// Frames after the warm-up that built a gesture's static layer (a full redraw and the
    /// layer's saves, once per gesture), apart from `measured`; `None` if there are none.
    #[serde(default)]
    pub layer_builds: Option<Section>,
}

impl Summary {
    #[must_use]
    pub fn from_frames(frames: &[FrameRecord]) -> Summary {
        let (warmup, after): (Vec<&FrameRecord>, Vec<&FrameRecord>) =
            frames.iter().partition(|f| f.warmup);
        let (builds, steady): (Vec<&FrameRecord>, Vec<&FrameRecord>) =
            after.iter().partition(|f| f.layer_built);
        let (measured, builds) = if builds.len() < steady.len() {
            (steady, builds)
        } else {
            (after, Vec::new())
        };
        Summary {
            frames: frames.len(),
            warmup_frames: warmup.len(),
            bytes_uploaded: frames.iter().map(|f| f.bytes_uploaded).sum(),
            samples_touched: frames.iter().map(|f| f.samples_touched).sum(),
            measured: Section::from_frames(&measured),
            warmup: Section::from_frames(&warmup),
            layer_builds: Section::from_frames(&builds),
        }
    }
}

/// The content of `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryFile {
    /// Always [`SummaryFile::FORMAT`]; lets tools recognise the file.
    pub format: String,
    pub version: u32,
    /// Version of the crate that wrote the file.
    pub prespline_version: String,
    pub run: RunInfo,
    pub summary: Summary,
}

impl SummaryFile {
    pub const FORMAT: &str = "prespline-profile-summary";
    pub const VERSION: u32 = 2;

    #[must_use]
    pub fn new(run: &RunInfo, summary: &Summary) -> Self {
        SummaryFile {
            format: Self::FORMAT.into(),
            version: Self::VERSION,
            prespline_version: env!("CARGO_PKG_VERSION").into(),
            run: run.clone(),
            summary: summary.clone(),
        }
    }
}

/// `summary.json` as a pretty-printed string.
#[must_use]
pub fn summary_json(run: &RunInfo, summary: &Summary) -> String {
    // Serialising plain structs of strings, numbers and maps with string keys cannot fail.
    serde_json::to_string_pretty(&SummaryFile::new(run, summary))
        .expect("summary serialises to JSON")
}

pub fn write_summary_json(
    path: &Path,
    run: &RunInfo,
    summary: &Summary,
) -> Result<(), ProfileError> {
    let text = summary_json(run, summary);
    write_file(path, |w| {
        w.write_all(text.as_bytes())?;
        w.write_all(b"\n")
    })
}

/// Reads a `summary.json`, e.g. to compare a saved run with a new one.
pub fn read_summary_json(path: &Path) -> Result<SummaryFile, ProfileError> {
    let text = std::fs::read_to_string(path).map_err(|source| ProfileError::Read {
        path: path.to_owned(),
        source,
    })?;
    serde_json::from_str(&text).map_err(|source| ProfileError::Parse {
        path: path.to_owned(),
        source,
    })
}
