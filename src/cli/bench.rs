//! `prespline bench`: a scripted, reproducible editing session with per-frame phase timing,
//! headless (offscreen) by default or in a window, optionally followed by the same session in
//! naive mode (full re-sampling and full upload on every edit) for a same-run comparison.
//!
//! Writes the [`crate::profile::write_all`] reports and, headless, `final.png` (the last
//! frame) into the output folder; with `--naive` into its `incremental/` and `naive/`
//! subfolders, plus [`COMPARISON_TXT`], the table also printed at the end. While frames run,
//! a progress bar shows on a terminal (nothing off one); each run's results are headed by a
//! one-line banner naming scenario, scene, frames, size, mode and target.

use super::CliError;
use super::args::{MapRangeArgs, MemoryArgs, SamplesArgs, parse_size};
use super::load::{Notes, load_scene};
use super::render::validation_mode;
use crate::formats::demo::demo_scene;
use crate::gpu::{FRAMES_IN_FLIGHT, OffscreenDesc, Renderer, RendererDesc};
use crate::profile::{
    FrameRecord, Phase, Progress, Recorder, RunInfo, Summary, compare, write_all,
};
use crate::render::Redraw;
use crate::render::maps::SurfaceMap;
use crate::sampling::budget::MemoryBudget;
use crate::scene::{Scene, escape_controls};
use crate::view::app::{self, ViewArgs};
use crate::view::scenario::{Scenario, ScenarioDriver};
use crate::view::session::Session;
use clap::Args;
use std::path::{Path, PathBuf};

/// Run a scripted, reproducible editing session and report where every millisecond goes.
#[derive(Args, Debug, Clone)]
pub struct BenchArgs {
    /// Scene file (JSON, OBJ, STEP or IGES); the demo scene without it.
    pub scene: Option<PathBuf>,
    /// What the scripted user does. drag: the middle control point of the surface with the
    /// most control points (else of any object) is grabbed and moved in a circle of 40 pixels,
    /// one edit per frame. erbs-rotate: the middle local patch (or local curve) of the first
    /// ERBS object is turned a little every frame. orbit: the camera turns around the scene,
    /// 4 pixels of middle-button drag a frame, no edits. idle: nothing changes, yet every frame
    /// is drawn in full: it measures one full redraw (the viewer itself draws nothing while
    /// idle).
    #[arg(long, default_value = "drag", value_parser = Scenario::parse, value_name = "drag|erbs-rotate|orbit|idle")]
    pub scenario: Scenario,
    /// Measured frames.
    #[arg(long, default_value_t = 300)]
    pub frames: usize,
    /// Warm-up frames before measuring (shader compilation, first uploads), reported separately.
    #[arg(long, default_value_t = 30)]
    pub warmup: usize,
    /// Image or window size.
    #[arg(long, default_value = "1280x720", value_parser = parse_size, value_name = "WxH")]
    pub size: (u32, u32),
    /// Run in a window (no vsync) instead of headless.
    #[arg(long)]
    pub window: bool,
    /// Also run the same session the way tools without pre-evaluation work and compare. The
    /// naive run turns off the delta path only: every edit re-samples its whole object and
    /// uploads all of it, so the retained redraw (still on) must draw the whole object again
    /// each frame instead of the touched cells. Reports in DIR/incremental and DIR/naive; the
    /// comparison, with the samples, bytes and triangles of each run's frames and the static
    /// layers it rebuilt, is printed and saved as DIR/comparison.txt.
    #[arg(long)]
    pub naive: bool,
    /// Output directory for the reports.
    #[arg(long, default_value = "bench-out", value_name = "DIR")]
    pub out: PathBuf,
    /// MSAA samples (1, 2, 4, 8); 0 picks the device's default: 1 on CPU rasterisers such
    /// as lavapipe, 4 on GPUs (see docs/performance.md, "Frames").
    #[arg(long, default_value_t = 0)]
    pub msaa: u32,
    #[command(flatten)]
    pub samples: SamplesArgs,
    #[command(flatten)]
    pub memory: MemoryArgs,
    /// Draw every sample of every surface (no display level of detail), for comparison.
    #[arg(long)]
    pub no_lod: bool,
    /// Show a surface analysis map throughout: gaussian, mean, kmax, kmin or zebra.
    #[arg(long, value_name = "MAP", value_parser = SurfaceMap::parse)]
    pub analysis: Option<SurfaceMap>,
    #[command(flatten)]
    pub map_range: MapRangeArgs,
    /// How a gesture redraws: retained (what it cannot change is drawn once into a static
    /// layer; each frame restores it and draws only what moves) or full (every object,
    /// every frame). Both give the same pixels.
    #[arg(long, default_value = "retained", value_parser = Redraw::parse, value_name = "retained|full")]
    pub redraw: Redraw,
}

/// The settings of one bench run, resolved from [`BenchArgs`].
struct Bench {
    args: BenchArgs,
    budget: MemoryBudget,
}

/// Runs the benchmark, writes the reports and prints the closing line.
pub fn run(args: BenchArgs) -> Result<(), CliError> {
    let bench = Bench {
        budget: args.memory.budget(),
        args,
    };
    let line = bench.run()?;
    eprintln!("{}", escape_controls(&line));
    Ok(())
}

impl Bench {
    /// Runs the benchmark, writes the reports and returns the closing line.
    fn run(&self) -> Result<String, CliError> {
        let args = &self.args;
        if args.frames == 0 {
            return Err(CliError("--frames must be at least 1".into()));
        }
        let (scene, scene_name, notes) = match &args.scene {
            Some(p) => {
                let (scene, notes) = load_scene(p, &args.samples.counts(), &self.budget)?;
                (scene, p.display().to_string(), notes)
            }
            None => {
                let mut demo = demo_scene();
                args.samples.counts().apply(&mut demo)?;
                (demo, "demo".to_string(), Notes::default())
            }
        };
        super::render::check_drawable(&scene, Path::new(&scene_name), &self.budget)?;
        super::render::check_analysis(&scene, args.analysis, &self.budget)?;
        // Every frame keeps a record (and a frame-time entry in the progress line) until the
        // reports are written: the counts pass the budget before the recorder reserves them.
        let frames = args.frames as u128 + args.warmup as u128;
        self.budget
            .check_build(
                format_args!("--frames {} with --warmup {}", args.frames, args.warmup),
                frames * (std::mem::size_of::<crate::profile::FrameRecord>() as u128 + 8),
            )
            .map_err(CliError)?;
        notes.print();
        let modes: &[bool] = if args.naive { &[false, true] } else { &[false] };
        let mut summaries = Vec::new();
        let mut written = Vec::new();
        for &naive in modes {
            let mode = session_mode(naive);
            let dir = if args.naive {
                args.out.join(mode)
            } else {
                args.out.clone()
            };
            let (frames, device) = if args.window {
                self.run_window(&scene, naive)?
            } else {
                self.run_headless(&scene, naive, &dir)?
            };
            // The banner heads the results rather than announcing the run: printed first, it
            // would stand above the error of a run that fails to start, making it two lines.
            eprintln!("{}", banner(args, &scene_name, mode));
            let summary = Summary::from_frames(&frames);
            eprint!("{}", summary.table());
            let mut info = RunInfo {
                scenario: args.scenario.name().into(),
                scene: scene_name.clone(),
                size: format!("{}x{}", args.size.0, args.size.1),
                frames: args.frames,
                warmup_frames: args.warmup,
                device,
                mode: mode.into(),
                ..RunInfo::default()
            };
            info = info.with("target", if args.window { "window" } else { "offscreen" });
            // The problem size, which `--samples` sets: every object's sample count, summed.
            let samples: usize = scene
                .objects
                .iter()
                .map(|o| o.model.sample_dims().iter().product::<usize>())
                .sum();
            info = info.with("scene_samples", samples);
            info = info.with("redraw", args.redraw.name());
            // How many measured frames a static layer served (a gesture draws in full where a
            // layer would not pay, docs/performance.md); the table's "retained" line says it
            // of the frames it describes.
            let retained = frames.iter().filter(|f| !f.warmup && f.retained).count();
            info = info.with("retained_frames", retained);
            let paths = write_all(&dir, &info, &frames).map_err(|e| CliError(e.to_string()))?;
            written.extend(paths);
            if !args.window {
                written.push(dir.join("final.png"));
            }
            summaries.push((mode, summary));
        }
        if let [(a, inc), (b, naive)] = summaries.as_slice() {
            let text = comparison(a, inc, b, naive);
            eprint!("{text}");
            let path = args.out.join(COMPARISON_TXT);
            std::fs::write(&path, &text)
                .map_err(|e| CliError(format!("cannot write {}: {e}", path.display())))?;
            written.push(path);
        }
        Ok(format!(
            "bench results in {} ({} files)",
            args.out.display(),
            written.len()
        ))
    }
}

/// With `--naive`: the side-by-side table of both runs, in the output folder.
pub const COMPARISON_TXT: &str = "comparison.txt";

/// `bench: drag on demo, 120 frames + 10 warm-up, 1280x720, incremental, headless`.
fn banner(args: &BenchArgs, scene_name: &str, mode: &str) -> String {
    format!(
        "bench: {} on {scene_name}, {} frames + {} warm-up, {}x{}, {mode}, redraw {}, {}",
        args.scenario.name(),
        args.frames,
        args.warmup,
        args.size.0,
        args.size.1,
        args.redraw.name(),
        if args.window { "window" } else { "headless" }
    )
}

/// The content of `comparison.txt`: [`compare`]'s table, then the edit cost of both runs when
/// the incremental one has one.
fn comparison(a: &str, inc: &Summary, b: &str, naive: &Summary) -> String {
    let mut text = compare(a, inc, b, naive);
    if let (Some(i), Some(n)) = (&inc.measured, &naive.measured) {
        let (di, dn) = (i.phase_ms[Phase::Delta].mean, n.phase_ms[Phase::Delta].mean);
        if di > 0.0 {
            text.push_str(&format!(
                "edit cost (delta phase, mean): incremental {:.1} µs, naive {:.1} µs: {:.0}× less with pre-evaluation\n",
                di * 1e3,
                dn * 1e3,
                dn / di
            ));
        }
    }
    text
}

impl Bench {
    /// The session in an offscreen target: exactly the viewer's per-frame work without a window.
    fn run_headless(
        &self,
        scene: &Scene,
        naive: bool,
        dir: &Path,
    ) -> Result<(Vec<FrameRecord>, String), CliError> {
        let args = &self.args;
        let gpu = |e: crate::gpu::GpuError| CliError(e.to_string());
        let mut renderer = Renderer::new(&RendererDesc {
            app_name: "prespline bench".into(),
            validation: validation_mode(),
            ..RendererDesc::default()
        })
        .map_err(gpu)?;
        let device = renderer.caps().name.clone();
        let (w, h) = args.size;
        let mut target = renderer
            .create_offscreen(&OffscreenDesc {
                width: w,
                height: h,
                samples: args.msaa,
            })
            .map_err(gpu)?;
        let mut session = Session::open(
            &mut renderer,
            scene,
            dir.join("scene.json"),
            [w, h],
            self.budget,
        )
        .map_err(CliError)?;
        session.set_naive(naive);
        session.set_redraw(args.redraw);
        session.options.lod = !args.no_lod;
        session.options.map_range = args.map_range.map_range;
        session.set_map(args.analysis);
        let total = args.warmup + args.frames;
        let result = (|| -> Result<Recorder, CliError> {
            let mut driver = ScenarioDriver::new(args.scenario, &session, args.warmup, args.frames)
                .map_err(CliError)?;
            let mut rec = Recorder::with_capacity(args.warmup, total);
            let label = format!("bench {} ({})", args.scenario.name(), session_mode(naive));
            let progress = Progress::new(&label, Some(total as u64)).unit("frames");
            for k in 0..total {
                let index = rec.begin_frame();
                rec.phase_start(Phase::Input);
                for action in driver.actions(k, &session) {
                    session.perform(action);
                }
                rec.phase_start(Phase::Delta);
                let applied = session.apply_pending();
                rec.add_samples(applied.samples as u64);
                // Waiting for the frame slot's fence is what presenting costs offscreen.
                rec.phase_start(Phase::Present);
                let mut frame = renderer.begin_offscreen(&mut target).map_err(gpu)?;
                if let Some(ms) = frame.gpu_time_ms() {
                    rec.set_gpu_ms(index.saturating_sub(FRAMES_IN_FLIGHT), ms);
                }
                rec.phase_start(Phase::Upload);
                let stats = session.upload(&mut frame).map_err(gpu)?;
                rec.add_bytes(stats.bytes as u64);
                rec.phase_start(Phase::Record);
                session.record(&mut frame, true).map_err(gpu)?;
                let d = session.last_draw();
                rec.set_draw(d.retained, d.layer_built, d.triangles);
                if k + 1 == total {
                    // Only the last image is written (final.png); no other frame is read back.
                    frame.capture();
                }
                rec.phase_start(Phase::Submit);
                frame.finish().map_err(gpu)?;
                if d.layer_built {
                    // A layer build costs a full redraw and its saves, which the rasteriser
                    // would otherwise charge to the next frame's wait: drained here, it stays
                    // in its own frame (reported apart from the steady gesture).
                    rec.phase_start(Phase::Present);
                    renderer.wait_idle().map_err(gpu)?;
                }
                rec.end_frame();
                session
                    .hud
                    .push_frame(rec.frames().last().map_or(0.0, |f| f.frame_ms));
                session.hud.gpu_ms = renderer.last_gpu_time_ms();
                progress.inc(1);
            }
            progress.finish();
            // The last frames' GPU times arrive when their slots are waited on.
            renderer.wait_idle().map_err(gpu)?;
            std::fs::create_dir_all(dir)
                .map_err(|e| CliError(format!("cannot create {}: {e}", dir.display())))?;
            let png = dir.join("final.png");
            renderer
                .read_pixels(&target)
                .map_err(gpu)?
                .write_png(&png)
                .map_err(gpu)?;
            Ok(rec)
        })();
        session.destroy(&mut renderer);
        renderer.destroy_offscreen(target).map_err(gpu)?;
        let sink = renderer.validation_sink();
        drop(renderer);
        if let Some(errors) = sink.map(|s| s.errors()).filter(|e| !e.is_empty()) {
            return Err(CliError(format!(
                "Vulkan validation reported {} error(s), first: {}",
                errors.len(),
                errors[0]
            )));
        }
        Ok((result?.into_frames(), device))
    }

    fn run_window(
        &self,
        scene: &Scene,
        naive: bool,
    ) -> Result<(Vec<FrameRecord>, String), CliError> {
        let args = &self.args;
        let run = app::run(ViewArgs {
            scene: scene.clone(),
            title: format!("bench {}", args.scenario.name()),
            save_path: args.out.join("scene.json"),
            size: args.size,
            vsync: false,
            script: None,
            scenario: Some(args.scenario),
            warmup: args.warmup,
            max_frames: Some(args.warmup + args.frames),
            naive,
            autosave: None,
            msaa: args.msaa,
            lod: !args.no_lod,
            analysis: args.analysis,
            map_range: args.map_range.map_range,
            memory: self.budget,
            redraw: args.redraw,
        })
        .map_err(CliError)?;
        Ok((run.frames, run.device))
    }
}

fn session_mode(naive: bool) -> &'static str {
    if naive { "naive" } else { "incremental" }
}
