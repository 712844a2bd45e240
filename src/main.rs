//! The `prespline` command line: parses the arguments and hands them to the command
//! (src/cli/, one file each).
#![deny(unsafe_code)]

use clap::Parser;
use prespline::cli::Command;
use prespline::scene::escape_controls;
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
    let joined = escape_controls(&joined).into_owned();
    format!("{joined} (try --help)")
}

fn main() -> ExitCode {
    let cli = match parse_cli() {
        Ok(cli) => cli,
        Err(code) => return code,
    };
    if let Some(n) = cli.threads {
        // The pool size of the whole process, as RAYON_NUM_THREADS is for rayon: results are
        // the same bits on any number (src/parallel.rs).
        prespline::parallel::set_threads(usize::from(n));
    }
    match cli.command.run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", escape_controls(&e.to_string()));
            ExitCode::FAILURE
        }
    }
}
