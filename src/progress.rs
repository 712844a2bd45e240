//! Progress of long work (parsing, pre-evaluation) as a sink handed down by the caller, so the
//! floors that do the work never print: the command line passes one that draws on a terminal
//! (`profile::TerminalProgress`), tests and library users pass [`Silent`].

/// Where progress goes.
pub trait ProgressSink: Sync {
    /// Starts a piece of work: `label` names it ("parsing"), `total` is the count at
    /// completion if known, `unit` names what is counted ("objects", "samples").
    fn start(&self, label: &str, total: Option<u64>, unit: &str) -> Box<dyn ProgressTask + '_>;
}

/// One piece of work in progress. Dropping it unfinished (an error ended the work) clears
/// what it showed, so that the error stands alone.
pub trait ProgressTask: Send + Sync {
    /// Counts `n` more done.
    fn inc(&self, n: u64);
}

/// Shows nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Silent;

impl ProgressSink for Silent {
    fn start(&self, _: &str, _: Option<u64>, _: &str) -> Box<dyn ProgressTask + '_> {
        Box::new(Silent)
    }
}

impl ProgressTask for Silent {
    fn inc(&self, _: u64) {}
}
