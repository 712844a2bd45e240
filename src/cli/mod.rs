//! The subcommands behind `src/main.rs`, kept in the library so tests can call them. Each
//! command is a file with its clap `Args` and its `run`, registered once in `commands!`
//! below; this floor is the only one that prints.

pub mod args;
pub mod bench;
pub mod convert;
pub mod info;
pub mod load;
pub mod render;
pub mod resident;
pub mod sample;
pub mod samples;
pub mod view;

/// A command failure: one line for stderr; the process exits non-zero.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct CliError(pub String);

impl CliError {
    /// Prefixes a scene/edit error with the file it came from.
    pub fn in_file(path: &std::path::Path, e: impl std::fmt::Display) -> Self {
        CliError(format!("{}: {e}", path.display()))
    }
}

/// Declares the subcommands, `Variant(module)` each: generates [`Command`] (whose help is
/// each `Args` struct's doc comment) and its dispatch to `module::run`. A new command is its
/// file, its `mod` line above and one line here.
macro_rules! commands {
    ($($variant:ident($module:ident::$args:ident)),+ $(,)?) => {
        /// A subcommand with its arguments.
        #[derive(clap::Subcommand, Debug, Clone)]
        pub enum Command {
            $($variant($module::$args),)+
        }

        impl Command {
            /// Runs the command; it prints its own output and returns the error line.
            pub fn run(self) -> Result<(), CliError> {
                match self {
                    $(Command::$variant(a) => $module::run(a),)+
                }
            }
        }
    };
}

commands! {
    Sample(sample::SampleArgs),
    View(view::ViewArgs),
    Bench(bench::BenchArgs),
    Render(render::RenderArgs),
    Convert(convert::ConvertArgs),
    Info(info::InfoArgs),
}

/// Writes `text` to stdout in one piece.
pub fn print_stdout(text: &str) -> Result<(), CliError> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| CliError(format!("cannot write to stdout: {e}")))
}
