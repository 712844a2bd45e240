//! Recording per-frame phase timings with `Instant`, cheaply enough to leave on in every frame.

use super::{Phase, PhaseMap};
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// Everything measured for one frame. Times are in milliseconds unless the name says otherwise.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct FrameRecord {
    /// Position in the run, from 0; the key for [`Recorder::set_gpu_ms`].
    pub index: usize,
    /// Seconds from the start of the first frame to the start of this one.
    pub start_s: f64,
    /// One of the first `warmup_frames` frames: excluded from the main statistics.
    pub warmup: bool,
    /// Wall time from this frame's start to the next frame's start. For the last frame of a
    /// recording, which has no successor, start to [`Recorder::end_frame`].
    pub frame_ms: f64,
    /// Time spent in each CPU phase; a phase entered several times accumulates.
    pub phase_ms: PhaseMap<f64>,
    /// GPU execution time from timestamp queries; `None` until (unless) it is reported.
    pub gpu_ms: Option<f64>,
    pub bytes_uploaded: u64,
    pub samples_touched: u64,
    /// Drawn from a gesture's static layer (`--redraw retained`).
    pub retained: bool,
    /// Built a gesture's static layer: a full redraw plus the layer's saves, reported apart
    /// from the steady frames (see [`super::Summary`]).
    #[serde(default)]
    pub layer_built: bool,
    /// Surface triangles drawn (after level of detail; a retained frame's dynamic part).
    #[serde(default)]
    pub triangles: u64,
}

impl FrameRecord {
    /// Sum of the CPU phases.
    #[must_use]
    pub fn cpu_ms(&self) -> f64 {
        self.phase_ms.iter().map(|(_, ms)| ms).sum()
    }

    /// Frame time not covered by any phase (never negative).
    #[must_use]
    pub fn other_ms(&self) -> f64 {
        (self.frame_ms - self.cpu_ms()).max(0.0)
    }
}

/// Records frames as they run.
///
/// Per frame: [`begin_frame`](Self::begin_frame), any number of
/// [`phase_start`](Self::phase_start) / [`time`](Self::time) / counter calls,
/// [`end_frame`](Self::end_frame). Each phase call costs one `Instant::now()` and no
/// allocation; the frame list grows amortised (or not at all with
/// [`with_capacity`](Self::with_capacity)).
///
/// Calls that need an open frame (phases, counters) are ignored between frames, so a
/// half-instrumented loop never panics.
#[derive(Debug)]
pub struct Recorder {
    warmup_frames: usize,
    frames: Vec<FrameRecord>,
    run_start: Option<Instant>,
    /// Start of the last ended frame while no later frame has begun: its `frame_ms` is
    /// provisional until the next `begin_frame` supplies the real next start.
    provisional_start: Option<Instant>,
    open: Option<OpenFrame>,
}

#[derive(Debug)]
struct OpenFrame {
    start: Instant,
    running: Option<(Phase, Instant)>,
    record: FrameRecord,
}

impl OpenFrame {
    fn stop_phase(&mut self, now: Instant) {
        if let Some((phase, since)) = self.running.take() {
            self.record.phase_ms[phase] += ms_between(since, now);
        }
    }
}

fn ms_between(from: Instant, to: Instant) -> f64 {
    to.saturating_duration_since(from).as_secs_f64() * 1e3
}

impl Recorder {
    /// The first `warmup_frames` frames will be flagged as warm-up.
    #[must_use]
    pub fn new(warmup_frames: usize) -> Self {
        Self::with_capacity(warmup_frames, 0)
    }

    /// Like [`new`](Self::new), with room for `frames` frames so that recording never
    /// reallocates when the run length is known.
    #[must_use]
    pub fn with_capacity(warmup_frames: usize, frames: usize) -> Self {
        Recorder {
            warmup_frames,
            frames: Vec::with_capacity(frames),
            run_start: None,
            provisional_start: None,
            open: None,
        }
    }

    /// Starts a frame and returns its index. Ends the open frame first, if any, so a loop may
    /// call only this. The run's time origin is the first call.
    pub fn begin_frame(&mut self) -> usize {
        let now = Instant::now();
        if let Some(open) = self.open.take() {
            self.close(open, now);
        }
        if let Some(prev_start) = self.provisional_start.take()
            && let Some(prev) = self.frames.last_mut()
        {
            prev.frame_ms = ms_between(prev_start, now);
        }
        let run_start = *self.run_start.get_or_insert(now);
        let index = self.frames.len();
        self.open = Some(OpenFrame {
            start: now,
            running: None,
            record: FrameRecord {
                index,
                start_s: now.saturating_duration_since(run_start).as_secs_f64(),
                warmup: index < self.warmup_frames,
                ..FrameRecord::default()
            },
        });
        index
    }

    /// Ends the running phase (if any) and starts timing `phase`.
    pub fn phase_start(&mut self, phase: Phase) {
        let now = Instant::now();
        if let Some(open) = &mut self.open {
            open.stop_phase(now);
            open.running = Some((phase, now));
        }
    }

    /// Ends the running phase without starting another; time until the next phase counts
    /// as "other".
    pub fn phase_end(&mut self) {
        let now = Instant::now();
        if let Some(open) = &mut self.open {
            open.stop_phase(now);
        }
    }

    /// Runs `f` as `phase` (ending the running phase first) and returns its result.
    pub fn time<R>(&mut self, phase: Phase, f: impl FnOnce() -> R) -> R {
        self.phase_start(phase);
        let result = f();
        self.phase_end();
        result
    }

    /// Adds to the open frame's uploaded byte count.
    pub fn add_bytes(&mut self, bytes: u64) {
        if let Some(open) = &mut self.open {
            open.record.bytes_uploaded += bytes;
        }
    }

    /// What the open frame's draw did: drawn from a static layer, built one, and the surface
    /// triangles it drew.
    pub fn set_draw(&mut self, retained: bool, layer_built: bool, triangles: u64) {
        if let Some(open) = &mut self.open {
            open.record.retained = retained;
            open.record.layer_built = layer_built;
            open.record.triangles = triangles;
        }
    }

    /// Adds to the open frame's count of samples re-evaluated.
    pub fn add_samples(&mut self, samples: u64) {
        if let Some(open) = &mut self.open {
            open.record.samples_touched += samples;
        }
    }

    /// Ends the running phase and the frame. Its `frame_ms` is start-to-now until the next
    /// [`begin_frame`](Self::begin_frame) replaces it by start-to-next-start.
    pub fn end_frame(&mut self) {
        if let Some(open) = self.open.take() {
            self.close(open, Instant::now());
        }
    }

    fn close(&mut self, mut open: OpenFrame, now: Instant) {
        open.stop_phase(now);
        open.record.frame_ms = ms_between(open.start, now);
        self.provisional_start = Some(open.start);
        self.frames.push(open.record);
    }

    /// Attaches the GPU time of frame `index` (ended or still open). Returns false, recording
    /// nothing, for an unknown frame or a negative or non-finite time.
    pub fn set_gpu_ms(&mut self, index: usize, ms: f64) -> bool {
        if !(ms.is_finite() && ms >= 0.0) {
            return false;
        }
        let slot = match (self.frames.get_mut(index), &mut self.open) {
            (Some(frame), _) => &mut frame.gpu_ms,
            (None, Some(open)) if open.record.index == index => &mut open.record.gpu_ms,
            _ => return false,
        };
        *slot = Some(ms);
        true
    }

    /// Index of the open frame, if one is open.
    #[must_use]
    pub fn current_frame(&self) -> Option<usize> {
        self.open.as_ref().map(|open| open.record.index)
    }

    #[must_use]
    pub fn warmup_frames(&self) -> usize {
        self.warmup_frames
    }

    /// The ended frames, in order (`frames()[i].index == i`).
    #[must_use]
    pub fn frames(&self) -> &[FrameRecord] {
        &self.frames
    }

    /// Ends the open frame, if any, and returns all frames.
    #[must_use]
    pub fn into_frames(mut self) -> Vec<FrameRecord> {
        self.end_frame();
        self.frames
    }
}
