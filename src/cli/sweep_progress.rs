//! A sweep's progress on stderr: an indicatif bar with ETA on a terminal, plain lines every
//! few seconds otherwise (logs of cluster jobs and CI), printed by a ticker thread so that long
//! runs still show the sweep is alive. Driven by the sweep's events ([`SweepDisplay::event`]), with
//! its notices (backend chosen, resume).

use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use quadrecomb::internals::experiment::events::Event;
use quadrecomb::internals::gpu::BackendNote;

/// How progress is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgressMode {
    /// A bar when stderr is a terminal, else plain lines.
    Auto,
    /// Plain lines every [`PLAIN_PERIOD`].
    Plain,
    /// No progress and no notices: only warnings (and errors).
    Quiet,
}

/// Shows what a sweep reports: the backend chosen (under -q only when it is a warning: a
/// fallback or a failed adapter), the resume notice and the progress (as `mode` says).
#[derive(Debug)]
pub struct SweepDisplay {
    mode: ProgressMode,
    progress: Option<Progress>,
}

impl SweepDisplay {
    /// Shows nothing until the sweep reports.
    pub fn new(mode: ProgressMode) -> SweepDisplay {
        SweepDisplay {
            mode,
            progress: None,
        }
    }

    /// Shows one event.
    pub fn event(&mut self, event: Event<'_>) {
        match event {
            // Under -q only warnings: a fallback or a failed adapter, not the GPU picked.
            Event::Backend(note) => {
                let info = matches!(
                    note,
                    BackendNote::Picked {
                        software: false,
                        ..
                    }
                );
                if self.mode != ProgressMode::Quiet || !info {
                    noteln!("quality backend: {note}");
                }
            }
            Event::Calibrated(note) => {
                if self.mode != ProgressMode::Quiet {
                    noteln!("{}", calibrated_line(note));
                }
            }
            Event::Extending { before, after } => {
                if self.mode != ProgressMode::Quiet {
                    noteln!(
                        "sweep: extending the sweep: its run list grows from {before} to {after} \
                         runs (the recorded ones are kept)"
                    );
                }
            }
            Event::Resuming {
                recorded,
                planned,
                torn,
            } => {
                if self.mode != ProgressMode::Quiet {
                    noteln!("{}", resuming_line(recorded, planned, torn));
                }
            }
            Event::Started { runs } => self.progress = Some(Progress::new(self.mode, runs)),
            Event::RunDone => {
                if let Some(p) = &self.progress {
                    p.inc();
                }
            }
            Event::Finished => {
                if let Some(mut p) = self.progress.take() {
                    p.finish();
                }
            }
        }
    }
}

/// The notice of a resumed sweep.
fn resuming_line(recorded: usize, planned: usize, torn: bool) -> String {
    format!(
        "sweep: resuming: {recorded} of {planned} runs already recorded{}",
        if torn {
            " (a torn last line was dropped and will be redone)"
        } else {
            ""
        }
    )
}

/// Time between two plain progress lines.
pub const PLAIN_PERIOD: Duration = Duration::from_secs(5);

#[derive(Debug)]
struct Shared {
    total: u64,
    done: AtomicU64,
    start: Instant,
    stop: Mutex<bool>,
    wake: Condvar,
}

/// A progress display for a known number of runs.
#[derive(Debug)]
pub struct Progress {
    bar: Option<ProgressBar>,
    shared: Arc<Shared>,
    ticker: Option<JoinHandle<()>>,
    finished: AtomicBool,
}

impl Progress {
    /// Starts showing progress over `total` runs.
    pub fn new(mode: ProgressMode, total: u64) -> Progress {
        let terminal = std::io::stderr().is_terminal();
        let shared = Arc::new(Shared {
            total,
            done: AtomicU64::new(0),
            start: Instant::now(),
            stop: Mutex::new(false),
            wake: Condvar::new(),
        });
        let bar = (mode == ProgressMode::Auto && terminal).then(|| {
            let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template(
                    "{prefix} [{elapsed_precise}] {wide_bar} {pos}/{len} runs ({per_sec}, ETA {eta})",
                )
                .expect("valid template"),
            );
            bar.set_prefix("sweep");
            bar.enable_steady_tick(Duration::from_millis(500));
            bar
        });
        let plain = mode == ProgressMode::Plain || (mode == ProgressMode::Auto && !terminal);
        let ticker = plain.then(|| {
            let shared = Arc::clone(&shared);
            std::thread::spawn(move || {
                let mut stop = shared.stop.lock().unwrap_or_else(|p| p.into_inner());
                // The flag is read before each wait: a stop set before this thread first
                // took the lock (a sweep of a few milliseconds) was waited out for a whole
                // period, 5 s more for every short sweep whose progress was plain lines.
                while !*stop {
                    let (guard, _) = shared
                        .wake
                        .wait_timeout_while(stop, PLAIN_PERIOD, |stop| !*stop)
                        .unwrap_or_else(|p| p.into_inner());
                    stop = guard;
                    if !*stop {
                        noteln!("{}", line(&shared));
                    }
                }
            })
        });
        Progress {
            bar,
            shared,
            ticker,
            finished: AtomicBool::new(false),
        }
    }

    /// One more run finished.
    pub fn inc(&self) {
        self.shared.done.fetch_add(1, Ordering::SeqCst);
        if let Some(bar) = &self.bar {
            bar.inc(1);
        }
    }

    /// The current plain line, e.g. "sweep: 340/1283 runs (26.5%), 12.3 s elapsed, ETA 34 s".
    #[cfg(test)]
    fn line(&self) -> String {
        line(&self.shared)
    }

    /// Stops the display; prints a last plain line when in plain mode.
    pub fn finish(&mut self) {
        if self.finished.swap(true, Ordering::SeqCst) {
            return;
        }
        if let Some(bar) = self.bar.take() {
            // Left drawn (its last figures), the cursor at the end of its line: end the line,
            // or the summary that follows runs into it.
            bar.abandon();
            if !bar.is_hidden() {
                noteln!();
            }
        }
        if let Some(t) = self.ticker.take() {
            *self.shared.stop.lock().unwrap_or_else(|p| p.into_inner()) = true;
            self.shared.wake.notify_all();
            let _ = t.join();
            noteln!("{}", line(&self.shared));
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.finish();
    }
}

fn line(s: &Shared) -> String {
    let done = s.done.load(Ordering::SeqCst);
    let elapsed = s.start.elapsed().as_secs_f64();
    let pct = if s.total == 0 {
        100.0
    } else {
        100.0 * done as f64 / s.total as f64
    };
    let eta = if done == 0 {
        "unknown".to_string()
    } else {
        let left = elapsed / done as f64 * s.total.saturating_sub(done) as f64;
        format!("{left:.0} s")
    };
    format!(
        "sweep: {done}/{} runs ({pct:.1}%), {elapsed:.1} s elapsed, ETA {eta}",
        s.total
    )
}

/// "sweep: calibrated 2/12: borouchaki mcts h=3 at 0.2 s: budget 40 (pilot median 0.19 s
/// over 4 pilots; 6 knobs probed)".
pub fn calibrated_line(
    note: &quadrecomb::internals::experiment::calibrate::CalibrationNote,
) -> String {
    let c = &note.calibrated;
    let (what, given) = match c.budget {
        Some(b) => (format!("budget {b}"), format!(" h={}", c.horizon)),
        None => (format!("horizon {}", c.horizon), String::new()),
    };
    format!(
        "sweep: calibrated {}/{}: {} {}{given} at {}: {what} (pilot median {:.3} s over {} \
         pilots; {} knobs probed){}",
        note.done,
        note.total,
        c.mesh,
        c.algo,
        c.time_budget_s,
        c.median_s,
        c.pilots,
        c.probes.len(),
        if c.saturated {
            " — it covers the pilots' trees: a larger one makes the same runs".to_string()
        } else if c.fits {
            String::new()
        } else {
            " — over the budget even at the smallest knob".to_string()
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sweep that ends as soon as it starts does not wait out the plain ticker's period
    /// (it did in about half of the tries: the stop came before the ticker's first wait).
    #[test]
    fn a_plain_display_stops_at_once() {
        let start = Instant::now();
        for _ in 0..40 {
            let mut p = Progress::new(ProgressMode::Plain, 1);
            p.inc();
            p.finish();
        }
        // 40 tries, each of which waited 5 s when the race was lost.
        assert!(start.elapsed() < PLAIN_PERIOD, "{:?}", start.elapsed());
    }

    #[test]
    fn plain_line_counts_and_estimates() {
        let p = Progress::new(ProgressMode::Quiet, 4);
        assert!(
            p.line().starts_with("sweep: 0/4 runs (0.0%)"),
            "{}",
            p.line()
        );
        assert!(p.line().ends_with("ETA unknown"));
        p.inc();
        assert!(
            p.line().starts_with("sweep: 1/4 runs (25.0%)"),
            "{}",
            p.line()
        );
        assert!(p.line().contains("ETA "));
    }

    #[test]
    fn events_drive_the_display() {
        assert_eq!(
            resuming_line(9, 40, true),
            "sweep: resuming: 9 of 40 runs already recorded (a torn last line was dropped \
             and will be redone)"
        );
        let mut d = SweepDisplay::new(ProgressMode::Quiet);
        d.event(Event::Started { runs: 3 });
        d.event(Event::RunDone);
        d.event(Event::RunDone);
        let line = d.progress.as_ref().unwrap().line();
        assert!(line.starts_with("sweep: 2/3 runs"), "{line}");
        d.event(Event::Finished);
        assert!(d.progress.is_none());
    }
}
