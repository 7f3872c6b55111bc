//! Executes a list of jobs on a rayon pool: one worker (and so one reusable searcher) per
//! thread, jobs handed out in order from a shared counter, results passed to one sink under a
//! lock (the single writer), a cancel flag checked between jobs.

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use super::ExperimentError;
use super::manifest::OptimumEntry;
use super::plan::Job;
use crate::quality::{CandidateTable, ElementQuality};
use crate::search::RunOutcome;

/// What a run produced, apart from what identifies it.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// Quads created.
    pub quads: usize,
    /// Triangles left.
    pub triangles_left: usize,
    /// Sum of eta over the quads.
    pub quality: f64,
    /// Tree nodes expanded.
    pub nodes_expanded: u64,
    /// Look-ahead trees built.
    pub trees: u64,
    /// Decisions taken.
    pub decisions: u64,
    /// Seconds of search.
    pub time_s: f64,
    /// Worst and mean eta of the quads, and the poor ones.
    pub elements: ElementQuality,
    /// The run after its finish (`sweep --finish`).
    pub finish: Option<super::finished::FinishOutcome>,
}

impl Outcome {
    /// The outcome of a search run, with its quads' eta figures from `table` (the one
    /// conversion from [`RunOutcome`]).
    pub fn of_run(out: &RunOutcome, table: &CandidateTable) -> Outcome {
        Outcome {
            quads: out.quads,
            triangles_left: out.triangles_left,
            quality: out.quality,
            nodes_expanded: out.nodes_expanded,
            trees: out.trees,
            decisions: out.decisions,
            time_s: out.time_s,
            elements: ElementQuality::of_chosen(table, &out.chosen),
            finish: None,
        }
    }

    /// The outcome recorded for the optimum's run: its matching, no tree, one decision per
    /// quad, the time the matching took.
    pub fn of_optimum(o: &OptimumEntry) -> Outcome {
        Outcome {
            quads: o.quads,
            triangles_left: o.triangles_left,
            quality: o.quality,
            nodes_expanded: 0,
            trees: 0,
            decisions: o.quads as u64,
            time_s: o.time_s,
            elements: o.elements,
            finish: None,
        }
    }
}

/// Runs jobs one after another on one thread, keeping whatever it reuses between them.
pub trait Worker {
    /// Runs one job.
    fn run(&mut self, job: &Job) -> Result<Outcome, ExperimentError>;
}

/// Makes one [`Worker`] per thread.
pub trait WorkerFactory: Sync {
    /// A fresh worker for one thread.
    fn worker(&self) -> Box<dyn Worker + '_>;
}

/// How an execution ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Executed {
    /// Jobs finished and passed to the sink.
    pub finished: usize,
    /// Whether the cancel flag stopped it before every job ran.
    pub cancelled: bool,
}

/// Runs `jobs` on `threads` threads and passes each finished one to `sink` (called under a
/// lock, so it may write files). Stops handing out jobs when `cancel` is set (in-flight jobs
/// finish and are kept) or after the first error (worker or sink), which is returned.
pub fn execute(
    jobs: &[Job],
    threads: usize,
    factory: &dyn WorkerFactory,
    cancel: &AtomicBool,
    sink: &mut (dyn FnMut(&Job, Outcome) -> Result<(), ExperimentError> + Send),
) -> Result<Executed, ExperimentError> {
    let threads = threads.max(1).min(jobs.len().max(1));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("sweep-{i}"))
        .build()
        .map_err(|e| ExperimentError::Run(format!("cannot start {threads} threads: {e}")))?;
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let error: Mutex<Option<ExperimentError>> = Mutex::new(None);
    let finished = AtomicUsize::new(0);
    let sink = Mutex::new(sink);
    pool.scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|_| {
                let mut worker = factory.worker();
                loop {
                    if cancel.load(Ordering::SeqCst) || failed.load(Ordering::SeqCst) {
                        break;
                    }
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(job) = jobs.get(i) else { break };
                    let result = worker.run(job).and_then(|outcome| {
                        let mut sink = sink.lock().unwrap_or_else(|p| p.into_inner());
                        (*sink)(job, outcome)
                    });
                    match result {
                        Ok(()) => {
                            finished.fetch_add(1, Ordering::SeqCst);
                        }
                        Err(e) => {
                            failed.store(true, Ordering::SeqCst);
                            error
                                .lock()
                                .unwrap_or_else(|p| p.into_inner())
                                .get_or_insert(e);
                            break;
                        }
                    }
                }
            });
        }
    });
    if let Some(e) = error.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(e);
    }
    let finished = finished.into_inner();
    Ok(Executed {
        finished,
        cancelled: finished < jobs.len(),
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A worker whose outcome is a pure function of the job's seed.
    #[derive(Debug)]
    pub(crate) struct FakeFactory {
        pub(crate) fail_on_run: Option<u32>,
    }

    struct FakeWorker<'a> {
        factory: &'a FakeFactory,
        runs: u64,
    }

    impl Worker for FakeWorker<'_> {
        fn run(&mut self, job: &Job) -> Result<Outcome, ExperimentError> {
            self.runs += 1;
            if self.factory.fail_on_run == Some(job.run) {
                return Err(ExperimentError::Run(format!("job {} failed", job.run)));
            }
            Ok(fake_outcome(job))
        }
    }

    pub(crate) fn fake_outcome(job: &Job) -> Outcome {
        let h = job.horizon.unwrap_or(1);
        // Values a run can have on the test spec's meshes (10 and 20 triangles, optimum 5
        // quads): the records are checked when resumed or merged.
        let triangles = 10 * (job.mesh + 1);
        // The optimum's run is the recorded optimum (`engine::tests::manifest`), as it is
        // checked to be.
        let (quads, eta) = if job.algo == "optimum" {
            (5, 0.9)
        } else {
            ((job.seed % 3) as usize + 2, (job.seed % 100) as f64 / 100.0)
        };
        Outcome {
            quads,
            triangles_left: triangles - 2 * quads,
            quality: quads as f64 * eta,
            nodes_expanded: u64::from(h) * 10 + job.seed % 7,
            trees: 5,
            decisions: 5,
            time_s: 0.001 * f64::from(h),
            elements: crate::quality::ElementQuality::of(vec![eta; quads]),
            finish: None,
        }
    }

    impl WorkerFactory for FakeFactory {
        fn worker(&self) -> Box<dyn Worker + '_> {
            Box::new(FakeWorker {
                factory: self,
                runs: 0,
            })
        }
    }

    fn jobs(n: u32) -> Vec<Job> {
        (0..n)
            .map(|run| Job {
                mesh: 0,
                algo: "selective".into(),
                horizon: Some(1 + run % 3),
                budget: None,
                time_budget: None,
                run,
                seed: u64::from(run) * 7919,
            })
            .collect()
    }

    #[test]
    fn every_job_once_whatever_the_threads() {
        let jobs = jobs(50);
        for threads in [1, 2, 5] {
            let mut got = Vec::new();
            let cancel = AtomicBool::new(false);
            let done = execute(
                &jobs,
                threads,
                &FakeFactory { fail_on_run: None },
                &cancel,
                &mut |job, out| {
                    got.push((job.run, out));
                    Ok(())
                },
            )
            .unwrap();
            assert_eq!(
                done,
                Executed {
                    finished: 50,
                    cancelled: false
                }
            );
            got.sort_by_key(|g| g.0);
            let want: Vec<_> = jobs.iter().map(|j| (j.run, fake_outcome(j))).collect();
            assert_eq!(got, want, "{threads} threads");
        }
    }

    #[test]
    fn cancel_stops_handing_out_jobs() {
        let jobs = jobs(50);
        let cancel = AtomicBool::new(false);
        let mut seen = 0;
        let done = execute(
            &jobs,
            2,
            &FakeFactory { fail_on_run: None },
            &cancel,
            &mut |_, _| {
                seen += 1;
                if seen == 10 {
                    cancel.store(true, Ordering::SeqCst);
                }
                Ok(())
            },
        )
        .unwrap();
        assert!(done.cancelled);
        assert_eq!(done.finished, seen);
        assert!((10..=11).contains(&seen), "{seen}");
    }

    #[test]
    fn first_error_is_returned() {
        let jobs = jobs(50);
        let cancel = AtomicBool::new(false);
        let err = execute(
            &jobs,
            2,
            &FakeFactory {
                fail_on_run: Some(20),
            },
            &cancel,
            &mut |_, _| Ok(()),
        )
        .unwrap_err();
        assert!(err.to_string().contains("job 20 failed"));
    }
}
