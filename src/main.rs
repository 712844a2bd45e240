//! The `prespline` command line.

use clap::{Parser, Subcommand};
use prespline::cli::{self, CliError};
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
}

#[derive(Subcommand)]
enum Command {
    /// Sample every object of a scene and print positions and derivatives as JSON on stdout.
    Sample {
        /// Scene file (JSON, see README "Scene files").
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
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Sample {
            scene,
            derivatives,
            edits,
            full,
        } => {
            let args = cli::sample::SampleArgs {
                scene: &scene,
                derivatives,
                edits: edits.as_deref(),
                full,
            };
            cli::sample::run(&args).and_then(|text| print(&text))
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn print(text: &str) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| CliError(format!("cannot write to stdout: {e}")))
}
