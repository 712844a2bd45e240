//! `trace.json`: the run in the Chrome trace event format, for chrome://tracing and
//! ui.perfetto.dev.
//!
//! One process with three tracks: "frames" (one slice per frame), "CPU phases" (the phases of
//! each frame) and "GPU", plus counter tracks for bytes uploaded and samples touched. Times
//! are in µs from the first frame.
//!
//! Only phase durations are recorded, not when each phase started, so phases are laid out
//! back to back in [`Phase`] order from the frame start; time covered by no phase shows as a
//! gap at the end of the frame. GPU slices start when the frame's `submit` phase ends, or when
//! the previous GPU slice ends if later, since one queue runs its work in order. Both are
//! approximations of where the work happened, exact in duration.

use super::{FrameRecord, Phase, ProfileError, RunInfo, write_file};
use serde::Serialize;
use serde_json::{Value, json};
use std::io::{self, Write};
use std::path::Path;

const PID: u32 = 1;
const TID_FRAMES: u32 = 1;
const TID_CPU: u32 = 2;
const TID_GPU: u32 = 3;

#[derive(Serialize)]
struct Event<'a> {
    name: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    cat: Option<&'a str>,
    ph: &'a str,
    ts: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    dur: Option<f64>,
    pid: u32,
    tid: u32,
    #[serde(skip_serializing_if = "Value::is_null")]
    args: Value,
}

/// Streams events as elements of the `traceEvents` array.
struct EventWriter<'w, W: Write> {
    w: &'w mut W,
    first: bool,
}

impl<W: Write> EventWriter<'_, W> {
    fn event(&mut self, e: &Event) -> io::Result<()> {
        self.w.write_all(if self.first { b"\n" } else { b",\n" })?;
        self.first = false;
        serde_json::to_writer(&mut *self.w, e)?;
        Ok(())
    }

    fn metadata(&mut self, name: &str, tid: u32, args: Value) -> io::Result<()> {
        self.event(&Event {
            name,
            cat: None,
            ph: "M",
            ts: 0.0,
            dur: None,
            pid: PID,
            tid,
            args,
        })
    }

    fn slice(
        &mut self,
        name: &str,
        cat: &str,
        tid: u32,
        span: (f64, f64),
        args: Value,
    ) -> io::Result<()> {
        self.event(&Event {
            name,
            cat: Some(cat),
            ph: "X",
            ts: span.0,
            dur: Some(span.1),
            pid: PID,
            tid,
            args,
        })
    }

    fn counter(&mut self, name: &str, ts: f64, args: Value) -> io::Result<()> {
        self.event(&Event {
            name,
            cat: None,
            ph: "C",
            ts,
            dur: None,
            pid: PID,
            tid: TID_FRAMES,
            args,
        })
    }
}

/// Places slices on one track so that they never overlap: viewers mis-nest overlapping
/// slices of one thread. Overlap only arises from hand-made records or the GPU estimate.
#[derive(Default)]
struct Track {
    end_us: f64,
}

impl Track {
    /// `(ts, dur)` in µs, rounded to ns, starting no earlier than the previous slice's end.
    fn place(&mut self, start_ms: f64, dur_ms: f64) -> (f64, f64) {
        let ts = round_ns(start_ms * 1e3).max(self.end_us);
        let dur = round_ns(dur_ms * 1e3);
        self.end_us = ts + dur;
        (ts, dur)
    }
}

fn round_ns(us: f64) -> f64 {
    (us * 1e3).round() / 1e3
}

pub fn write_trace_json(
    path: &Path,
    run: &RunInfo,
    frames: &[FrameRecord],
) -> Result<(), ProfileError> {
    write_file(path, |w| write_trace_json_to(w, run, frames))
}

/// Writes the trace to any writer.
pub fn write_trace_json_to(
    w: &mut impl Write,
    run: &RunInfo,
    frames: &[FrameRecord],
) -> io::Result<()> {
    w.write_all(b"{\"displayTimeUnit\":\"ms\",\"otherData\":")?;
    serde_json::to_writer(&mut *w, run)?;
    w.write_all(b",\"traceEvents\":[")?;
    let mut ev = EventWriter { w, first: true };

    let process = if run.scenario.is_empty() {
        "prespline".to_string()
    } else {
        format!("prespline: {}", run.scenario)
    };
    ev.metadata("process_name", 0, json!({ "name": process }))?;
    for (tid, name) in [
        (TID_FRAMES, "frames"),
        (TID_CPU, "CPU phases"),
        (TID_GPU, "GPU"),
    ] {
        ev.metadata("thread_name", tid, json!({ "name": name }))?;
        ev.metadata("thread_sort_index", tid, json!({ "sort_index": tid }))?;
    }

    let (mut frame_track, mut cpu_track, mut gpu_track) =
        (Track::default(), Track::default(), Track::default());
    for f in frames {
        let start_ms = f.start_s * 1e3;
        let cat = if f.warmup { "warmup" } else { "frame" };
        let args = json!({
            "index": f.index,
            "warmup": f.warmup,
            "frame_ms": f.frame_ms,
            "gpu_ms": f.gpu_ms,
            "bytes_uploaded": f.bytes_uploaded,
            "samples_touched": f.samples_touched,
        });
        let name = if f.warmup { "frame (warm-up)" } else { "frame" };
        ev.slice(
            name,
            cat,
            TID_FRAMES,
            frame_track.place(start_ms, f.frame_ms),
            args,
        )?;
        ev.counter(
            "bytes_uploaded",
            round_ns(start_ms * 1e3),
            json!({ "bytes": f.bytes_uploaded }),
        )?;
        ev.counter(
            "samples_touched",
            round_ns(start_ms * 1e3),
            json!({ "samples": f.samples_touched }),
        )?;

        let mut offset_ms = start_ms;
        let mut submit_end_ms = start_ms;
        for phase in Phase::ALL {
            let dur = f.phase_ms[phase];
            if dur > 0.0 {
                let args = json!({ "frame": f.index });
                ev.slice(
                    phase.name(),
                    "cpu",
                    TID_CPU,
                    cpu_track.place(offset_ms, dur),
                    args,
                )?;
            }
            offset_ms += dur.max(0.0);
            if phase == Phase::Submit {
                submit_end_ms = offset_ms;
            }
        }
        if let Some(gpu) = f.gpu_ms.filter(|g| *g > 0.0) {
            let args = json!({ "frame": f.index });
            ev.slice(
                "gpu",
                "gpu",
                TID_GPU,
                gpu_track.place(submit_end_ms, gpu),
                args,
            )?;
        }
    }
    ev.w.write_all(b"\n]}\n")
}
