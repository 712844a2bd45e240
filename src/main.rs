//! The `prespline` command line.
#![deny(unsafe_code)]

use clap::{Args, Parser, Subcommand};
use prespline::cli::files::{SampleOverride, SamplesArg};
use prespline::cli::{self, CliError};
use prespline::render::maps::{MapRange, SurfaceMap};
use prespline::render::{NetMode, OrbitCamera, Redraw, ViewOptions, Wire};
use prespline::sampling::budget::{self, MemoryBudget};
use prespline::scene::escape_controls;
use prespline::view::scenario::Scenario;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "prespline",
    version,
    about = "Pre-evaluated interactive editing of Bézier, B-spline, NURBS and ERBS curves and surfaces"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Threads for pre-evaluating many objects (default: every core). Results are bit for
    /// bit the same on any number.
    #[arg(long, global = true, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    threads: Option<u16>,
}

#[derive(Subcommand)]
enum Command {
    /// Sample every object of a scene and print positions and derivatives as JSON on stdout.
    Sample {
        /// Scene file (JSON, see docs/scene-format.md; or Wavefront OBJ, see docs/obj.md).
        scene: PathBuf,
        /// Highest derivative order N: curves get c..c^(N), surfaces every ∂^{a+b}S with a, b ≤ N.
        #[arg(long, short = 'd', default_value_t = 1, value_name = "N")]
        derivatives: usize,
        /// Edits (JSON list) applied in order through the incremental (delta) path.
        #[arg(long, value_name = "EDITS.json")]
        edits: Option<PathBuf>,
        /// Apply the edits to the model and re-sample from scratch instead of the delta path.
        #[arg(long)]
        full: bool,
        #[command(flatten)]
        samples: SamplesArgs,
        #[command(flatten)]
        memory: MemoryArgs,
    },
    /// Open the interactive viewer on a scene (the built-in demo scene without SCENE).
    ///
    /// docs/viewer.md describes the mouse, the keys, the editing modes and the --script
    /// format; H or F1 in the viewer lists the keys.
    View {
        /// Scene file (JSON, or Wavefront OBJ by its .obj extension); without it, the demo:
        /// B-spline surface, ERBS surface and curve, NURBS circle, closed ERBS torus, Utah
        /// teapot.
        scene: Option<PathBuf>,
        /// Window size.
        #[arg(long, default_value = "1280x720", value_parser = cli::render::parse_size, value_name = "WxH")]
        size: (u32, u32),
        /// Present without vsync (MAILBOX or IMMEDIATE) to measure frame times.
        #[arg(long)]
        no_vsync: bool,
        /// Replay timed input events from a JSON script (format: docs/viewer.md, "Scripts").
        #[arg(long, value_name = "SCRIPT.json")]
        script: Option<PathBuf>,
        /// Where Ctrl+S writes (default: the scene file, or prespline-demo.json for the demo);
        /// a path ending in .obj is written as Wavefront OBJ.
        #[arg(long, value_name = "PATH")]
        save_as: Option<PathBuf>,
        #[command(flatten)]
        samples: SamplesArgs,
        /// Record per-frame phase timings while interacting and write the reports (CSV, JSON
        /// summary, Chrome trace, SVG plots) into DIR when the window closes.
        #[arg(long, value_name = "DIR")]
        profile: Option<PathBuf>,
        /// Open an earlier session's unsaved edits instead of the scene: the newest autosave,
        /// or =FILE (the start-up note lists those waiting). Autosaves: NAME.autosave.json
        /// beside NAME.json (demo.autosave.json for the demo), earlier sessions' as
        /// NAME.autosave.YYYYMMDD-HHMMSS.json, or in $XDG_STATE_HOME/prespline/ when the
        /// scene's directory cannot take them. Ctrl+S removes the recovered autosave; see
        /// docs/autosave.md.
        #[arg(long, value_name = "FILE", num_args = 0..=1, require_equals = true)]
        recover: Option<Option<PathBuf>>,
        #[command(flatten)]
        memory: MemoryArgs,
        /// Open with a surface analysis map on: gaussian, mean, kmax, kmin or zebra (M cycles).
        #[arg(long, value_name = "MAP", value_parser = SurfaceMap::parse)]
        analysis: Option<SurfaceMap>,
        #[command(flatten)]
        map_range: MapRangeArgs,
        /// How a gesture redraws: retained (what it cannot change is drawn once into a static
        /// layer; each frame restores it and draws only what moves) or full (every object,
        /// every frame). Both give the same pixels.
        #[arg(long, default_value = "retained", value_parser = Redraw::parse, value_name = "retained|full")]
        redraw: Redraw,
    },
    /// Run a scripted, reproducible editing session and report where every millisecond goes.
    Bench {
        /// Scene file (JSON or OBJ); the demo scene without it.
        scene: Option<PathBuf>,
        /// What the scripted user does.
        #[arg(long, default_value = "drag", value_parser = Scenario::parse, value_name = "drag|erbs-rotate|orbit|idle")]
        scenario: Scenario,
        /// Measured frames.
        #[arg(long, default_value_t = 300)]
        frames: usize,
        /// Warm-up frames before measuring (shader compilation, first uploads), reported separately.
        #[arg(long, default_value_t = 30)]
        warmup: usize,
        /// Image or window size.
        #[arg(long, default_value = "1280x720", value_parser = cli::render::parse_size, value_name = "WxH")]
        size: (u32, u32),
        /// Run in a window (no vsync) instead of headless.
        #[arg(long)]
        window: bool,
        /// Also run the same session the way tools without pre-evaluation work (full re-sampling
        /// and full upload of edited objects every frame) and compare: reports in DIR/incremental
        /// and DIR/naive, the comparison printed and saved as DIR/comparison.txt.
        #[arg(long)]
        naive: bool,
        /// Output directory for the reports.
        #[arg(long, default_value = "bench-out", value_name = "DIR")]
        out: PathBuf,
        /// MSAA samples (1, 2, 4, 8); 0 picks the device's default: 1 on CPU rasterisers such
        /// as lavapipe, 4 on GPUs (see docs/performance.md, "Frames").
        #[arg(long, default_value_t = 0)]
        msaa: u32,
        #[command(flatten)]
        samples: SamplesArgs,
        #[command(flatten)]
        memory: MemoryArgs,
        /// Draw every sample of every surface (no display level of detail), for comparison.
        #[arg(long)]
        no_lod: bool,
        /// Show a surface analysis map throughout: gaussian, mean, kmax, kmin or zebra.
        #[arg(long, value_name = "MAP", value_parser = SurfaceMap::parse)]
        analysis: Option<SurfaceMap>,
        #[command(flatten)]
        map_range: MapRangeArgs,
        /// How a gesture redraws: retained (what it cannot change is drawn once into a static
        /// layer; each frame restores it and draws only what moves) or full (every object,
        /// every frame). Both give the same pixels.
        #[arg(long, default_value = "retained", value_parser = Redraw::parse, value_name = "retained|full")]
        redraw: Redraw,
    },
    /// Render a scene headless (no display needed) into a PNG or JPEG image (by the extension).
    Render {
        /// Scene file (JSON, or Wavefront OBJ by its .obj extension).
        scene: PathBuf,
        /// Output image: PNG for .png, JPEG for .jpg or .jpeg; other extensions are refused.
        #[arg(long, short = 'o', value_name = "IMAGE.png|IMAGE.jpg")]
        out: PathBuf,
        /// Image size.
        #[arg(long, default_value = "1280x720", value_parser = cli::render::parse_size, value_name = "WxH")]
        size: (u32, u32),
        /// Camera as eye and target, optionally the vertical field of view in degrees:
        /// EX,EY,EZ,TX,TY,TZ[,FOV]. Default: frames the whole scene.
        #[arg(long, value_parser = OrbitCamera::parse, value_name = "EYE,TARGET[,FOV]", allow_hyphen_values = true)]
        camera: Option<OrbitCamera>,
        /// Edits (JSON list) applied before rendering.
        #[arg(long, value_name = "EDITS.json")]
        edits: Option<PathBuf>,
        /// MSAA samples (1, 2, 4, 8); a still image is worth 4; 0 picks the device's interactive
        /// default (1 on CPU rasterisers, 4 on GPUs).
        #[arg(long, default_value_t = 4)]
        msaa: u32,
        /// Draw the osculating circle of curve NAME at parameter T, labelled with its
        /// curvature, radius and torsion.
        #[arg(long, value_name = "NAME@T", value_parser = parse_osculating)]
        osculating: Option<(String, f64)>,
        #[command(flatten)]
        display: DisplayArgs,
        #[command(flatten)]
        samples: SamplesArgs,
        #[command(flatten)]
        memory: MemoryArgs,
        /// After writing the image, print the memory budget's estimate of the scene next to
        /// what it made resident (peak resident size less the program and the Vulkan driver).
        #[arg(long)]
        memory_report: bool,
    },
    /// Convert a scene between JSON and Wavefront OBJ (direction from the extensions).
    ///
    /// IN and OUT end in .json (the scene format) or .obj (free-form curves and surfaces);
    /// control data are kept bit for bit. docs/obj.md describes the exact mapping.
    Convert {
        /// Input scene (.json or .obj).
        input: PathBuf,
        /// Output scene (.json or .obj), written atomically.
        output: PathBuf,
        #[command(flatten)]
        samples: SamplesArgs,
        #[command(flatten)]
        memory: MemoryArgs,
    },
}

/// Sample counts that replace the file's (or, for OBJ without them, the default).
#[derive(Args, Clone)]
struct SamplesArgs {
    /// Sample counts: N for every curve, NxM for every surface; repeat for both
    /// (e.g. --samples 400 --samples 64x64). A count the scene has no object for is noted.
    #[arg(long, value_name = "N|NxM", value_parser = SamplesArg::parse)]
    samples: Vec<SamplesArg>,
}

impl SamplesArgs {
    fn counts(&self) -> SampleOverride {
        SampleOverride::from_args(&self.samples)
    }
}

/// How much memory pre-evaluation may take.
#[derive(Args, Clone, Copy)]
struct MemoryArgs {
    /// Refuse scenes whose pre-evaluated tables, samples and GPU mirrors would need more than
    /// this (bytes, or with K, M, G, T: 512M, 4G). Default: half of physical memory.
    #[arg(long, value_name = "SIZE", value_parser = budget::parse_size)]
    memory_limit: Option<u64>,
}

impl MemoryArgs {
    /// The command's budget, which also becomes the one every count read from its files,
    /// edits and flags is held to before anything is built from it (`budget::check_build`).
    fn budget(self) -> MemoryBudget {
        let budget = MemoryBudget::from_flag(self.memory_limit);
        budget::set_build_budget(budget);
        budget
    }
}

/// The colour scale of curvature maps.
#[derive(Args, Clone, Copy)]
struct MapRangeArgs {
    /// Colour scale of curvature maps: per-object (each surface its own symmetric range from
    /// the 90th percentile of |value|; the patches of one model share one: surfaces named
    /// NAME_0, NAME_1, … whose bounding boxes touch, directly or through each other; see
    /// docs/viewer.md, "Analysis"), shared (one range over every surface) or MIN,MAX (fixed:
    /// MIN blue, MAX red, white halfway).
    #[arg(long, value_name = "shared|per-object|MIN,MAX", default_value = "per-object", value_parser = MapRange::parse, allow_hyphen_values = true)]
    map_range: MapRange,
}

/// What to draw besides curves and shaded surfaces.
#[derive(Args, Clone, Copy)]
struct DisplayArgs {
    /// Draw control polygons, control nets and control points.
    #[arg(long)]
    net: bool,
    /// Hide ERBS local curves and patches.
    #[arg(long)]
    no_local: bool,
    /// Isoparametric lines every N samples on surfaces (1 = full wireframe).
    #[arg(long, value_name = "N")]
    wire: Option<u32>,
    /// Draw surface normals.
    #[arg(long)]
    normals: bool,
    /// Draw Frenet frames along curves.
    #[arg(long)]
    frenet: bool,
    /// Draw curvature combs along curves.
    #[arg(long)]
    comb: bool,
    /// Draw continuity badges (G0/G1/G2, C1/C2 from left and right derivatives) at curve
    /// junctions and at knots of multiplicity > 1.
    #[arg(long)]
    badges: bool,
    /// Colour surfaces by an analysis map, with a legend: gaussian, mean, kmax, kmin
    /// (principal curvatures) or zebra (reflection lines).
    #[arg(long, value_name = "MAP", value_parser = SurfaceMap::parse)]
    analysis: Option<SurfaceMap>,
    #[command(flatten)]
    map_range: MapRangeArgs,
    /// Draw every sample of every surface (no display level of detail).
    #[arg(long)]
    no_lod: bool,
}

impl DisplayArgs {
    fn options(self) -> ViewOptions {
        ViewOptions {
            control_nets: if self.net { NetMode::All } else { NetMode::Off },
            local_curves: !self.no_local,
            wire: match self.wire {
                None | Some(0) => Wire::Off,
                Some(1) => Wire::Full,
                Some(n) => Wire::Isolines(n),
            },
            normals: self.normals,
            frenet: self.frenet,
            curvature_comb: self.comb,
            badges: self.badges,
            analysis: self.analysis,
            map_range: self.map_range.map_range,
            lod: !self.no_lod,
            ..ViewOptions::default()
        }
    }
}

/// A command-line error as one line, like every other error the program reports: clap's
/// message with its continuation lines joined, its usage block and hint replaced by a pointer
/// to `--help`. Help and version requests print as clap writes them.
fn parse_cli() -> Result<Cli, ExitCode> {
    use clap::error::ErrorKind;
    Cli::try_parse().map_err(|e| match e.kind() {
        ErrorKind::DisplayHelp
        | ErrorKind::DisplayVersion
        | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => e.exit(),
        _ => {
            eprintln!("{}", one_line_error(&e.render().to_string()));
            ExitCode::from(2)
        }
    })
}

/// The paragraph of clap's rendered error up to its first blank line, as one line ending in
/// a pointer to `--help`.
fn one_line_error(rendered: &str) -> String {
    let mut lines = rendered.lines().take_while(|l| !l.trim().is_empty());
    let first = lines
        .next()
        .unwrap_or("error: invalid command line")
        .trim_end();
    let rest: Vec<&str> = lines.map(str::trim).collect();
    let joined = if rest.is_empty() {
        first.to_string()
    } else {
        format!("{} {}", first, rest.join(", "))
    };
    let joined = prespline::scene::escape_controls(&joined).into_owned();
    format!("{joined} (try --help)")
}

fn main() -> ExitCode {
    let cli = match parse_cli() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    if let Some(n) = cli.threads {
        prespline::parallel::set_threads(usize::from(n));
    }
    let result = match cli.command {
        Command::Sample {
            scene,
            derivatives,
            edits,
            full,
            samples,
            memory,
        } => {
            let args = cli::sample::SampleArgs {
                scene: &scene,
                derivatives,
                edits: edits.as_deref(),
                full,
                memory: memory.budget(),
                samples: samples.counts(),
            };
            cli::sample::run(&args).and_then(|text| print(&text))
        }
        Command::View {
            scene,
            size,
            no_vsync,
            script,
            save_as,
            profile,
            samples,
            recover,
            memory,
            analysis,
            map_range,
            redraw,
        } => cli::view::run(&cli::view::ViewOptions {
            scene: scene.as_deref(),
            size,
            vsync: !no_vsync,
            script: script.as_deref(),
            save_as: save_as.as_deref(),
            profile: profile.as_deref(),
            samples: samples.counts(),
            memory: memory.budget(),
            recover: recover.as_ref().map(Option::as_deref),
            analysis,
            map_range: map_range.map_range,
            redraw,
        }),
        Command::Bench {
            scene,
            scenario,
            frames,
            warmup,
            size,
            window,
            naive,
            out,
            msaa,
            samples,
            memory,
            no_lod,
            analysis,
            map_range,
            redraw,
        } => {
            let args = cli::bench::BenchArgs {
                scene,
                scenario,
                frames,
                warmup,
                size,
                window,
                naive,
                out,
                msaa,
                memory: memory.budget(),
                lod: !no_lod,
                analysis,
                map_range: map_range.map_range,
                samples: samples.counts(),
                redraw,
            };
            cli::bench::run(&args).map(|line| eprintln!("{}", escape_controls(&line)))
        }
        Command::Render {
            scene,
            out,
            size,
            camera,
            edits,
            msaa,
            osculating,
            display,
            samples,
            memory,
            memory_report,
        } => {
            let before = cli::resident::Resident::read();
            cli::render::load_document(
                &scene,
                edits.as_deref(),
                &samples.counts(),
                &memory.budget(),
                display.analysis,
                display.net,
            )
            .and_then(|(doc, estimate)| {
                let mut options = display.options();
                if let Some((name, t)) = &osculating {
                    options.osculating_at = Some(cli::render::osculating_at(&doc, name, *t)?);
                }
                let probe = before
                    .filter(|_| memory_report)
                    .map(|before| cli::render::MemoryProbe { estimate, before });
                let (w, h) = size;
                let lines = cli::render::run(&doc, &out, w, h, camera, options, msaa, probe);
                // The process ends with this command: freeing a large scene's allocations
                // one by one (two per object and more) would only delay the exit.
                std::mem::forget(doc);
                lines
            })
            .map(|(line, report)| {
                eprintln!("{}", escape_controls(&line));
                if let Some(r) = report {
                    eprintln!("{r}");
                } else if memory_report {
                    eprintln!("memory: the resident size is not readable here (/proc/self/status)");
                }
            })
        }
        Command::Convert {
            input,
            output,
            samples,
            memory,
        } => {
            memory.budget();
            cli::files::convert(&input, &output, &samples.counts())
        }
        .map(|line| eprintln!("{}", escape_controls(&line))),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", escape_controls(&e.to_string()));
            ExitCode::FAILURE
        }
    }
}

/// `NAME@T` of `--osculating`.
fn parse_osculating(s: &str) -> Result<(String, f64), String> {
    let (name, t) = s
        .rsplit_once('@')
        .ok_or_else(|| format!("'{s}' is not NAME@T"))?;
    let t: f64 = t
        .parse()
        .ok()
        .filter(|t: &f64| t.is_finite())
        .ok_or_else(|| format!("'{t}' is not a parameter value"))?;
    Ok((name.to_string(), t))
}

fn print(text: &str) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| CliError(format!("cannot write to stdout: {e}")))
}
