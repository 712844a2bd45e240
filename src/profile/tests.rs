//! Structure of the outputs on a synthetic run, and Recorder consistency. Never timings.

use super::*;
use serde_json::Value;
use std::hint::black_box;

/// 40 frames, 5 of them warm-up; GPU time missing on every 7th frame and the last two
/// (still in flight); a hitch at frame 20.
pub(super) fn synthetic_frames() -> Vec<FrameRecord> {
    let mut start_s = 0.0;
    (0..40)
        .map(|i| {
            let warmup = i < 5;
            let mut f = FrameRecord {
                index: i,
                start_s,
                warmup,
                bytes_uploaded: 4096 * (i as u64 % 3),
                samples_touched: 1000 + i as u64,
                gpu_ms: (i % 7 != 3 && i < 38).then_some(2.0 + 0.01 * i as f64),
                ..FrameRecord::default()
            };
            for (k, phase) in Phase::ALL.into_iter().enumerate() {
                f.phase_ms[phase] = 0.5 + 0.1 * k as f64;
            }
            f.phase_ms[Phase::Present] = if warmup { 30.0 } else { 10.0 };
            if i == 20 {
                f.phase_ms[Phase::Delta] = 50.0;
            }
            f.frame_ms = f.cpu_ms() + 0.25;
            start_s += f.frame_ms / 1e3;
            f
        })
        .collect()
}

pub(super) fn run_info() -> RunInfo {
    RunInfo {
        scenario: "drag <fast> & \"loud\"".into(),
        scene: "demo".into(),
        size: "64x64 samples".into(),
        frames: 40,
        warmup_frames: 5,
        device: "test device".into(),
        mode: "incremental".into(),
        ..RunInfo::default()
    }
    .with("window", "900x600")
    .with("seed", 7)
}

pub(super) fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("prespline-profile-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Checks that tags nest and close, and that every `&` starts an entity: enough to catch
/// unescaped text and unbalanced output without an XML parser.
pub(super) fn assert_well_formed(xml: &str) {
    let mut stack: Vec<&str> = vec![];
    let mut rest = xml;
    while let Some(open) = rest.find('<') {
        let text = &rest[..open];
        assert_entities(text);
        let close = rest[open..].find('>').expect("unterminated tag") + open;
        let tag = &rest[open + 1..close];
        assert!(!tag.contains('<'), "'<' inside tag: {tag}");
        if let Some(name) = tag.strip_prefix('/') {
            assert_eq!(stack.pop(), Some(name.trim()), "mismatched </{name}>");
        } else if !tag.ends_with('/') && !tag.starts_with('?') && !tag.starts_with('!') {
            stack.push(tag.split_whitespace().next().expect("tag name"));
        }
        assert_entities(tag);
        rest = &rest[close + 1..];
    }
    assert!(rest.trim().is_empty(), "text after the root element");
    assert!(stack.is_empty(), "unclosed tags: {stack:?}");
}

/// The content of every `<text>` element, unescaped and trimmed (plotters writes it on a line
/// of its own).
pub(super) fn svg_texts(svg: &str) -> Vec<String> {
    let mut texts = vec![];
    let mut rest = svg;
    while let Some(open) = rest.find("<text") {
        let start = rest[open..].find('>').expect("text tag ends") + open + 1;
        let end = rest[start..].find("</text>").expect("text closes") + start;
        let unescaped = rest[start..end]
            .replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&quot;", "\"")
            .replace("&apos;", "'")
            .replace("&amp;", "&");
        texts.push(unescaped.trim().to_string());
        rest = &rest[end..];
    }
    texts
}

fn assert_entities(text: &str) {
    for (i, _) in text.match_indices('&') {
        let entity_ok = ["&amp;", "&lt;", "&gt;", "&quot;", "&apos;"]
            .iter()
            .any(|e| text[i..].starts_with(e));
        assert!(entity_ok, "bare '&' in {text:?}");
    }
}

#[test]
fn recorder_phases_are_consistent() {
    let mut rec = Recorder::new(2);
    for i in 0..6 {
        assert_eq!(rec.begin_frame(), i);
        for phase in Phase::ALL {
            rec.time(phase, || black_box((0..1000u64).sum::<u64>()));
        }
        rec.add_bytes(10);
        rec.add_bytes(5);
        rec.add_samples(3);
        rec.end_frame();
    }
    let frames = rec.into_frames();
    assert_eq!(frames.len(), 6);
    for (i, f) in frames.iter().enumerate() {
        assert_eq!(f.index, i);
        assert_eq!(f.warmup, i < 2);
        assert_eq!((f.bytes_uploaded, f.samples_touched), (15, 3));
        assert!(Phase::ALL.iter().all(|&p| f.phase_ms[p] >= 0.0));
        assert!(f.frame_ms >= 0.0);
        // Phases are disjoint parts of the frame; allow float rounding only.
        assert!(f.cpu_ms() <= f.frame_ms + 1e-6, "{f:?}");
        assert_eq!(f.gpu_ms, None);
    }
    for pair in frames.windows(2) {
        assert!(pair[1].start_s >= pair[0].start_s);
        // frame_ms runs to the next frame's start.
        let gap_ms = (pair[1].start_s - pair[0].start_s) * 1e3;
        assert!((gap_ms - pair[0].frame_ms).abs() < 1e-3, "{pair:?}");
    }
    assert_eq!(frames[0].start_s, 0.0);
}

#[test]
fn recorder_phase_start_accumulates_and_ignores_calls_outside_frames() {
    let mut rec = Recorder::new(0);
    rec.phase_start(Phase::Input);
    rec.add_bytes(99);
    rec.end_frame();
    assert!(rec.frames().is_empty());

    rec.begin_frame();
    rec.phase_start(Phase::Delta);
    rec.phase_start(Phase::Upload);
    rec.phase_start(Phase::Delta);
    rec.phase_end();
    assert_eq!(rec.current_frame(), Some(0));
    // begin_frame closes the open frame.
    rec.begin_frame();
    assert_eq!(rec.frames().len(), 1);
    let f = &rec.frames()[0];
    assert_eq!(f.bytes_uploaded, 0);
    assert!(f.phase_ms[Phase::Delta] >= 0.0 && f.phase_ms[Phase::Input] == 0.0);
    assert!(f.cpu_ms() <= f.frame_ms + 1e-6);
}

#[test]
fn recorder_gpu_times_arrive_late() {
    let mut rec = Recorder::new(0);
    rec.begin_frame();
    rec.end_frame();
    rec.begin_frame();
    assert!(rec.set_gpu_ms(1, 0.5), "open frame");
    rec.end_frame();
    assert!(rec.set_gpu_ms(0, 1.5), "ended frame");
    assert!(!rec.set_gpu_ms(2, 1.0), "future frame");
    assert!(!rec.set_gpu_ms(0, f64::NAN));
    assert!(!rec.set_gpu_ms(0, -1.0));
    let gpu: Vec<_> = rec.frames().iter().map(|f| f.gpu_ms).collect();
    assert_eq!(gpu, [Some(1.5), Some(0.5)]);
}

#[test]
fn summary_separates_warmup() {
    let frames = synthetic_frames();
    let s = Summary::from_frames(&frames);
    assert_eq!((s.frames, s.warmup_frames), (40, 5));
    let m = s.measured.as_ref().unwrap();
    let w = s.warmup.as_ref().unwrap();
    assert_eq!((m.frames, w.frames), (35, 5));
    assert_eq!(m.frame_ms.count, 35);
    assert!(
        w.frame_ms.mean > m.frame_ms.p50,
        "warm-up frames are the slow ones"
    );
    // GPU: measured frames 5..38 minus 10, 17, 24, 31.
    assert_eq!(m.gpu_ms.unwrap().count, 33 - 4);
    // The hitch is the single slowest measured frame: it is the max and the 1% low.
    assert_eq!(m.frame_ms.max, frames[20].frame_ms);
    assert_eq!(m.frame_ms.low_1pct, frames[20].frame_ms);
    assert_eq!(m.phase_ms[Phase::Delta].max, 50.0);
    assert!((m.other_ms.mean - 0.25).abs() < 1e-9);
    assert_eq!(s.bytes_uploaded, m.bytes_uploaded + w.bytes_uploaded);
    assert_eq!(s.samples_touched, (0..40).map(|i| 1000 + i).sum::<u64>());
}

#[test]
fn summary_of_warmup_only_and_empty_runs() {
    let mut frames = synthetic_frames();
    frames.truncate(3);
    let s = Summary::from_frames(&frames);
    assert!(s.measured.is_none());
    assert!(s.table().contains("no measured frames"));
    let s = Summary::from_frames(&[]);
    assert!(s.measured.is_none() && s.warmup.is_none());
    // Writers cope with nothing to show.
    assert_well_formed(&frame_times_svg(&RunInfo::default(), &[]).unwrap());
    assert_well_formed(&histogram_svg(&RunInfo::default(), &frames).unwrap());
}

#[test]
fn table_has_a_row_per_phase_and_aligned_columns() {
    let table = Summary::from_frames(&synthetic_frames()).table();
    let lines: Vec<&str> = table.lines().collect();
    for word in ["phase (ms)", "p50", "p99", "1% low"] {
        assert!(lines[0].contains(word), "{}", lines[0]);
    }
    for phase in Phase::ALL {
        assert!(
            lines
                .iter()
                .any(|l| l.trim_start().starts_with(phase.name()))
        );
    }
    for word in ["gpu", "bytes/frame", "samples/frame", "warm-up"] {
        assert!(table.contains(word), "{table}");
    }
    // Every stats row ends at the same column as the header.
    let width = lines[0].len();
    let frame_row = lines.iter().find(|l| l.starts_with("frame")).unwrap();
    assert_eq!(frame_row.len(), width, "\n{table}");
}

#[test]
fn compare_prints_ratios() {
    let a = Summary::from_frames(&synthetic_frames());
    let mut slow = synthetic_frames();
    for f in &mut slow {
        f.frame_ms *= 2.0;
        f.bytes_uploaded *= 4;
    }
    let text = compare("incremental", &a, "naive", &Summary::from_frames(&slow));
    assert!(text.starts_with("A = incremental, B = naive"));
    let frame_row = text.lines().find(|l| l.starts_with("frame")).unwrap();
    assert!(frame_row.contains("2.00x"), "{text}");
    let bytes_row = text.lines().find(|l| l.starts_with("bytes/frame")).unwrap();
    assert!(bytes_row.contains("4.00x"), "{text}");
}

#[test]
fn write_all_writes_every_file() {
    let dir = temp_dir("write-all").join("nested");
    let frames = synthetic_frames();
    let run = run_info();
    let paths = write_all(&dir, &run, &frames).unwrap();
    let names: Vec<_> = paths
        .iter()
        .map(|p| p.file_name().unwrap().to_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            FRAMES_CSV,
            SUMMARY_JSON,
            SUMMARY_TXT,
            TRACE_JSON,
            FRAME_TIMES_SVG,
            HISTOGRAM_SVG
        ]
    );
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).unwrap();

    // CSV: header plus one row per frame, 16 columns each, empty gpu cell where unknown.
    let csv = read(FRAMES_CSV);
    let rows: Vec<Vec<&str>> = csv.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(rows[0].join(","), CSV_HEADER);
    assert_eq!(rows.len(), 1 + frames.len());
    assert!(rows.iter().all(|r| r.len() == 16));
    let gpu_col = rows[0].iter().position(|c| *c == "gpu_ms").unwrap();
    assert_eq!(rows[1 + 3][gpu_col], "");
    assert!(rows[1][gpu_col].parse::<f64>().is_ok());
    assert_eq!(rows[1][2], "1");
    assert_eq!(rows[6][2], "0");

    // summary.json: run info and both sections with the stats keys.
    let json: Value = serde_json::from_str(&read(SUMMARY_JSON)).unwrap();
    assert_eq!(json["format"], "prespline-profile-summary");
    assert_eq!(json["run"]["scenario"], run.scenario.as_str());
    assert_eq!(json["run"]["extra"]["seed"], 7);
    let measured = &json["summary"]["measured"];
    for key in [
        "count", "mean", "min", "p50", "p90", "p95", "p99", "max", "low_1pct",
    ] {
        assert!(measured["frame_ms"][key].is_number(), "frame_ms.{key}");
        assert!(measured["gpu_ms"][key].is_number(), "gpu_ms.{key}");
        for phase in Phase::ALL {
            assert!(measured["phase_ms"][phase.name()][key].is_number());
        }
    }
    for key in [
        "bytes_per_frame",
        "samples_per_frame",
        "bytes_uploaded",
        "fps",
    ] {
        assert!(measured[key].is_number(), "{key}");
    }
    assert_eq!(json["summary"]["warmup"]["frames"], 5);
    let back = read_summary_json(&dir.join(SUMMARY_JSON)).unwrap();
    assert_eq!(back.summary, Summary::from_frames(&frames));
    assert_eq!(back.run, run);

    // summary.txt: the terminal table, then what its names mean.
    let summary = Summary::from_frames(&frames);
    let text = read(SUMMARY_TXT);
    assert_eq!(text, summary.report(&run));
    assert_eq!(
        text,
        format!("{}\n{}\n{}", run.header(), summary.table(), definitions())
    );
    // The header names the run: scenario, scene, size, mode, the extras and the device.
    let head: Vec<&str> = text.lines().take(3).collect();
    assert_eq!(
        head,
        [
            "run: drag <fast> & \"loud\" on demo, 64x64 samples, incremental; 40 frames + 5 warm-up",
            "     seed 7, window 900x600",
            "device: test device",
        ]
    );
    for phase in Phase::ALL {
        let line = format!("{:<10}{}", phase.name(), phase.meaning());
        assert!(text.lines().any(|l| l == line), "{text}");
    }
    for name in ["(other)", "gpu", "p50..p99", "1% low"] {
        assert!(text.lines().any(|l| l.starts_with(name)), "{name}: {text}");
    }

    // trace.json: X events with ts/dur/name on named threads.
    let trace: Value = serde_json::from_str(&read(TRACE_JSON)).unwrap();
    let events = trace["traceEvents"].as_array().unwrap();
    let complete: Vec<&Value> = events.iter().filter(|e| e["ph"] == "X").collect();
    assert!(complete.iter().all(|e| {
        e["name"].is_string() && e["ts"].as_f64().unwrap() >= 0.0 && e["dur"].is_number()
    }));
    let count = |name: &str| complete.iter().filter(|e| e["name"] == name).count();
    assert_eq!(count("frame") + count("frame (warm-up)"), 40);
    assert_eq!(count("delta"), 40);
    assert_eq!(count("gpu"), 40 - 2 - 5);
    let thread_names: Vec<&str> = events
        .iter()
        .filter(|e| e["ph"] == "M" && e["name"] == "thread_name")
        .map(|e| e["args"]["name"].as_str().unwrap())
        .collect();
    assert_eq!(thread_names, ["frames", "CPU phases", "GPU"]);
    assert!(events.iter().any(|e| e["ph"] == "C"));
    // Slices on one track never overlap (viewers would mis-nest them).
    for tid in 1..=3 {
        let mut spans: Vec<(f64, f64)> = complete
            .iter()
            .filter(|e| e["tid"] == tid)
            .map(|e| (e["ts"].as_f64().unwrap(), e["dur"].as_f64().unwrap()))
            .collect();
        spans.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert!(
            spans.windows(2).all(|w| w[0].0 + w[0].1 <= w[1].0 + 1e-6),
            "tid {tid}"
        );
    }

    // SVGs: well-formed, titled, with drawn data.
    for (name, kind) in [
        (FRAME_TIMES_SVG, "Frame time"),
        (HISTOGRAM_SVG, "Frame-time histogram"),
    ] {
        let svg = read(name);
        assert!(svg.starts_with("<svg"), "{name}");
        assert_well_formed(&svg);
        let title = format!("<title>{kind} — drag &lt;fast&gt; &amp; &quot;loud&quot;</title>");
        assert!(svg.contains(&title), "{name}");
        assert!(svg.contains("<path") || svg.contains("<polyline"), "{name}");
        assert!(svg.len() < 200_000, "{name} is {} bytes", svg.len());
    }
    let plot = read(FRAME_TIMES_SVG);
    for label in ["median", "warm-up", "delta", "gpu"] {
        assert!(plot.contains(label), "frame_times.svg lacks {label}");
    }
    // Axis names are whole text elements.
    let texts = svg_texts(&plot);
    for label in ["frame", "ms"] {
        assert!(
            texts.iter().any(|t| t == label),
            "no text {label:?} in {texts:?}"
        );
    }
    // The footnote names every phase with its meaning.
    let footnote = texts.join(" ");
    for phase in Phase::ALL {
        let entry = format!("{phase} = {}", phase.meaning());
        assert!(
            footnote.contains(&entry),
            "footnote lacks {entry:?}: {footnote}"
        );
    }
    assert!(footnote.contains(OTHER_MEANING), "{footnote}");
    let hist = read(HISTOGRAM_SVG);
    let texts = svg_texts(&hist);
    for label in ["p50 ", "p99 ", "frame time (ms)"] {
        assert!(
            texts.iter().any(|t| t.starts_with(label)),
            "histogram.svg lacks {label}: {texts:?}"
        );
    }
    let footnote = texts.join(" ");
    assert!(footnote.contains(LOW_1PCT_MEANING), "{footnote}");
    assert!(footnote.contains(PERCENTILE_MEANING), "{footnote}");
    std::fs::remove_dir_all(dir.parent().unwrap()).unwrap();
}

#[test]
fn long_runs_are_downsampled() {
    let base = synthetic_frames();
    let frames: Vec<FrameRecord> = (0..20_000)
        .map(|i| FrameRecord {
            index: i,
            warmup: i < 5,
            ..base[5 + i % 30].clone()
        })
        .collect();
    let svg = frame_times_svg(&RunInfo::default(), &frames).unwrap();
    assert_well_formed(&svg);
    assert!(svg.len() < 400_000, "{} bytes", svg.len());
    assert!(svg.contains("frame (max)"));
}

#[test]
fn write_errors_name_the_path() {
    let dir = temp_dir("write-error");
    std::fs::create_dir_all(&dir).unwrap();
    // A file where the directory should be.
    let blocker = dir.join("blocker");
    std::fs::write(&blocker, "x").unwrap();
    let err = write_all(
        &blocker.join("out"),
        &RunInfo::default(),
        &synthetic_frames(),
    )
    .unwrap_err();
    assert!(err.to_string().contains("blocker"), "{err}");
    let err = write_frames_csv(&blocker.join("frames.csv"), &[]).unwrap_err();
    assert!(matches!(err, ProfileError::Write { .. }));
    let err = read_summary_json(&blocker).unwrap_err();
    assert!(matches!(err, ProfileError::Parse { .. }), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A frame that built a gesture's static layer is reported on its own line, not among the
/// measured frames, so their percentiles describe the steady gesture; the retained count and
/// the triangles per frame are in the table and the comparison. Negative control: without the
/// flag the build's frame is the measured maximum.
#[test]
fn layer_builds_are_reported_apart() {
    let mut frames = synthetic_frames();
    for f in frames.iter_mut().filter(|f| !f.warmup) {
        f.retained = true;
        f.triangles = 500;
    }
    frames[5].layer_built = true;
    frames[5].frame_ms = 400.0;
    frames[5].triangles = 80_000;
    let summary = Summary::from_frames(&frames);
    let m = summary.measured.as_ref().unwrap();
    assert_eq!(m.frames, 34);
    assert!(m.frame_ms.max < 100.0, "{}", m.frame_ms.max);
    assert_eq!(m.retained_frames, 34);
    assert_eq!(m.triangles_per_frame, 500.0);
    let b = summary.layer_builds.as_ref().unwrap();
    assert_eq!((b.frames, b.frame_ms.max), (1, 400.0));
    let table = summary.table();
    assert!(table.contains("retained       34 of 34 frames"), "{table}");
    assert!(
        table.contains("layer builds   1 frame, mean 400"),
        "{table}"
    );
    assert!(table.contains("triangles/frame 500"), "{table}");
    let mut naive = frames.clone();
    for f in naive.iter_mut().filter(|f| !f.warmup) {
        f.triangles *= 4;
    }
    let text = compare(
        "incremental",
        &summary,
        "naive",
        &Summary::from_frames(&naive),
    );
    let row = text
        .lines()
        .find(|l| l.starts_with("triangles/frame"))
        .unwrap();
    assert!(row.contains("4.00x"), "{text}");

    frames[5].layer_built = false;
    let flat = Summary::from_frames(&frames);
    assert_eq!(flat.measured.as_ref().unwrap().frame_ms.max, 400.0);
    assert!(flat.layer_builds.is_none());
    // Most frames a build (`--naive`: every edit leaves the layer stale): building is the
    // steady state, so they stay measured and the table says so.
    let mut most = synthetic_frames();
    most.iter_mut()
        .for_each(|f| f.layer_built = !f.warmup && f.index % 4 != 0);
    let s = Summary::from_frames(&most);
    let m = s.measured.as_ref().unwrap();
    assert_eq!((m.frames, m.layer_builds), (35, 27));
    assert!(s.layer_builds.is_none());
    assert!(
        s.table().contains("layer builds   27 of 35 frames above"),
        "{}",
        s.table()
    );
}
