//! Progress on stderr: an indicatif bar with ETA on a terminal, plain periodic lines otherwise
//! (logs of cluster jobs and CI).

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// How progress is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProgressMode {
    /// A bar when stderr is a terminal, else plain lines.
    Auto,
    /// Plain lines every `PLAIN_PERIOD`.
    Plain,
    /// Nothing.
    Quiet,
}

/// Time between two plain progress lines.
pub const PLAIN_PERIOD: Duration = Duration::from_secs(5);

/// A progress display for a known number of runs.
#[derive(Debug)]
pub struct Progress {
    bar: Option<ProgressBar>,
    plain: bool,
    total: u64,
    done: u64,
    start: Instant,
    last_line: Instant,
}

impl Progress {
    /// Starts showing progress over `total` runs (`already` of a larger list were done before).
    pub fn new(mode: ProgressMode, total: u64) -> Progress {
        let terminal = std::io::stderr().is_terminal();
        let bar = (mode == ProgressMode::Auto && terminal).then(|| {
            let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            bar.set_style(
                ProgressStyle::with_template(
                    "{prefix} [{elapsed_precise}] {wide_bar} {pos}/{len} runs ({per_sec}, ETA {eta})",
                )
                .expect("valid template"),
            );
            bar.set_prefix("sweep");
            bar
        });
        let plain = mode == ProgressMode::Plain || (mode == ProgressMode::Auto && !terminal);
        let now = Instant::now();
        Progress {
            bar,
            plain,
            total,
            done: 0,
            start: now,
            last_line: now,
        }
    }

    /// One more run finished.
    pub fn inc(&mut self) {
        self.done += 1;
        if let Some(bar) = &self.bar {
            bar.inc(1);
        } else if self.plain && self.last_line.elapsed() >= PLAIN_PERIOD {
            self.last_line = Instant::now();
            eprintln!("{}", self.line());
        }
    }

    /// A line such as "sweep: 340/1283 runs (26.5%), 12.3 s elapsed, ETA 34 s".
    pub fn line(&self) -> String {
        let elapsed = self.start.elapsed().as_secs_f64();
        let pct = if self.total == 0 {
            100.0
        } else {
            100.0 * self.done as f64 / self.total as f64
        };
        let eta = if self.done == 0 {
            "unknown".to_string()
        } else {
            let left = elapsed / self.done as f64 * (self.total - self.done.min(self.total)) as f64;
            format!("{left:.0} s")
        };
        format!(
            "sweep: {}/{} runs ({pct:.1}%), {elapsed:.1} s elapsed, ETA {eta}",
            self.done, self.total
        )
    }

    /// Stops the display; prints a last plain line when in plain mode.
    pub fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.abandon();
        } else if self.plain {
            eprintln!("{}", self.line());
        }
    }
}
