//! The comparison harness: random apply/undo walks, as a tree search makes them, with every
//! answer of the state under test checked against the naive oracle after every step.

use super::naive::{Naive, Verdicts};
use quadrecomb::internals::mesh::Mesh;
use quadrecomb::internals::quality::CandidateTable;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write as _;

/// The state API under test (the contract of `search::state::State`).
pub trait Subject {
    fn apply(&mut self, c: u32);
    fn undo(&mut self);
    fn is_allowed(&mut self, c: u32) -> bool;
    fn allowed_count(&mut self, t: u32) -> u32;
    fn is_remaining(&mut self, t: u32) -> bool;
    fn allowed_actions(&mut self) -> Vec<u32>;
    /// `P_1`, `P_2`, `P_3` as the state keeps them, in its own order, if it keeps them.
    fn buckets(&mut self) -> Option<[Vec<u32>; 3]> {
        None
    }
    /// The smallest k with `P_k` non-empty, if the state says.
    fn min_k(&mut self) -> Option<Option<u32>> {
        None
    }
}

/// Shape of the walks.
#[derive(Debug, Clone, Copy)]
pub struct WalkConfig {
    /// Explorations (apply/undo walks that end back where they started) per decision, at most.
    pub explorations: u32,
    /// Deepest an exploration goes.
    pub max_depth: usize,
    /// Undo every kept action at the end (false for a forward-mode state, which cannot).
    pub unwind: bool,
}

impl Default for WalkConfig {
    fn default() -> Self {
        WalkConfig {
            explorations: 2,
            max_depth: 10,
            unwind: true,
        }
    }
}

/// What a walk did, to check that it did something.
#[derive(Debug, Default, Clone, Copy)]
pub struct WalkStats {
    pub checks: u64,
    pub applies: u64,
    pub undos: u64,
    /// Actions applied along the trunk until no allowed action was left.
    pub trunk: usize,
    /// Triangles left when no allowed action remained.
    pub left: usize,
}

/// Compares everything `subject` says with the oracle's verdicts; on a difference, a report
/// naming the context, the path from the start and the first differences.
pub fn compare<S: Subject>(
    subject: &mut S,
    oracle: &Naive,
    context: &str,
) -> Result<Verdicts, String> {
    let v = oracle.verdicts();
    let mut diffs = Vec::new();
    for t in 0..v.remaining.len() as u32 {
        let got = subject.is_remaining(t);
        if got != v.remaining[t as usize] {
            diffs.push(format!(
                "is_remaining({t}): expected {}, got {got}",
                v.remaining[t as usize]
            ));
        }
        let got = subject.allowed_count(t);
        if got != v.count[t as usize] {
            diffs.push(format!(
                "allowed_count({t}): expected {}, got {got}",
                v.count[t as usize]
            ));
        }
    }
    for c in 0..v.allowed.len() as u32 {
        let got = subject.is_allowed(c);
        let expected = v.allowed[c as usize];
        if got != expected {
            let [a, b] = oracle.pair(c);
            let why = match oracle.parts(c) {
                None => "not an action: a triangle is used".to_string(),
                Some((size, parts)) => format!("polder of {size} triangles, parts {parts:?}"),
            };
            diffs.push(format!(
                "is_allowed({c}) (triangles [{a}, {b}]): expected {expected}, got {got} ({why})"
            ));
        }
    }
    let mut got = subject.allowed_actions();
    let len = got.len();
    got.sort_unstable();
    got.dedup();
    if got.len() != len {
        diffs.push(format!(
            "allowed_actions() repeats candidates ({len} entries, {} distinct)",
            got.len()
        ));
    }
    let expected = v.allowed_actions();
    if got != expected {
        let missing: Vec<u32> = expected
            .iter()
            .copied()
            .filter(|c| got.binary_search(c).is_err())
            .collect();
        let extra: Vec<u32> = got
            .iter()
            .copied()
            .filter(|c| expected.binary_search(c).is_err())
            .collect();
        diffs.push(format!(
            "allowed_actions(): {} expected, {} got; missing {missing:?}, extra {extra:?}",
            expected.len(),
            got.len()
        ));
    }
    if let Some(buckets) = subject.buckets() {
        for (i, bucket) in buckets.iter().enumerate() {
            let k = i as u32 + 1;
            let mut got = bucket.clone();
            got.sort_unstable();
            got.dedup();
            if got.len() != bucket.len() {
                diffs.push(format!("bucket({k}) repeats triangles: {bucket:?}"));
            }
            let expected: Vec<u32> = (0..v.count.len() as u32)
                .filter(|&t| v.remaining[t as usize] && v.count[t as usize] == k)
                .collect();
            if got != expected {
                diffs.push(format!(
                    "bucket({k}) (P_{k}): expected {expected:?}, got {got:?}"
                ));
            }
        }
    }
    if let Some(got) = subject.min_k() {
        let expected =
            (1..=3).find(|&k| v.count.iter().zip(&v.remaining).any(|(&n, &r)| r && n == k));
        if got != expected {
            diffs.push(format!("min_k(): expected {expected:?}, got {got:?}"));
        }
    }
    if diffs.is_empty() {
        return Ok(v);
    }
    let mut report = format!(
        "state differs from the naive oracle: {context}\n  path (candidates applied from the start, with their triangles): {:?}\n",
        oracle
            .path()
            .iter()
            .map(|&c| (c, oracle.pair(c)))
            .collect::<Vec<_>>()
    );
    for d in diffs.iter().take(12) {
        let _ = writeln!(report, "  {d}");
    }
    if diffs.len() > 12 {
        let _ = writeln!(report, "  ... and {} more differences", diffs.len() - 12);
    }
    Err(report)
}

/// A random walk on `subject` and the oracle in lockstep: at each decision, a few explorations
/// (random applies of allowed actions and undos, down to `max_depth`, then undo back), then one
/// random allowed action kept; until no action is allowed; then every kept action undone
/// (when `config.unwind`).
/// Everything is compared after every apply and every undo.
pub fn walk<S: Subject>(
    name: &str,
    mesh: &Mesh,
    table: &CandidateTable,
    subject: &mut S,
    seed: u64,
    config: WalkConfig,
) -> Result<WalkStats, String> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut oracle = Naive::new(mesh, table);
    let mut stats = WalkStats::default();
    let ctx = |step: usize, what: &str| {
        format!("mesh {name}, walk seed {seed:#x}, decision {step}, {what}")
    };
    let initial = compare(subject, &oracle, &ctx(0, "initial state"))?;
    stats.checks += 1;
    let mut allowed = initial.allowed_actions();
    let mut step = 0;
    // P_k buckets before each applied action, to check that undo restores their order.
    let mut saved = Vec::new();
    while !allowed.is_empty() {
        for e in 0..rng.random_range(0..=config.explorations) {
            let max_depth = rng.random_range(1..=config.max_depth);
            let mut depth = 0;
            let mut here = allowed.clone();
            for op in 0..2 * max_depth {
                let go_down =
                    depth < max_depth && !here.is_empty() && (depth == 0 || rng.random_bool(0.7));
                let what;
                if go_down {
                    let c = here[rng.random_range(0..here.len())];
                    apply(subject, &mut oracle, &mut saved, c);
                    depth += 1;
                    stats.applies += 1;
                    what = format!("exploration {e}, op {op}: after apply({c})");
                } else if depth > 0 {
                    let c = undo(
                        subject,
                        &mut oracle,
                        &mut saved,
                        &ctx(step, &format!("exploration {e}, op {op}")),
                    )?;
                    depth -= 1;
                    stats.undos += 1;
                    what = format!("exploration {e}, op {op}: after undo() of {c}");
                } else {
                    break;
                }
                here = compare(subject, &oracle, &ctx(step, &what))?.allowed_actions();
                stats.checks += 1;
            }
            while depth > 0 {
                let c = undo(
                    subject,
                    &mut oracle,
                    &mut saved,
                    &ctx(step, &format!("exploration {e}, unwinding")),
                )?;
                depth -= 1;
                stats.undos += 1;
                compare(
                    subject,
                    &oracle,
                    &ctx(
                        step,
                        &format!("exploration {e}, unwinding: after undo() of {c}"),
                    ),
                )?;
                stats.checks += 1;
            }
        }
        let c = allowed[rng.random_range(0..allowed.len())];
        apply(subject, &mut oracle, &mut saved, c);
        stats.applies += 1;
        step += 1;
        allowed = compare(
            subject,
            &oracle,
            &ctx(step, &format!("after decision apply({c})")),
        )?
        .allowed_actions();
        stats.checks += 1;
    }
    stats.trunk = step;
    stats.left = (0..mesh.num_triangles() as u32)
        .filter(|&t| oracle.is_remaining(t))
        .count();
    while config.unwind && !oracle.path().is_empty() {
        let c = undo(
            subject,
            &mut oracle,
            &mut saved,
            &ctx(step, "undoing the whole walk"),
        )?;
        stats.undos += 1;
        let v = compare(
            subject,
            &oracle,
            &ctx(
                step,
                &format!("undoing the whole walk: after undo() of {c}"),
            ),
        )?;
        stats.checks += 1;
        if oracle.path().is_empty() && v != initial {
            return Err(format!(
                "mesh {name}, walk seed {seed:#x}: oracle not back to its initial verdicts"
            ));
        }
    }
    Ok(stats)
}

/// Applies `c` to both, remembering the state's P_k buckets from before.
fn apply<S: Subject>(
    subject: &mut S,
    oracle: &mut Naive,
    saved: &mut Vec<Option<[Vec<u32>; 3]>>,
    c: u32,
) {
    saved.push(subject.buckets());
    subject.apply(c);
    oracle.apply(c);
}

/// Undoes the last action on both; the state's P_k buckets must be back in the order they had
/// before that action (so that runs are reproducible whatever the tree explored).
fn undo<S: Subject>(
    subject: &mut S,
    oracle: &mut Naive,
    saved: &mut Vec<Option<[Vec<u32>; 3]>>,
    context: &str,
) -> Result<u32, String> {
    let c = *oracle.path().last().expect("something to undo");
    subject.undo();
    oracle.undo();
    let before = saved.pop().expect("saved buckets");
    let now = subject.buckets();
    if now != before {
        return Err(format!(
            "P_k buckets not restored in order by undo() of {c}: {context}\n  path: {:?}\n  before apply: {before:?}\n  after undo:   {now:?}",
            oracle.path()
        ));
    }
    Ok(c)
}
