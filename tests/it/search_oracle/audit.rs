//! The budgeted policies (optimistic, mcts, beam) against the naive oracle after every push
//! and pop of their look-ahead trees (issue 22): an audit hook on the state
//! (`Searcher::set_tree_audit`) replays, at every node the policy reaches, the base actions
//! plus the tree's path on the naive oracle and compares every candidate's `tree_allowed`
//! and every triangle's remaining flag and `tree_count` with it. The audited runs must make
//! the same decisions as the runs without the hook.

use super::naive::Naive;
use super::sample_meshes;
use crate::util::SEED;
use quadrecomb::internals::mesh::Mesh;
use quadrecomb::internals::quality::CandidateTable;
use quadrecomb::internals::search::state::{TreeEvent, TreeView};
use quadrecomb::internals::search::{Algo, Params, Searcher};
use std::cell::RefCell;

const BUDGETED: [&str; 3] = ["optimistic", "mcts", "beam"];

/// What the hook keeps between calls (per test thread).
struct Audit {
    naive: Naive,
    /// The run being audited, for messages.
    label: String,
    pushes: u64,
    pops: u64,
    /// Verdicts compared (candidates and triangles).
    checks: u64,
    /// The first disagreement with the oracle.
    error: Option<String>,
    /// Fault injection (to show the audit can fail): flip the tree's verdict of the first
    /// live candidate at the first push.
    flip: bool,
}

thread_local! {
    static AUDIT: RefCell<Option<Audit>> = const { RefCell::new(None) };
}

/// The hook: brings the oracle to base + path, then compares every verdict.
fn audit(view: &mut TreeView<'_, '_>, event: TreeEvent) {
    AUDIT.with(|cell| {
        let mut cell = cell.borrow_mut();
        let a = cell.as_mut().expect("the audit is set up before the run");
        match event {
            TreeEvent::Push(_) => a.pushes += 1,
            TreeEvent::Pop(_) => a.pops += 1,
        }
        if a.error.is_some() {
            return;
        }
        if let Err(e) = check(view, event, a) {
            a.error = Some(format!(
                "{}: after {event:?}, path {:?}: {e}",
                a.label,
                view.path()
            ));
        }
    });
}

fn check(view: &mut TreeView<'_, '_>, event: TreeEvent, a: &mut Audit) -> Result<(), String> {
    let want: Vec<u32> = view.base().iter().chain(view.path()).copied().collect();
    match event {
        TreeEvent::Push(c) if view.path().last() != Some(&c) => {
            return Err("the path does not end with the action pushed".into());
        }
        TreeEvent::Pop(c) if view.is_remaining(view.table().pairs[c as usize][0]) => {}
        TreeEvent::Pop(c) => return Err(format!("candidate {c} popped, its triangle still used")),
        _ => {}
    }
    let naive = &mut a.naive;
    let common = naive
        .path()
        .iter()
        .zip(&want)
        .take_while(|(x, y)| x == y)
        .count();
    while naive.path().len() > common {
        naive.undo();
    }
    for &c in &want[common..] {
        naive.apply(c);
    }
    let v = naive.verdicts();
    for (t, &r) in v.remaining.iter().enumerate() {
        let t = t as u32;
        if view.is_remaining(t) != r {
            return Err(format!("triangle {t} remaining: expected {r}"));
        }
        let got = view.tree_count(t);
        if got != v.count[t as usize] {
            return Err(format!(
                "tree_count({t}): expected {}, got {got}",
                v.count[t as usize]
            ));
        }
    }
    let mut flip = a.flip && matches!(event, TreeEvent::Push(_));
    for (c, &expected) in v.allowed.iter().enumerate() {
        let c = c as u32;
        let mut got = view.tree_allowed(c);
        let [x, y] = view.table().pairs[c as usize];
        if flip && view.is_remaining(x) && view.is_remaining(y) {
            (got, flip) = (!got, false);
        }
        if got != expected {
            return Err(format!("tree_allowed({c}): expected {expected}, got {got}"));
        }
    }
    a.checks += (v.remaining.len() + v.allowed.len()) as u64;
    Ok(())
}

fn algo(name: &str, h: u32, b: u32) -> Algo {
    Algo::new(
        name,
        Params {
            horizon: Some(h),
            budget: Some(b),
        },
    )
    .expect("a registered method")
}

/// Runs `algo` with the audit and without it; returns the audit (its error, if any) and
/// whether both runs chose the same actions.
fn audited_run(
    mesh: &Mesh,
    table: &CandidateTable,
    algo: Algo,
    seed: u64,
    label: String,
    flip: bool,
) -> (Audit, bool) {
    AUDIT.with(|cell| {
        *cell.borrow_mut() = Some(Audit {
            naive: Naive::new(mesh, table),
            label,
            pushes: 0,
            pops: 0,
            checks: 0,
            error: None,
            flip,
        })
    });
    let mut s = Searcher::new(mesh, table);
    s.set_tree_audit(Some(audit));
    let got = s.run(algo, seed);
    let audit = AUDIT
        .with(|cell| cell.borrow_mut().take())
        .expect("set above");
    let plain = Searcher::new(mesh, table).run(algo, seed);
    (audit, got.chosen == plain.chosen)
}

#[test]
fn budgeted_trees_match_the_naive_oracle_after_every_push_and_pop() {
    let (mut pushes, mut checks) = (0u64, 0u64);
    for (name, mesh) in sample_meshes(SEED ^ 0xA0D).into_iter().take(5) {
        let table = CandidateTable::build(&mesh);
        for p in BUDGETED {
            for h in 2..=4u32 {
                // A small budget, and one that covers the selective tree to depth h.
                for b in [3u32, 1 << 20] {
                    for seed in 0..2u64 {
                        let label = format!("{name}: {p} h={h} b={b} seed {seed}");
                        let (a, same) =
                            audited_run(&mesh, &table, algo(p, h, b), seed, label.clone(), false);
                        if let Some(e) = a.error {
                            panic!("{e}");
                        }
                        assert!(same, "{label}: the audit changed the run");
                        assert_eq!(a.pushes, a.pops, "{label}: every push popped");
                        pushes += a.pushes;
                        checks += a.checks;
                    }
                }
            }
        }
    }
    // 11,743 pushes and 10.0 million verdicts when written.
    assert!(pushes > 5_000, "{pushes} pushes audited");
    assert!(checks > 2_000_000, "{checks} verdicts compared");
}

#[test]
fn the_audit_catches_a_wrong_verdict() {
    // A jittered grid: every policy builds trees there (a strip may leave no choice).
    let (name, mesh) = sample_meshes(SEED).swap_remove(3);
    let table = CandidateTable::build(&mesh);
    for p in BUDGETED {
        let label = format!("{name}: {p} with one verdict flipped");
        let (a, _) = audited_run(&mesh, &table, algo(p, 3, 1 << 20), 0, label.clone(), true);
        assert!(a.pushes > 0, "{label}: no tree built");
        let e = a.error.unwrap_or_else(|| panic!("{label}: not caught"));
        assert!(e.contains("tree_allowed("), "{label}: {e}");
    }
}
