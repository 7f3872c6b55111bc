//! Wall-time budgets, calibrated into the reproducible knobs (issue #22, `sweep
//! --time-budgets`).
//!
//! A search stopped on the clock would depend on the machine and its load, not only on its
//! seed, and every record must replay from its seed. So a time budget `T` (seconds per run)
//! is turned, once per sweep, into the knob of each method that has one: the node budget per
//! decision of the budgeted policies (at each given horizon), the horizon of `selective` and
//! `uniform`. The knob chosen is the largest one whose median run time over a few pilot runs
//! (seeds derived with a "calibration" tag, never a sweep's) is at most `T (1 + TOLERANCE)`.
//! The manifest keeps every calibration (its probes, pilot times and machine); a resumed or
//! extended sweep reuses it and never calibrates again, and each record keeps `time_budget_s`
//! beside the `budget` / `horizon` it ran with, which `replay` replays as any other run.

use serde::{Deserialize, Serialize};

use super::ExperimentError;
use super::exec::{WorkerFactory, execute};
use super::manifest::{Machine, SweepSpec};
use super::plan::{Job, has_budget, has_horizon};
use crate::stats::describe::median;

/// How far above its time budget a knob's pilot median may lie and still be chosen (5 %).
pub const TOLERANCE: f64 = 0.05;
/// Shortest time budget taken (1 ms: below it a run's time is mostly the clock's noise).
pub const MIN_SECONDS: f64 = 0.001;
/// Longest time budget taken (one day per run).
pub const MAX_SECONDS: f64 = 86_400.0;
/// Fewest pilot runs per probed knob (rounded up to a multiple of the worker threads, so that
/// the pilots run as contended as the sweep's runs).
pub const MIN_PILOTS: u32 = 3;
/// Most knobs probed per calibrated time budget.
pub const MAX_PROBES: usize = 12;
/// The largest horizon a calibration of `selective` or `uniform` probes.
pub const MAX_HORIZON: u32 = 256;
/// A probe is close enough when its pilot median lies within this fraction below the budget
/// (the search then stops; the choice is still the largest knob that fits).
const CLOSE_BELOW: f64 = 0.15;

/// A wall-time budget per run, in seconds: finite, in [`MIN_SECONDS`]..=[`MAX_SECONDS`].
/// Ordered and hashed by value, so that it can name a configuration; serialised as a plain
/// number of seconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct TimeBudget(f64);

impl Eq for TimeBudget {}

impl PartialOrd for TimeBudget {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for TimeBudget {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

impl std::hash::Hash for TimeBudget {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.0.to_bits().hash(state);
    }
}

/// Why a number of seconds is not a time budget.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TimeBudgetError {
    /// Not a number of seconds with an optional unit.
    #[error("{0:?} is not a time: expected seconds (0.2, 2s) or milliseconds (50ms)")]
    Syntax(String),
    /// Not finite, or out of range.
    #[error(
        "{0:?} s is not a time budget: it must be a finite number of seconds from {MIN_SECONDS} \
         to {MAX_SECONDS} (one day)"
    )]
    Range(f64),
}

impl TimeBudget {
    /// The budget of `seconds`, if it is one.
    pub fn new(seconds: f64) -> Result<TimeBudget, TimeBudgetError> {
        if seconds.is_finite() && (MIN_SECONDS..=MAX_SECONDS).contains(&seconds) {
            Ok(TimeBudget(seconds))
        } else {
            Err(TimeBudgetError::Range(seconds))
        }
    }

    /// Seconds.
    pub fn seconds(self) -> f64 {
        self.0
    }

    /// Whether it holds a value [`TimeBudget::new`] takes (a manifest or record read back).
    pub fn is_valid(self) -> bool {
        TimeBudget::new(self.0).is_ok()
    }
}

impl std::fmt::Display for TimeBudget {
    /// Seconds, shortest form that reads back: "0.2 s".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} s", self.0)
    }
}

impl std::str::FromStr for TimeBudget {
    type Err = TimeBudgetError;

    /// "0.2", "0.2s", "50ms" (no other unit).
    fn from_str(s: &str) -> Result<TimeBudget, TimeBudgetError> {
        let t = s.trim();
        let (number, scale) = if let Some(n) = t.strip_suffix("ms") {
            (n, 1e-3)
        } else if let Some(n) = t.strip_suffix('s') {
            (n, 1.0)
        } else {
            (t, 1.0)
        };
        let v: f64 = (number.trim().parse()).map_err(|_| TimeBudgetError::Syntax(s.to_string()))?;
        TimeBudget::new(v * scale)
    }
}

/// One knob probed: its value and the pilot runs' times.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Probe {
    /// The knob's value (nodes per decision, or horizon).
    pub knob: u32,
    /// Seconds of each pilot run, in pilot order.
    pub times_s: Vec<f64>,
}

impl Probe {
    /// The pilots' median time.
    pub fn median_s(&self) -> f64 {
        median(&self.times_s)
    }
}

/// The calibration of one (mesh, method, horizon of a budgeted method, time budget): the
/// knob chosen and how. Part of the manifest's spec: the run list depends on it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Calibrated {
    /// Mesh name.
    pub mesh: String,
    /// Method name.
    pub algo: String,
    /// The time budget, seconds per run.
    pub time_budget_s: TimeBudget,
    /// The horizon the runs have: given (a budgeted method's, one calibration per horizon of
    /// the sweep) or chosen (`selective`, `uniform`).
    pub horizon: u32,
    /// The node budget per decision chosen (budgeted methods); absent for the others.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub budget: Option<u32>,
    /// The pilots' median time at the chosen knob.
    pub median_s: f64,
    /// Whether that median is at most `T (1 + tolerance)`; false when even the smallest knob
    /// takes longer (its runs then exceed the budget, and the report says so).
    pub fits: bool,
    /// Whether a larger knob probed made the same pilot runs (this one covers their trees:
    /// a larger one only takes longer), so the search stopped here below the budget.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub saturated: bool,
    /// The tolerance above the budget used.
    pub tolerance: f64,
    /// Pilot runs per probe.
    pub pilots: u32,
    /// Worker threads the pilots ran on (the sweep's).
    pub threads: usize,
    /// Every knob probed for this (mesh, method, horizon), ascending, with its pilot times
    /// (shared by the time budgets calibrated together).
    pub probes: Vec<Probe>,
    /// The machine the pilots ran on.
    pub machine: Machine,
}

impl Calibrated {
    /// Whether this calibration is the one for (mesh, algo, given horizon, budget).
    pub fn is_for(&self, mesh: &str, algo: &str, horizon: Option<u32>, t: TimeBudget) -> bool {
        self.mesh == mesh
            && self.algo == algo
            && self.time_budget_s == t
            && (!has_budget(algo) || Some(self.horizon) == horizon)
    }

    /// The knob chosen.
    pub fn knob(&self) -> u32 {
        self.budget.unwrap_or(self.horizon)
    }
}

/// The methods a time budget applies to: those with a knob (a horizon or a node budget).
pub fn has_knob(algo: &str) -> bool {
    has_horizon(algo) || has_budget(algo)
}

/// The calibration of `spec` for (mesh, algo, given horizon, t), if made.
pub fn find<'a>(
    spec: &'a SweepSpec,
    mesh: &str,
    algo: &str,
    horizon: Option<u32>,
    t: TimeBudget,
) -> Option<&'a Calibrated> {
    (spec.calibration.iter()).find(|c| c.is_for(mesh, algo, horizon, t))
}

/// How the knob is searched for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum KnobKind {
    /// Node budget per decision: time grows about linearly with it; proportional steps,
    /// then bisection (geometric) between the largest knob that fits and the smallest that
    /// does not.
    Nodes,
    /// Horizon: time grows with it, for `uniform` exponentially; one step up at a time
    /// (larger steps while far below the budget), then bisection.
    Horizon,
}

/// The knob chosen for one time budget.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Choice {
    /// The knob.
    pub knob: u32,
    /// Its pilots' median time.
    pub median_s: f64,
    /// Whether that median is at most the budget times (1 + tolerance).
    pub fits: bool,
    /// Whether a larger knob probed gave the same pilot results (it covers their trees).
    pub saturated: bool,
}

/// Finds, for each of `targets` (seconds), the largest knob in `min..=max` whose median
/// time (`measure(knob)`: one pilot time each, and a digest of the pilots' results) is at
/// most `target (1 + tolerance)`; the smallest knob probed when none is (`fits` false).
/// The pilots have the same seeds at every knob, so a larger knob whose pilots give the
/// same results as a smaller one's shows that the smaller already covers their trees: knobs
/// above it make the same runs (only slower) and are not chosen ([`Choice::saturated`]).
/// Probes are shared between targets (knobs already in `probes` are not measured again)
/// and the choices are made from all of them at the end, so a larger target never gets a
/// smaller knob. Returns the choices in the order of `targets`; `probes` ends sorted by knob.
pub fn search_knobs<E>(
    targets: &[f64],
    kind: KnobKind,
    (min, max): (u32, u32),
    tolerance: f64,
    probes: &mut Vec<Probe>,
    measure: &mut dyn FnMut(u32) -> Result<(Vec<f64>, u64), E>,
) -> Result<Vec<Choice>, E> {
    let mut sorted: Vec<f64> = targets.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mut digests: Vec<(u32, u64)> = Vec::new();
    // The smallest knob whose pilot results every larger knob probed repeats, one of them
    // at least twice as large: the budget no longer binds there (equal results at two
    // nearby knobs, or with a different result above, prove nothing).
    let ceiling = |digests: &[(u32, u64)]| {
        (digests.iter())
            .filter(|(k, d)| {
                let above: Vec<&(u32, u64)> = digests.iter().filter(|(k2, _)| k2 > k).collect();
                above
                    .iter()
                    .any(|(k2, _)| u64::from(*k2) >= 2 * u64::from(*k))
                    && above.iter().all(|(_, d2)| d2 == d)
            })
            .map(|(k, _)| *k)
            .min()
            .unwrap_or(max)
    };
    for &target in &sorted {
        let limit = target * (1.0 + tolerance);
        for _ in 0..MAX_PROBES {
            let top = ceiling(&digests);
            let times: Vec<(u32, f64)> = (probes.iter())
                .filter(|p| p.knob <= top)
                .map(|p| (p.knob, p.median_s()))
                .collect();
            let lo = (times.iter()).filter(|t| t.1 <= limit).max_by_key(|t| t.0);
            let hi = (times.iter())
                .filter(|t| t.1 > limit && lo.is_none_or(|l| t.0 > l.0))
                .min_by_key(|t| t.0);
            if lo.is_some_and(|l| l.1 >= target * (1.0 - CLOSE_BELOW) || l.0 == top) {
                break;
            }
            if hi.is_some_and(|h| h.0 == min) {
                break; // even the smallest knob is too slow
            }
            if let (Some(l), Some(h)) = (lo, hi)
                && h.0 <= l.0 + 1
            {
                break;
            }
            let next = match (kind, lo, hi) {
                (KnobKind::Nodes, None, None) => 16.clamp(min, top),
                (KnobKind::Horizon, None, None) => min,
                (_, Some(l), Some(h)) => match kind {
                    KnobKind::Nodes => {
                        // Proportional estimate, kept strictly inside the bracket.
                        let guess = (f64::from(l.0) * target / l.1.max(1e-9)).round();
                        let mid = (f64::from(l.0) * f64::from(h.0)).sqrt().round();
                        let g = if guess > f64::from(l.0) && guess < f64::from(h.0) {
                            guess
                        } else {
                            mid
                        };
                        (g as u32).clamp(l.0 + 1, h.0 - 1)
                    }
                    KnobKind::Horizon => l.0 + (h.0 - l.0) / 2,
                },
                (KnobKind::Nodes, Some(l), None) => {
                    // Proportional, at most 8 times up (the fixed part of a run's time
                    // makes the estimate overshoot when far below).
                    let guess = (f64::from(l.0) * target / l.1.max(1e-9)).min(8.0 * f64::from(l.0));
                    (guess.round().min(f64::from(top)) as u32).clamp(l.0 + 1, top)
                }
                (KnobKind::Horizon, Some(l), None) => {
                    let step = if l.1 < target / 3.0 {
                        (l.0 / 2).max(1)
                    } else {
                        1
                    };
                    l.0.saturating_add(step).min(top)
                }
                (KnobKind::Nodes, None, Some(h)) => {
                    let guess = f64::from(h.0) * target / h.1.max(1e-9);
                    (guess.round().max(f64::from(min)) as u32).clamp(min, h.0 - 1)
                }
                (KnobKind::Horizon, None, Some(h)) => (h.0 / 2).max(min),
            };
            if probes.iter().any(|p| p.knob == next) {
                break;
            }
            let (times, digest) = measure(next)?;
            digests.push((next, digest));
            probes.push(Probe {
                knob: next,
                times_s: times,
            });
        }
    }
    probes.sort_by_key(|p| p.knob);
    let top = ceiling(&digests);
    Ok(targets
        .iter()
        .map(|&target| choose(probes, target * (1.0 + tolerance), top))
        .collect())
}

/// The first 8 bytes of a pilot digest (the pilots' quads and quality), as a number.
fn first_u64(digest: &blake3::Hasher) -> u64 {
    let bytes = digest.finalize();
    u64::from_le_bytes(bytes.as_bytes()[..8].try_into().expect("8 of 32 bytes"))
}

/// The largest probed knob up to `top` whose median is at most `limit`; the smallest probed
/// when none.
fn choose(probes: &[Probe], limit: f64, top: u32) -> Choice {
    let fit = (probes.iter())
        .filter(|p| p.knob <= top && p.median_s() <= limit)
        .max_by_key(|p| p.knob);
    let p = fit
        .or_else(|| probes.iter().min_by_key(|p| p.knob))
        .expect("a probe");
    Choice {
        knob: p.knob,
        median_s: p.median_s(),
        fits: fit.is_some(),
        saturated: fit.is_some() && p.knob == top && probes.iter().any(|q| q.knob > top),
    }
}

/// The pilot runs per probe on `threads` threads: at least [`MIN_PILOTS`], a multiple of the
/// threads.
pub fn pilots_for(threads: usize) -> u32 {
    let t = threads.max(1) as u32;
    MIN_PILOTS.div_ceil(t) * t
}

/// What a sweep's calibration tells its caller, one per calibration made.
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrationNote {
    /// The calibration made.
    pub calibrated: Calibrated,
    /// Calibrations made so far and in all.
    pub done: usize,
    /// Calibrations to make in all.
    pub total: usize,
}

/// The calibrations `spec` needs (its time budgets, for every mesh and method with a knob,
/// and every horizon of the budgeted methods): those of `existing` are kept as they are (a
/// resumed or extended sweep makes the same runs), the others made now by pilot runs through
/// `factory` on `threads` threads, each reported to `note`. `cancel` stops between probes
/// (an error: no run is made without its calibration).
pub fn calibrate_spec(
    spec: &SweepSpec,
    existing: &[Calibrated],
    factory: &dyn WorkerFactory,
    threads: usize,
    cancel: &std::sync::atomic::AtomicBool,
    note: &mut dyn FnMut(&CalibrationNote),
) -> Result<Vec<Calibrated>, ExperimentError> {
    let mut out: Vec<Calibrated> = existing.to_vec();
    // (mesh index, algo, given horizon) -> the time budgets to calibrate there.
    let mut todo: Vec<(usize, String, Option<u32>, Vec<TimeBudget>)> = Vec::new();
    for (m, mesh) in spec.meshes.iter().enumerate() {
        for algo in spec.algos.iter().filter(|a| has_knob(a)) {
            let horizons: Vec<Option<u32>> = if has_budget(algo) {
                spec.horizons.iter().map(|&h| Some(h)).collect()
            } else {
                vec![None]
            };
            for h in horizons {
                let missing: Vec<TimeBudget> = (spec.time_budgets.iter().copied())
                    .filter(|&t| !out.iter().any(|c| c.is_for(&mesh.name, algo, h, t)))
                    .collect();
                if !missing.is_empty() {
                    todo.push((m, algo.clone(), h, missing));
                }
            }
        }
    }
    let total: usize = todo.iter().map(|t| t.3.len()).sum();
    let pilots = pilots_for(threads);
    let machine = Machine::current();
    let mut done = 0;
    for (m, algo, horizon, budgets) in todo {
        let mesh = &spec.meshes[m];
        let nodes = has_budget(&algo);
        let (kind, range) = if nodes {
            let b = crate::search::methods::BUDGET;
            (KnobKind::Nodes, (b.min, b.max))
        } else {
            (KnobKind::Horizon, (1, MAX_HORIZON))
        };
        let mut measure = |knob: u32| -> Result<(Vec<f64>, u64), ExperimentError> {
            if cancel.load(std::sync::atomic::Ordering::SeqCst) {
                return Err(ExperimentError::Interrupted(
                    "interrupted while calibrating the time budgets: no run was made".into(),
                ));
            }
            let (h, b) = if nodes {
                (horizon, Some(knob))
            } else {
                (Some(knob), None)
            };
            // The same pilot seeds at every knob: times compare on the same runs, and a
            // knob that changes no run shows it.
            let named = match horizon {
                Some(h) => format!("calibration {algo} h={h}"),
                None => format!("calibration {algo}"),
            };
            let jobs: Vec<Job> = (0..pilots)
                .map(|run| Job {
                    mesh: m,
                    algo: algo.clone(),
                    horizon: h,
                    budget: b,
                    time_budget: None,
                    run,
                    seed: super::seed::derive_seed(
                        spec.plan_version,
                        spec.seed,
                        &mesh.hash,
                        &named,
                        None,
                        run,
                    ),
                })
                .collect();
            let mut times = vec![0.0; jobs.len()];
            let mut results = vec![(0usize, 0u64); jobs.len()];
            let never = std::sync::atomic::AtomicBool::new(false);
            execute(&jobs, threads, factory, &never, &mut |job, outcome| {
                times[job.run as usize] = outcome.time_s;
                results[job.run as usize] = (outcome.quads, outcome.quality.to_bits());
                Ok(())
            })?;
            let mut digest = blake3::Hasher::new();
            for (q, bits) in results {
                digest.update(&(q as u64).to_le_bytes());
                digest.update(&bits.to_le_bytes());
            }
            Ok((times, first_u64(&digest)))
        };
        let targets: Vec<f64> = budgets.iter().map(|t| t.seconds()).collect();
        let mut probes = Vec::new();
        let choices = search_knobs(&targets, kind, range, TOLERANCE, &mut probes, &mut measure)?;
        for (t, c) in budgets.iter().zip(choices) {
            let calibrated = Calibrated {
                mesh: mesh.name.clone(),
                algo: algo.clone(),
                time_budget_s: *t,
                horizon: if nodes {
                    horizon.expect("a budgeted method has a horizon")
                } else {
                    c.knob
                },
                budget: nodes.then_some(c.knob),
                median_s: c.median_s,
                fits: c.fits,
                saturated: c.saturated,
                tolerance: TOLERANCE,
                pilots,
                threads,
                probes: probes.clone(),
                machine: machine.clone(),
            };
            done += 1;
            note(&CalibrationNote {
                calibrated: calibrated.clone(),
                done,
                total,
            });
            out.push(calibrated);
        }
    }
    Ok(out)
}

/// The calibration of one run (`recombine --time-budget`): the knob of `algo` (its node
/// budget at `horizon`, or its horizon) for `t`, found by pilot runs one after another on
/// this thread (as the run itself goes), with seeds derived from `seed` and a calibration
/// tag, never `seed` itself. Returns the choice and the probes.
pub fn calibrate_run(
    mesh: &crate::mesh::Mesh,
    table: &crate::quality::CandidateTable,
    algo: &str,
    horizon: Option<u32>,
    t: TimeBudget,
    seed: u64,
) -> Result<(Choice, Vec<Probe>), crate::search::AlgoError> {
    let nodes = has_budget(algo);
    let (kind, range) = if nodes {
        let b = crate::search::methods::BUDGET;
        (KnobKind::Nodes, (b.min, b.max))
    } else {
        (KnobKind::Horizon, (1, MAX_HORIZON))
    };
    // Checks the method and the given horizon once, before any pilot.
    crate::search::Algo::new(
        algo,
        crate::search::Params {
            horizon,
            budget: None,
        },
    )?;
    let mut searcher = crate::search::Searcher::new(mesh, table);
    let mut measure = |knob: u32| -> Result<(Vec<f64>, u64), crate::search::AlgoError> {
        let params = if nodes {
            crate::search::Params {
                horizon,
                budget: Some(knob),
            }
        } else {
            crate::search::Params {
                horizon: Some(knob),
                budget: None,
            }
        };
        let method = crate::search::Algo::new(algo, params)?;
        let mut times = Vec::new();
        let mut digest = blake3::Hasher::new();
        for i in 0..MIN_PILOTS {
            let pilot = super::seed::derive_seed(
                super::seed::PLAN_VERSION,
                seed,
                "recombine",
                &format!("calibration {algo}"),
                horizon,
                i,
            );
            let out = searcher.run(method, pilot);
            times.push(out.time_s);
            digest.update(&(out.quads as u64).to_le_bytes());
            digest.update(&out.quality.to_bits().to_le_bytes());
        }
        Ok((times, first_u64(&digest)))
    };
    let mut probes = Vec::new();
    let choice = search_knobs(
        &[t.seconds()],
        kind,
        range,
        TOLERANCE,
        &mut probes,
        &mut measure,
    )?;
    Ok((choice[0], probes))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run time linear in the knob with a fixed part and a deterministic wobble.
    fn model(knob: u32) -> Result<(Vec<f64>, u64), ()> {
        let base = 0.05 + 0.002 * f64::from(knob);
        let times = (0..3)
            .map(|i| base * (1.0 + 0.02 * f64::from((knob * 7 + i) % 5) - 0.04))
            .collect();
        Ok((times, u64::from(knob)))
    }

    #[test]
    fn parsing_and_range() {
        let t = |s: &str| s.parse::<TimeBudget>().map(TimeBudget::seconds);
        assert_eq!(t("0.2"), Ok(0.2));
        assert_eq!(t("0.2s"), Ok(0.2));
        assert_eq!(t("50ms"), Ok(0.05));
        assert_eq!(t(" 2 s"), Ok(2.0));
        for bad in ["0", "-1", "NaN", "inf", "1e9", "0.0001", "0ms"] {
            assert!(
                matches!(t(bad), Err(TimeBudgetError::Range(_))),
                "{bad}: {:?}",
                t(bad)
            );
        }
        for bad in ["", "abc", "5min", "1h"] {
            assert!(matches!(t(bad), Err(TimeBudgetError::Syntax(_))), "{bad}");
        }
        // Numbers as written, not in long form (1e300 printed 301 digits).
        assert_eq!(
            t("1e300").unwrap_err().to_string(),
            "1e300 s is not a time budget: it must be a finite number of seconds from 0.001 to \
             86400 (one day)"
        );
        assert!(t("1e-9").unwrap_err().to_string().starts_with("1e-9 s "));
        assert_eq!(TimeBudget::new(0.2).unwrap().to_string(), "0.2 s");
        assert_eq!(
            serde_json::to_string(&TimeBudget::new(0.6).unwrap()).unwrap(),
            "0.6"
        );
    }

    #[test]
    fn node_knob_is_monotone_and_close_to_the_budget() {
        let targets = [0.1, 0.2, 0.4, 0.8, 1.6];
        let mut probes = Vec::new();
        let mut calls = 0;
        let choices = search_knobs(
            &targets,
            KnobKind::Nodes,
            (1, 1 << 24),
            TOLERANCE,
            &mut probes,
            &mut |k| {
                calls += 1;
                model(k)
            },
        )
        .unwrap();
        for w in choices.windows(2) {
            assert!(w[0].knob < w[1].knob, "{choices:?}");
        }
        for (c, t) in choices.iter().zip(targets) {
            assert!(c.fits && c.median_s <= t * (1.0 + TOLERANCE), "{c:?} {t}");
            assert!(c.median_s >= t * 0.8, "{c:?} {t}: not close");
        }
        assert!(calls <= 5 * MAX_PROBES, "{calls} probes");
        // The same targets given in another order get the same knobs.
        let mut again = Vec::new();
        let rev: Vec<f64> = targets.iter().rev().copied().collect();
        let back = search_knobs(
            &rev,
            KnobKind::Nodes,
            (1, 1 << 24),
            TOLERANCE,
            &mut again,
            &mut model,
        )
        .unwrap();
        let mut back: Vec<u32> = back.iter().map(|c| c.knob).collect();
        back.reverse();
        assert_eq!(back, choices.iter().map(|c| c.knob).collect::<Vec<_>>());
    }

    #[test]
    fn a_budget_below_the_smallest_knob_is_flagged() {
        let mut probes = Vec::new();
        let c = search_knobs(
            &[0.01],
            KnobKind::Nodes,
            (1, 1 << 24),
            TOLERANCE,
            &mut probes,
            &mut model,
        )
        .unwrap();
        assert_eq!((c[0].knob, c[0].fits), (1, false));
    }

    #[test]
    fn horizon_knob_is_the_largest_that_fits() {
        // Exponential growth, like the uniform tree: 0.01 * 2^h.
        let mut measure = |h: u32| Ok::<_, ()>((vec![0.01 * 2f64.powi(h as i32); 3], u64::from(h)));
        let mut probes = Vec::new();
        let c = search_knobs(
            &[0.1, 1.0],
            KnobKind::Horizon,
            (1, MAX_HORIZON),
            TOLERANCE,
            &mut probes,
            &mut measure,
        )
        .unwrap();
        // 0.01 * 2^3 = 0.08 <= 0.105 < 0.16; 0.01 * 2^6 = 0.64 <= 1.05 < 1.28.
        assert_eq!((c[0].knob, c[1].knob), (3, 6));
        assert!(probes.iter().all(|p| p.knob <= 7), "{probes:?}");
    }

    #[test]
    fn a_knob_that_changes_no_pilot_run_stops_the_search() {
        // The pilots' runs stop changing from 40 nodes on (their trees are covered), and
        // time stops growing: no budget above the first such probe is chosen or sought.
        let mut measure = |k: u32| {
            let k = k.min(40);
            Ok::<_, ()>((vec![0.001 * f64::from(k); 3], u64::from(k)))
        };
        let mut probes = Vec::new();
        let c = search_knobs(
            &[1.0],
            KnobKind::Nodes,
            (1, 1 << 24),
            TOLERANCE,
            &mut probes,
            &mut measure,
        )
        .unwrap();
        assert!(c[0].fits && c[0].saturated, "{c:?}");
        assert!(c[0].knob >= 40 && c[0].knob < 1000, "{c:?} {probes:?}");
        assert!(probes.len() <= 4, "{probes:?}");
    }

    #[test]
    fn equal_results_at_two_knobs_with_another_above_are_no_saturation() {
        // Knobs 1 and 3 make the same pilot runs, 16 others (the budget binds): the knob
        // chosen for a budget that 8 fits is not held at 1.
        let mut measure = |k: u32| {
            let digest = if k <= 3 { 0 } else { u64::from(k) };
            Ok::<_, ()>((vec![0.1 + 0.01 * f64::from(k); 3], digest))
        };
        let mut probes = Vec::new();
        let c = search_knobs(
            &[0.05, 0.18],
            KnobKind::Nodes,
            (1, 1 << 24),
            TOLERANCE,
            &mut probes,
            &mut measure,
        )
        .unwrap();
        assert_eq!((c[0].knob, c[0].fits, c[0].saturated), (1, false, false));
        assert!(
            c[1].fits && !c[1].saturated && c[1].knob >= 6,
            "{c:?} {probes:?}"
        );
    }

    #[test]
    fn pilots_are_a_multiple_of_the_threads() {
        assert_eq!([1, 2, 3, 4, 16].map(pilots_for), [3, 4, 3, 4, 16]);
    }
}
