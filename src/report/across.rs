//! "Across meshes" (issue 24 item 3), for a results directory of two or more meshes: each
//! method's per-mesh median quality, a win/tie/loss table against a baseline (ties decided by
//! the per-mesh test, Holm-corrected over the meshes), Friedman's test over the meshes with
//! Nemenyi's critical difference and the signed-rank test of every pair over the meshes, and
//! the critical-difference diagram. Tests over meshes take one value per mesh, its median,
//! never the runs of different meshes as one sample. Also the medians as CSV
//! ([`csv`], `across_meshes.csv`).

use super::cd_diagram::cd_svg;
use super::format::fmt_p;
use super::significance::{ALPHA, Family};
use super::summarized::median_of;
use super::{Config, Document, FIGURES_DIR, Metric, ReportError, ReportOptions, Results, Run};
use crate::experiment::summary::Summary;
use crate::stats::ranks::{
    NEMENYI_MAX_METHODS, block_ranks, friedman, friedman_min_p, nemenyi_cd, pairwise_signed_rank,
};

pub use crate::experiment::engine::ACROSS_CSV;

/// The baseline when none is chosen, if the results hold it on every mesh.
pub const DEFAULT_BASELINE: &str = "selective h=1";

/// The optimum is left out: its quality is 100 % of itself on every mesh.
const OPTIMUM: &str = "optimum";

/// One method's median on one mesh.
#[derive(Debug, Clone, Copy)]
struct Cell {
    median: f64,
    runs: usize,
    /// The horizon the runs on this mesh had (a time budget's calibration chooses it per
    /// mesh).
    horizon: Option<u32>,
}

/// The per-mesh medians the section is made of.
#[derive(Debug)]
struct Medians<'r> {
    /// Meshes with a quality % of the optimum, in report order.
    meshes: Vec<&'r str>,
    /// Meshes left out (no optimum recorded, or one of 0: no % to compare across meshes).
    left_out: Vec<&'r str>,
    /// Methods in report order ([`Config::method`]: a configuration without its mesh or a
    /// time budget's calibrated knob), the optimum left out.
    methods: Vec<Config>,
    /// `cells[mesh][method]`, `None` where the method was not run on the mesh.
    cells: Vec<Vec<Option<Cell>>>,
}

impl<'r> Medians<'r> {
    /// `None` with fewer than two meshes.
    fn of(results: &'r Results, summary: &Summary) -> Option<Medians<'r>> {
        if results.meshes.len() < 2 {
            return None;
        }
        let mut methods: Vec<Config> = Vec::new();
        for c in results.groups.keys().filter(|c| c.algo != OPTIMUM) {
            let m = c.method();
            if !methods.contains(&m) {
                methods.push(m);
            }
        }
        methods.sort();
        let (mut meshes, mut left_out, mut cells) = (Vec::new(), Vec::new(), Vec::new());
        for mesh in &results.meshes {
            let row: Vec<Option<Cell>> = (methods.iter())
                .map(|m| {
                    let runs = results.get_on(mesh, m)?;
                    let c = Config::of(&runs[0]);
                    let median = median_of(summary, &c, |g| g.quality_pct.as_ref())?;
                    Some(Cell {
                        median,
                        runs: runs.len(),
                        horizon: c.horizon,
                    })
                })
                .collect();
            if row.iter().any(Option::is_some) {
                meshes.push(mesh.as_str());
                cells.push(row);
            } else {
                left_out.push(mesh.as_str());
            }
        }
        Some(Medians {
            meshes,
            left_out,
            methods,
            cells,
        })
    }

    /// Indices of the methods with a median on every mesh (those the tests over meshes take).
    fn complete(&self) -> Vec<usize> {
        (0..self.methods.len())
            .filter(|&j| self.cells.iter().all(|row| row[j].is_some()))
            .collect()
    }

    /// `values[mesh][i]` of the methods `cols`, which must be complete.
    fn blocks(&self, cols: &[usize]) -> Vec<Vec<f64>> {
        (self.cells.iter())
            .map(|row| {
                cols.iter()
                    .map(|&j| row[j].map_or(f64::NAN, |c| c.median))
                    .collect()
            })
            .collect()
    }

    fn label(&self, j: usize) -> String {
        self.methods[j].label()
    }
}

/// The labels of the methods `results` holds (the optimum left out), for checking `--baseline`.
fn method_labels(results: &Results) -> Vec<String> {
    let mut labels: Vec<String> = Vec::new();
    for c in results.groups.keys().filter(|c| c.algo != OPTIMUM) {
        let l = c.label();
        if !labels.contains(&l) {
            labels.push(l);
        }
    }
    labels
}

/// Refuses a `--baseline` that names no method of the results.
pub(super) fn check_baseline(results: &Results, opts: &ReportOptions) -> Result<(), ReportError> {
    let Some(b) = &opts.baseline else {
        return Ok(());
    };
    let labels = method_labels(results);
    if labels.contains(b) {
        Ok(())
    } else {
        Err(ReportError::NoSuchBaseline(b.clone(), labels.join(", ")))
    }
}

/// The per-mesh medians as CSV, one row per (mesh, method): `mesh, triangles, method, algo,
/// horizon, runs, median_quality_pct, rank` (rank within the mesh among the methods run on
/// every mesh, 1 the best, ties averaged; empty for the others). `None` with fewer than two
/// meshes.
pub(super) fn csv(results: &Results, summary: &Summary) -> Option<String> {
    let m = Medians::of(results, summary)?;
    let complete = m.complete();
    let mut out = String::from("mesh,triangles,method,algo,horizon,runs,median_quality_pct,rank\n");
    for (i, row) in m.cells.iter().enumerate() {
        let values: Vec<f64> = complete
            .iter()
            .map(|&j| row[j].map_or(0.0, |c| c.median))
            .collect();
        let (ranks, _) = block_ranks(&values);
        let triangles = (results.configs_of(m.meshes[i]).next()).map_or(0, |(_, r)| r[0].triangles);
        for (j, cell) in row.iter().enumerate() {
            let Some(cell) = cell else { continue };
            let rank = (complete.iter().position(|&c| c == j))
                .map_or(String::new(), |p| ranks[p].to_string());
            out.push_str(&format!(
                "{},{triangles},{},{},{},{},{},{rank}\n",
                csv_field(m.meshes[i]),
                csv_field(&m.label(j)),
                csv_field(&m.methods[j].algo),
                cell.horizon.map_or(String::new(), |h| h.to_string()),
                cell.runs,
                cell.median,
            ));
        }
    }
    Some(out)
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// "8" or "1–32": the numbers of runs of a method's cells.
fn runs_range(cells: impl Iterator<Item = usize>) -> String {
    let v: Vec<usize> = cells.collect();
    match (v.iter().min(), v.iter().max()) {
        (Some(a), Some(b)) if a == b => a.to_string(),
        (Some(a), Some(b)) => format!("{a}–{b}"),
        _ => "–".to_string(),
    }
}

/// One method's record against the baseline over the meshes both were run on.
#[derive(Debug)]
struct Record {
    method: usize,
    wins: Vec<String>,
    ties: Vec<String>,
    losses: Vec<String>,
    /// Per mesh not won: what was found ("tie: 93.10 vs 93.02, Holm p = 0.41").
    not_won: Vec<String>,
    /// Runs of the method and of the baseline on those meshes.
    runs: (usize, usize),
}

/// The outcome on one mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Verdict {
    Win,
    Tie,
    Loss,
}

/// Win/tie/loss of method `j` against `base` on each mesh both were run on: the per-mesh test
/// of the report (Mann–Whitney, or signed-rank when one side is a single run) Holm-corrected
/// over those meshes; between two single runs (deterministic) the exact difference decides.
fn record(results: &Results, m: &Medians<'_>, j: usize, base: usize, seed: u64) -> Record {
    let (method, baseline) = (&m.methods[j], &m.methods[base]);
    let mut sides: Vec<(String, &[Run], String, &[Run])> = Vec::new();
    // Meshes where the method ran once and the baseline more: tested the other way round
    // (the runs against the single value, as the per-mesh comparisons with greedy do).
    let mut swapped: Vec<&str> = Vec::new();
    for mesh in &m.meshes {
        let (Some(x), Some(y)) = (results.get_on(mesh, method), results.get_on(mesh, baseline))
        else {
            continue;
        };
        if x.len() == 1 && y.len() > 1 {
            swapped.push(mesh);
            sides.push((mesh.to_string(), y, baseline.label(), x));
        } else {
            sides.push((mesh.to_string(), x, baseline.label(), y));
        }
    }
    let runs = sides.iter().fold((0, 0), |(a, b), s| {
        let (x, y) = (s.1.len(), s.3.len());
        if swapped.contains(&s.0.as_str()) {
            (a + y, b + x)
        } else {
            (a + x, b + y)
        }
    });
    let family = Family::build(String::new(), Metric::Quality, sides, seed);
    let mut r = Record {
        method: j,
        wins: Vec::new(),
        ties: Vec::new(),
        losses: Vec::new(),
        not_won: Vec::new(),
        runs,
    };
    // (mesh index, mesh, verdict) of every mesh, then in report order.
    let mut verdicts: Vec<(usize, String, Verdict, String)> = Vec::new();
    let index = |mesh: &str| {
        m.meshes
            .iter()
            .position(|x| *x == mesh)
            .unwrap_or(usize::MAX)
    };
    for p in &family.pairs {
        let [mut a, mut b] = p.cmp.median;
        // Who wins is the test's direction, not the medians': they can be equal on a
        // significant difference.
        let (mut direction, mut av) = (p.cmp.direction(), p.cmp.a);
        if swapped.contains(&p.first.as_str()) {
            (a, b) = (b, a);
            (direction, av) = (direction.reverse(), 1.0 - av);
        }
        let v = match (p.significant(), direction) {
            (true, std::cmp::Ordering::Greater) => Verdict::Win,
            (true, std::cmp::Ordering::Less) => Verdict::Loss,
            _ => Verdict::Tie,
        };
        // Equal medians on a significant difference: the rest of the runs differ (A says
        // how often the first is ahead), which a reader would not guess from the medians.
        let equal = if format!("{a:.2}") == format!("{b:.2}") && v != Verdict::Tie {
            "; the medians are equal, the test and A compare all the runs"
        } else {
            ""
        };
        let what = format!(
            "{a:.2} vs {b:.2}, A = {av:.2}, Holm p = {}{equal}",
            fmt_p(p.cmp.p_holm)
        );
        verdicts.push((index(&p.first), p.first.clone(), v, what));
    }
    for u in &family.untested {
        let [a, b] = u.median;
        let v = match a.total_cmp(&b) {
            std::cmp::Ordering::Greater => Verdict::Win,
            std::cmp::Ordering::Less => Verdict::Loss,
            std::cmp::Ordering::Equal => Verdict::Tie,
        };
        verdicts.push((
            index(&u.first),
            u.first.clone(),
            v,
            format!("{a:.2} vs {b:.2}, single runs"),
        ));
    }
    verdicts.sort_by_key(|v| v.0);
    for (_, mesh, v, what) in verdicts {
        match v {
            Verdict::Win => r.wins.push(mesh),
            Verdict::Tie => {
                r.not_won.push(format!("{mesh} (tie: {what})"));
                r.ties.push(mesh);
            }
            Verdict::Loss => {
                r.not_won.push(format!("{mesh} (loss: {what})"));
                r.losses.push(mesh);
            }
        }
    }
    r
}

/// Appends the section when `results` holds two or more meshes.
pub(super) fn across_meshes(
    doc: &mut Document,
    results: &Results,
    summary: &Summary,
    opts: &ReportOptions,
) -> Result<(), ReportError> {
    let Some(m) = Medians::of(results, summary) else {
        return Ok(());
    };
    doc.heading(2, "Across meshes");
    if !m.left_out.is_empty() {
        doc.para(format!(
            "Left out: {} (no optimum recorded, or an optimum of 0 (no quad possible), so no \
             quality as % of the optimum to compare across meshes).",
            m.left_out.join(", ")
        ));
    }
    if m.meshes.len() < 2 {
        doc.para(format!(
            "{} mesh(es) with a quality % of the optimum: at least 2 are needed to compare \
             methods across meshes.",
            m.meshes.len()
        ));
        return Ok(());
    }
    let n = m.meshes.len();
    let complete = m.complete();
    let total_runs: usize = m.cells.iter().flatten().flatten().map(|c| c.runs).sum();
    doc.para(format!(
        "{n} meshes ({}), {} methods, {total_runs} runs. Each method is summarized on each mesh \
         by its median quality (% of the optimum); the tests over meshes take these medians, \
         one value per mesh and method, never the runs of different meshes as one sample. The \
         optimum is left out (100 % on every mesh).",
        m.meshes.join(", "),
        m.methods.len()
    ));

    // Per-mesh medians, with the average rank of the methods run on every mesh.
    doc.heading(3, "Median quality per mesh (% of optimum)");
    let mut header = vec!["mesh".to_string(), "triangles".to_string()];
    header.extend((0..m.methods.len()).map(|j| m.label(j)));
    let mut rows: Vec<Vec<String>> = Vec::new();
    for (i, row) in m.cells.iter().enumerate() {
        let triangles = (results.configs_of(m.meshes[i]).next()).map_or(0, |(_, r)| r[0].triangles);
        let mut cells = vec![m.meshes[i].to_string(), triangles.to_string()];
        cells.extend(
            row.iter()
                .map(|c| c.map_or("–".into(), |c| format!("{:.2}", c.median))),
        );
        rows.push(cells);
    }
    let mut runs_row = vec!["runs per mesh".to_string(), String::new()];
    runs_row.extend(
        (0..m.methods.len())
            .map(|j| runs_range(m.cells.iter().filter_map(|row| row[j]).map(|c| c.runs))),
    );
    rows.push(runs_row);
    let fr = friedman(&m.blocks(&complete));
    if let Some(f) = &fr {
        let mut rank_row = vec!["average rank".to_string(), String::new()];
        rank_row.extend((0..m.methods.len()).map(|j| {
            (complete.iter().position(|&c| c == j))
                .map_or("–".to_string(), |p| format!("{:.2}", f.average_ranks[p]))
        }));
        rows.push(rank_row);
    }
    doc.table(header, rows);
    let partial: Vec<String> = (0..m.methods.len())
        .filter(|j| !complete.contains(j))
        .map(|j| m.label(j))
        .collect();
    if !partial.is_empty() {
        doc.para(format!(
            "Not run on every mesh, so left out of the ranks and of the tests over meshes (but \
             in the win/tie/loss table, on the meshes they were run on): {}.",
            partial.join(", ")
        ));
    }

    // Against the baseline.
    let base = match &opts.baseline {
        Some(b) => (0..m.methods.len()).find(|&j| &m.label(j) == b),
        None => (0..m.methods.len())
            .find(|&j| m.label(j) == DEFAULT_BASELINE && complete.contains(&j))
            .or(complete.first().copied())
            .or((!m.methods.is_empty()).then_some(0)),
    };
    let records: Vec<Record> = match base {
        Some(base) => (0..m.methods.len())
            .filter(|&j| j != base)
            .map(|j| {
                record(
                    results,
                    &m,
                    j,
                    base,
                    opts.seed.wrapping_add(9_000_000 + 1000 * j as u64),
                )
            })
            .collect(),
        None => Vec::new(),
    };
    if let Some(base) = base {
        doc.heading(3, format!("Against {}", m.label(base)));
        doc.para(format!(
            "Baseline: {}{}. On each mesh, a method's runs are tested against the baseline's \
             (Mann–Whitney U; the signed-rank test when one side is a single run), and the \
             p-values of one method's meshes are Holm-corrected together: a win is a \
             difference significant at {ALPHA} in the method's favour (in the test's direction: \
             Vargha–Delaney A above 0.5 for Mann–Whitney, T+ above its expectation for the \
             signed-rank test; the medians may be equal), a loss one against it, a tie no significant difference. Between two single runs (deterministic methods) \
             the exact difference decides.",
            m.label(base),
            if opts.baseline.is_some() {
                " (chosen with --baseline)"
            } else if m.label(base) == DEFAULT_BASELINE {
                " (the default)"
            } else {
                " (the first method run on every mesh; choose another with --baseline)"
            }
        ));
        let rows = records
            .iter()
            .map(|r| {
                let meshes = r.wins.len() + r.ties.len() + r.losses.len();
                vec![
                    m.label(r.method),
                    r.wins.len().to_string(),
                    r.ties.len().to_string(),
                    r.losses.len().to_string(),
                    meshes.to_string(),
                    format!("{} / {}", r.runs.0, r.runs.1),
                    if r.not_won.is_empty() {
                        "–".to_string()
                    } else {
                        r.not_won.join("; ")
                    },
                ]
            })
            .collect();
        doc.table(
            [
                "method",
                "wins",
                "ties",
                "losses",
                "meshes",
                "runs (method / baseline)",
                "meshes not won",
            ]
            .map(String::from)
            .to_vec(),
            rows,
        );
    }

    // Friedman, post-hoc, diagram.
    doc.heading(3, "Ranks over meshes");
    let k = complete.len();
    let Some(f) = fr else {
        doc.para(format!(
            "{k} method(s) run on every mesh: Friedman's test needs at least 2."
        ));
        return Ok(());
    };
    let runs_in_tests: usize = (m.cells.iter())
        .map(|row| {
            complete
                .iter()
                .filter_map(|&j| row[j])
                .map(|c| c.runs)
                .sum::<usize>()
        })
        .sum();
    let min_p = friedman_min_p(k, n);
    let rests = format!(
        "{k} methods over {n} meshes (their per-mesh medians, of {runs_in_tests} runs in all)"
    );
    if min_p > ALPHA {
        doc.para(format!(
            "Friedman's test of {rests}: too few meshes for the test. Even if every mesh ranked \
             the methods the same way, the exact p would be {} (1/(k!)^(n-1)), above {ALPHA}; \
             the chi-square statistic is {:.3} (average ranks in the table above). Add meshes \
             for a test.",
            fmt_p(min_p),
            f.chi2
        ));
    } else {
        doc.para(format!(
            "Friedman's test of {rests}: chi-square = {:.3} with {} degrees of freedom, p = {}; \
             Iman–Davenport F({}, {}) = {}, p = {}. {} {}",
            f.chi2,
            k - 1,
            fmt_p(f.p),
            f.f_df.0,
            f.f_df.1,
            if f.f.is_finite() {
                format!("{:.3}", f.f)
            } else {
                "infinite (every mesh ranks the methods the same way)".to_string()
            },
            fmt_p(f.p_f),
            if f.p_f < ALPHA {
                format!("The methods' ranks differ significantly at {ALPHA}.")
            } else {
                format!("No significant difference between the methods' ranks at {ALPHA}.")
            },
            if n < 10 {
                "(Both p-values are large-sample approximations, rough with fewer than about 10 \
                 meshes.)"
            } else {
                ""
            }
        ));
    }
    let cd = nemenyi_cd(k, n);
    match cd {
        Some(cd) => doc.para(format!(
            "Nemenyi's post-hoc test: critical difference CD = {cd:.3} (q = {:.3} for {k} \
             methods, alpha = 0.05, {n} meshes). Two methods whose average ranks differ by at \
             least CD differ significantly; the diagram joins those that do not.",
            cd / ((k * (k + 1)) as f64 / (6.0 * n as f64)).sqrt()
        )),
        None => doc.para(format!(
            "Nemenyi's critical difference is tabulated up to {NEMENYI_MAX_METHODS} methods; \
             {k} is more, so the diagram joins no methods (see the pairwise tests)."
        )),
    }
    // Every pair: signed-rank over the meshes, Holm.
    let pairs = pairwise_signed_rank(&m.blocks(&complete));
    let too_few = pairs.iter().any(|p| p.p_min > ALPHA);
    let rows = pairs
        .iter()
        .map(|p| {
            let (a, b) = (complete[p.first], complete[p.second]);
            let d: Vec<f64> = m.blocks(&[a, b]).iter().map(|v| v[0] - v[1]).collect();
            let higher = d.iter().filter(|v| **v > 0.0).count();
            let lower = d.iter().filter(|v| **v < 0.0).count();
            let (p_cell, holm_cell, verdict) = if p.p_min > ALPHA {
                let why = format!("too few meshes ({} that differ)", p.test.n);
                (why.clone(), "–".to_string(), "cannot be".to_string())
            } else {
                (
                    fmt_p(p.test.p),
                    fmt_p(p.p_holm),
                    if p.p_holm < ALPHA { "yes" } else { "no" }.to_string(),
                )
            };
            vec![
                format!("{} vs {}", m.label(a), m.label(b)),
                format!("{higher} / {lower} / {}", n - higher - lower),
                format!("T+ = {}", p.test.t_plus),
                p_cell,
                holm_cell,
                verdict,
            ]
        })
        .collect();
    doc.para(format!(
        "Every pair over the meshes: the Wilcoxon signed-rank test of the per-mesh medians' \
         differences (meshes where they are equal dropped), Holm-corrected over the {} pairs.{}",
        pairs.len(),
        if too_few {
            " With n meshes that differ the test cannot give p below 2/2^n, so with 5 or fewer \
             it cannot find a difference at 0.05 however large: those pairs say so instead of \
             giving a p-value."
        } else {
            ""
        }
    ));
    doc.table(
        [
            "pair",
            "meshes higher / lower / equal",
            "statistic",
            "p",
            "Holm p",
            "significant",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    );
    let ranked: Vec<(String, f64)> = (complete.iter().zip(&f.average_ranks))
        .map(|(&j, &r)| (m.label(j), r))
        .collect();
    doc.figure(
        format!("{FIGURES_DIR}/across-meshes-cd.svg"),
        cd_svg(
            &format!("Average rank over {n} meshes (1 = best quality)"),
            &ranked,
            cd,
        ),
        format!(
            "Critical-difference diagram: average rank of each of the {k} methods run on every \
             mesh over the {n} meshes (1 = highest median quality), {}",
            match cd {
                Some(cd) => format!(
                    "Nemenyi's critical difference at 0.05 (CD = {cd:.3}) in red; methods joined \
                     by a black bar do not differ significantly."
                ),
                None => "no critical difference (too many methods for its table).".to_string(),
            }
        ),
    );

    // The question: does the best method beat the baseline on every mesh? And, when it is
    // another, the deepest horizon of the baseline's algorithm (selective h=5 against h=1).
    if let Some(base) = base {
        let ranked = || (complete.iter().zip(&f.average_ranks)).filter(|(j, _)| **j != base);
        let best = ranked().min_by(|a, b| a.1.total_cmp(b.1));
        let deepest = (ranked())
            .filter(|(j, _)| m.methods[**j].algo == m.methods[base].algo)
            .filter(|(j, _)| m.methods[**j].horizon > m.methods[base].horizon)
            .max_by_key(|(j, _)| m.methods[**j].horizon);
        let mut asked = Vec::new();
        if let Some((&j, &rank)) = best {
            asked.push((
                j,
                format!("the best average rank of the methods other than the baseline, {rank:.2}"),
            ));
        }
        if let Some((&j, &rank)) = deepest.filter(|d| Some(d.0) != best.map(|b| b.0)) {
            asked.push((j, format!("the deepest horizon, average rank {rank:.2}")));
        }
        for (j, why) in asked {
            if let Some(r) = records.iter().find(|r| r.method == j) {
                doc.para(answer(&m, r, j, base, &why, &pairs, &complete, n));
            }
        }
    }
    Ok(())
}

/// "Does X (why it is asked) beat the baseline on every mesh?", answered from the
/// win/tie/loss record and the signed-rank test of the two over the meshes.
#[allow(clippy::too_many_arguments)]
fn answer(
    m: &Medians<'_>,
    r: &Record,
    best: usize,
    base: usize,
    why: &str,
    pairs: &[crate::stats::ranks::PairTest],
    complete: &[usize],
    n: usize,
) -> String {
    let meshes = r.wins.len() + r.ties.len() + r.losses.len();
    let (b, bl) = (m.label(best), m.label(base));
    let head = format!("Does {b} ({why}) beat {bl} on every mesh?");
    let verdict = if r.wins.len() == meshes && meshes == n {
        format!(
            " Yes: its quality is significantly higher on all {n} meshes ({} runs of {b}, \
             {} of {bl}).",
            r.runs.0, r.runs.1
        )
    } else {
        format!(
            " No: it is significantly higher on {} of the {meshes} meshes both were run on ({} \
             runs of {b}, {} of {bl}); not on {}.",
            r.wins.len(),
            r.runs.0,
            r.runs.1,
            r.not_won.join("; ")
        )
    };
    let pos = |j: usize| complete.iter().position(|&c| c == j);
    let over = match (pos(best), pos(base)) {
        (Some(a), Some(c)) => pairs
            .iter()
            .find(|p| (p.first, p.second) == (a.min(c), a.max(c)))
            .map(|p| {
                if p.p_min > ALPHA {
                    format!(
                        " Over the meshes, the signed-rank test of their per-mesh medians cannot \
                         decide: {} differ, too few to reach p < {ALPHA}.",
                        if p.test.n == 1 {
                            "1 mesh's medians".to_string()
                        } else {
                            format!("{} meshes' medians", p.test.n)
                        }
                    )
                } else {
                    format!(
                        " Over the {n} meshes, the signed-rank test of their per-mesh medians \
                         gives p = {} (Holm p = {} over all pairs): {}.",
                        fmt_p(p.test.p),
                        fmt_p(p.p_holm),
                        if p.p_holm < ALPHA {
                            "a significant difference"
                        } else {
                            "no significant difference"
                        }
                    )
                }
            })
            .unwrap_or_default(),
        _ => String::new(),
    };
    format!("{head}{verdict}{over}")
}
