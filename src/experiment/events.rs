//! What a sweep tells its caller while it runs, through a callback (`FnMut(Event)`): the
//! caller shows progress and notices; the library prints nothing.

use crate::gpu::BackendNote;

/// One thing a sweep reports, in the order it happens.
#[derive(Debug, Clone, PartialEq)]
pub enum Event<'a> {
    /// How the quality backend was chosen (with [`crate::gpu::Backend::Auto`]).
    Backend(&'a BackendNote),
    /// A time budget was calibrated (before any run: `sweep --time-budgets`).
    Calibrated(&'a super::calibrate::CalibrationNote),
    /// A sweep extends its directory's configuration: its run list grows.
    Extending {
        /// Runs in the directory's run list before.
        before: usize,
        /// Runs in the extended run list.
        after: usize,
    },
    /// A resumed sweep found runs already recorded.
    Resuming {
        /// Runs found recorded.
        recorded: usize,
        /// Runs in this directory's share of the run list.
        planned: usize,
        /// Whether a torn last line was dropped (its run is redone).
        torn: bool,
    },
    /// The runs start: this many are to be done now.
    Started {
        /// Runs to do.
        runs: u64,
    },
    /// One more run finished and was recorded.
    RunDone,
    /// No more runs will finish (all done, cancelled, or failed).
    Finished,
}

/// The callback a sweep reports its [`Event`]s to.
pub type Events<'a> = dyn FnMut(Event<'_>) + Send + 'a;
