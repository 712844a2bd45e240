//! The profiling module used from outside the crate, as `prespline bench` will: record a short
//! run, write every report, read the summary back and compare two runs. Checks structure only.

use prespline::profile::{
    CSV_HEADER, Phase, Progress, Recorder, RunInfo, Summary, compare, read_summary_json, write_all,
};
use std::hint::black_box;
use std::path::Path;

fn record_run(frames: usize, warmup: usize, work: u64) -> Vec<prespline::profile::FrameRecord> {
    let mut rec = Recorder::with_capacity(warmup, frames);
    let progress = Progress::hidden("record", Some(frames as u64)).unit("frames");
    for i in 0..frames {
        rec.begin_frame();
        rec.phase_start(Phase::Input);
        rec.phase_start(Phase::Delta);
        black_box((0..work).sum::<u64>());
        rec.add_samples(work);
        rec.phase_start(Phase::Upload);
        rec.add_bytes(work * 12);
        let _cmds = rec.time(Phase::Record, || black_box(vec![0u8; 64]));
        rec.phase_start(Phase::Submit);
        rec.phase_start(Phase::Present);
        rec.end_frame();
        // GPU times arrive two frames late; the last two never do.
        if i >= 2 {
            assert!(rec.set_gpu_ms(i - 2, 0.1));
        }
        progress.inc(1);
    }
    assert_eq!(progress.done(), frames as u64);
    progress.finish();
    rec.into_frames()
}

#[test]
fn recorded_run_writes_readable_reports() {
    let frames = record_run(50, 5, 20_000);
    assert_eq!(frames.iter().filter(|f| f.gpu_ms.is_none()).count(), 2);
    for f in &frames {
        assert!(f.cpu_ms() <= f.frame_ms + 1e-6, "{f:?}");
        assert_eq!(f.samples_touched, 20_000);
    }

    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("profile_outputs");
    let _ = std::fs::remove_dir_all(&dir);
    let run = RunInfo {
        scenario: "sum".into(),
        frames: 50,
        warmup_frames: 5,
        mode: "incremental".into(),
        ..RunInfo::default()
    };
    let paths = write_all(&dir, &run, &frames).unwrap();
    assert_eq!(paths.len(), 6);
    assert!(paths.iter().all(|p| p.starts_with(&dir) && p.is_file()));

    let csv = std::fs::read_to_string(dir.join("frames.csv")).unwrap();
    assert_eq!(csv.lines().next(), Some(CSV_HEADER));
    assert_eq!(csv.lines().count(), 51);

    let file = read_summary_json(&dir.join("summary.json")).unwrap();
    assert_eq!(file.run, run);
    let summary = file.summary;
    assert_eq!(summary.measured.as_ref().unwrap().frames, 45);
    assert_eq!(summary.warmup.as_ref().unwrap().frames, 5);

    let naive = Summary::from_frames(&record_run(50, 5, 200_000));
    let table = compare("incremental", &summary, "naive", &naive);
    assert_eq!(table.lines().count(), 2 + 2 + Phase::ALL.len() + 6);
    assert!(summary.table().contains("1% low"));
}
