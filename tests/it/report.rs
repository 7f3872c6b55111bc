//! Reports: the statistics against published and scipy values, the report written from
//! synthetic results (every configuration named, every SVG parsing and rendering with the
//! expected boxes), mesh pictures, and the `report` subcommand.

use crate::util::{SEED, run_in, run_ok};
use quadrecomb::internals::experiment::record::RunRecord;
use quadrecomb::internals::mesh::{Mesh, MeshData};
use quadrecomb::internals::quality::{CandidateTable, recombined};
use quadrecomb::internals::report::picture::{PictureOptions, mesh_svg};
use quadrecomb::internals::report::{self, ReportOptions};
use quadrecomb::internals::stats::compare::{
    Magnitude, PMethod, Test, bootstrap_median_diff_ci, compare, holm, mann_whitney, signed_rank,
    vargha_delaney,
};
use quadrecomb::internals::stats::describe::effective_branching_factor;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-300)
}

// ---------------------------------------------------------------------------------------------
// Statistics against known values.

#[test]
fn mann_whitney_exact_textbook_example() {
    // U = 17 of x: x > y in 17 of the 20 pairs, counted by hand. Exact two-sided p = 2 P(U <= 3)
    // for n1 = 5, n2 = 4: (1+1+2+3)/126 * 2 = 14/126 = 0.1111...; scipy 1.17.1
    // `mannwhitneyu(x, y, method='exact')` gives (17.0, 0.1111111111111111).
    let x = [19.0, 22.0, 16.0, 29.0, 24.0];
    let y = [20.0, 11.0, 17.0, 12.0];
    let r = mann_whitney(&x, &y);
    assert_eq!(r.u, 17.0);
    assert_eq!(r.method, PMethod::Exact);
    assert!(close(r.p, 14.0 / 126.0, 1e-12), "{}", r.p);
    // The other way round: U = 3, same p.
    let r2 = mann_whitney(&y, &x);
    assert_eq!(r2.u, 3.0);
    assert!(close(r2.p, r.p, 1e-12));
}

#[test]
fn mann_whitney_exact_extreme_separation() {
    // All of x below all of y: U = 0, p = 2 / C(14, 3) = 2/364 (scipy 1.17.1: 0.005494505494505495).
    let x = [1.0, 2.0, 3.0];
    let y: Vec<f64> = (4..=14).map(f64::from).collect();
    let r = mann_whitney(&x, &y);
    assert_eq!(r.u, 0.0);
    assert_eq!(r.method, PMethod::Exact);
    assert!(close(r.p, 0.005_494_505_494_505_495, 1e-12), "{}", r.p);
}

#[test]
fn mann_whitney_normal_with_ties_matches_scipy() {
    // scipy 1.17.1, mannwhitneyu(x, y) (asymptotic, use_continuity=True, tie-corrected).
    let cases: [(&[f64], &[f64], f64, f64); 3] = [
        (
            &[3.0, 4.0, 2.0, 6.0, 2.0, 5.0],
            &[9.0, 7.0, 5.0, 10.0, 6.0, 8.0],
            2.0,
            0.012_591_911_490_379_705,
        ),
        (
            &[
                7.0, 7.0, 8.0, 9.0, 9.0, 9.0, 10.0, 12.0, 12.0, 13.0, 14.0, 15.0, 15.0, 15.0, 16.0,
                18.0, 20.0, 21.0, 21.0, 25.0,
            ],
            &[
                5.0, 6.0, 6.0, 7.0, 8.0, 8.0, 9.0, 10.0, 10.0, 11.0, 11.0, 11.0, 12.0, 13.0, 13.0,
                14.0, 14.0, 16.0, 17.0, 17.0,
            ],
            263.0,
            0.090_210_168_023_562_66,
        ),
        (
            // Widely separated: x = 0..39, y = x + 25.5 (no ties); p far in the tail.
            &(0..40).map(f64::from).collect::<Vec<_>>(),
            &(0..40).map(|v| f64::from(v) + 25.5).collect::<Vec<_>>(),
            105.0,
            2.343_724_213_621_403_5e-11,
        ),
    ];
    for (x, y, u, p) in cases {
        let r = mann_whitney(x, y);
        assert_eq!(r.method, PMethod::Normal);
        assert_eq!(r.u, u);
        assert!(close(r.p, p, 1e-6), "p = {} expected {p}", r.p);
    }
}

#[test]
#[allow(clippy::approx_constant)] // 3.14 is data, not pi.
fn mann_whitney_nine_against_nine_without_ties_uses_normal() {
    // Both samples have 9 values: scipy's 'auto' chooses the normal approximation,
    // scipy 1.17.1 gives (58.0, 0.13291945818531892) (exact would be 0.13591114767585355).
    let x = [1.83, 0.50, 1.62, 2.48, 1.68, 1.88, 1.55, 3.06, 1.30];
    let y = [0.878, 0.647, 0.598, 2.05, 1.06, 1.29, 1.06, 3.14, 1.29];
    let r = mann_whitney(&x, &y);
    assert_eq!(r.u, 58.0);
    assert!(close(r.p, 0.132_919_458_185_318_92, 1e-6), "{}", r.p);
}

#[test]
#[allow(clippy::approx_constant)] // 3.14 is data, not pi.
fn signed_rank_matches_scipy() {
    // scipy 1.17.1 `wilcoxon(d)` reports min(T+, T-); p two-sided.
    // Exact (n = 9, no ties): differences of the nine pairs above; wilcoxon(x - y,
    // method='exact') = (5.0, 0.0390625) = 2 * 10/512.
    let x = [1.83, 0.50, 1.62, 2.48, 1.68, 1.88, 1.55, 3.06, 1.30];
    let y = [0.878, 0.647, 0.598, 2.05, 1.06, 1.29, 1.06, 3.14, 1.29];
    let d: Vec<f64> = x.iter().zip(&y).map(|(a, b)| a - b).collect();
    let r = signed_rank(&d, 0.0);
    assert_eq!(r.method, PMethod::Exact);
    assert_eq!(r.t_plus.min(45.0 - r.t_plus), 5.0);
    assert!(close(r.p, 0.039_062_5, 1e-12), "{}", r.p);
    // Ties among |d|: normal approximation; wilcoxon(d, method='approx', correction=True)
    // = (5.0, 0.008437510017470243).
    let d = [1.5, -0.5, 2.0, 3.0, 2.0, -1.0, 4.0, 2.5, 3.5, 1.0, 0.5, 2.0];
    let r = signed_rank(&d, 0.0);
    assert_eq!(r.method, PMethod::Normal);
    assert_eq!(r.t_plus.min(78.0 - r.t_plus), 5.0);
    assert!(close(r.p, 0.008_437_510_017_470_243, 1e-6), "{}", r.p);
    // n = 60 > 50: normal; (1..=60) - 20.5 against 0: (410.0, 0.00020386339085503644).
    let d: Vec<f64> = (1..=60).map(|v| f64::from(v) - 20.5).collect();
    let r = signed_rank(&d, 0.0);
    assert_eq!(r.method, PMethod::Normal);
    assert_eq!(r.t_plus.min(1830.0 - r.t_plus), 410.0);
    assert!(close(r.p, 2.038_633_908_550_364_4e-4, 1e-6), "{}", r.p);
    // The same test against a constant c is the test of x - c against 0.
    let shifted: Vec<f64> = d.iter().map(|v| v + 7.0).collect();
    assert_eq!(signed_rank(&shifted, 7.0), r);
}

#[test]
fn a_single_baseline_run_is_tested_with_signed_ranks() {
    // 20 runs all above a deterministic baseline's one value: Mann–Whitney could not go below
    // p = 2/21, the signed-rank test against the value can (exact: 2 / 2^20).
    let x: Vec<f64> = (1..=20).map(f64::from).collect();
    let c = compare(&x, &[0.5], SEED);
    match c.test {
        Test::SignedRank(t) => {
            assert_eq!(t.t_plus, 210.0);
            assert!(close(t.p, 2.0 / 1_048_576.0, 1e-12), "{}", t.p);
        }
        other => panic!("expected a signed-rank test, got {other:?}"),
    }
    assert_eq!(c.a, 1.0);
    let c = compare(&x, &[0.5, 0.7], SEED);
    assert!(matches!(c.test, Test::MannWhitney(_)));
}

#[test]
fn identical_samples_are_not_different() {
    let x = [5.0; 10];
    let r = mann_whitney(&x, &x);
    assert_eq!(r.p, 1.0);
    assert_eq!(vargha_delaney(&x, &x), 0.5);
}

#[test]
fn holm_adjusts_step_down() {
    // Holm (1979) step-down by hand: sorted p = .01, .02, .03, .04 with m = 4 become
    // .04, .06, .06 (monotone), .06; order restored.
    let adj = holm(&[0.03, 0.01, 0.04, 0.02]);
    let want = [0.06, 0.04, 0.06, 0.06];
    for (a, w) in adj.iter().zip(want) {
        assert!(close(*a, w, 1e-12), "{adj:?}");
    }
    // Capped at 1.
    assert_eq!(holm(&[0.5, 0.6]), vec![1.0, 1.0]);
}

#[test]
fn vargha_delaney_counts_wins_and_half_ties() {
    // Pairs: 3>1, 3>2, 3=3 (1/2); 2>1, 2=2 (1/2), 2<3; 1=1 (1/2), 1<2, 1<3 -> 4.5 of 9 = 0.5.
    assert_eq!(vargha_delaney(&[1.0, 2.0, 3.0], &[1.0, 2.0, 3.0]), 0.5);
    // The textbook sample: A = U / (n1 n2) = 17/20.
    let x = [19.0, 22.0, 16.0, 29.0, 24.0];
    let y = [20.0, 11.0, 17.0, 12.0];
    assert!(close(vargha_delaney(&x, &y), 0.85, 1e-12));
    assert_eq!(Magnitude::of(0.85), Magnitude::Large);
    assert_eq!(Magnitude::of(0.71), Magnitude::Large);
    assert_eq!(Magnitude::of(0.70), Magnitude::Medium);
    assert_eq!(Magnitude::of(0.36), Magnitude::Medium);
    assert_eq!(Magnitude::of(0.56), Magnitude::Small);
    assert_eq!(Magnitude::of(0.45), Magnitude::Negligible);
}

#[test]
fn bootstrap_interval_covers_shift_and_is_seeded() {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let x: Vec<f64> = (0..200).map(|_| rng.random_range(0.0..1.0) + 2.0).collect();
    let y: Vec<f64> = (0..200).map(|_| rng.random_range(0.0..1.0)).collect();
    let (lo, hi) = bootstrap_median_diff_ci(&x, &y, 0.95, 2000, SEED).unwrap();
    assert!(lo < 2.0 && 2.0 < hi && hi - lo < 0.4, "[{lo}, {hi}]");
    assert_eq!(
        bootstrap_median_diff_ci(&x, &y, 0.95, 2000, SEED),
        Some((lo, hi))
    );
    assert_ne!(
        bootstrap_median_diff_ci(&x, &y, 0.95, 2000, SEED + 1),
        Some((lo, hi))
    );
    assert_eq!(bootstrap_median_diff_ci(&[], &y, 0.95, 2000, SEED), None);
}

// ---------------------------------------------------------------------------------------------
// Synthetic results directories.

/// The configurations of the synthetic sweep: the paper's sphere experiment plus greedy.
const CONFIGS: [(&str, Option<u32>); 6] = [
    ("greedy", None),
    ("uniform", Some(1)),
    ("uniform", Some(2)),
    ("selective", Some(1)),
    ("selective", Some(2)),
    ("selective", Some(3)),
];

/// One line of `runs.jsonl`: a runner `RunRecord`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn record(
    mesh: &str,
    algo: &str,
    horizon: Option<u32>,
    run: u32,
    quality_pct: f64,
    recombined_pct: f64,
    time_s: f64,
) -> String {
    let triangles = 2104usize;
    let quads = (recombined_pct / 100.0 * triangles as f64 / 2.0).round() as usize;
    // The figures a record derives are derived as a sweep does (a report checks them).
    let recombined_pct = 100.0 * 2.0 * quads as f64 / triangles as f64;
    let decisions = quads as u64 + 3;
    let nodes = decisions * u64::from(horizon.unwrap_or(1)) * 2;
    RunRecord {
        mesh: mesh.to_string(),
        mesh_hash: "0123456789abcdef0123456789abcdef".to_string(),
        triangles,
        algo: algo.to_string(),
        horizon,
        budget: None,
        time_budget_s: None,
        seed: 1000 + u64::from(run),
        run,
        quads,
        triangles_left: triangles - 2 * quads,
        recombined_pct,
        quality: quality_pct * 9.5,
        quality_pct: Some(quality_pct),
        time_s,
        nodes_expanded: Some(nodes),
        trees: Some(decisions),
        decisions,
        branching_factor: horizon
            .filter(|&h| h >= 2)
            .and_then(|h| effective_branching_factor(nodes as f64 / decisions as f64 - 1.0, h - 1)),
        worst_eta: Some(0.05),
        mean_eta: Some(quality_pct * 9.5 / quads as f64),
        quads_eta_below_0_1: Some(2),
        quads_eta_below_0_3: Some(9),
        min_eta: 0.0,
        allow_invalid: false,
        backend: "cpu-twin".to_string(),
        version: "0.1.0".to_string(),
        finish: None,
    }
    .to_json_line()
}

/// Two deterministic single runs are compared as they are, outside the Holm family; a sample
/// of times is not tested against one timing; a sample of qualities is (against an exact
/// deterministic value), and the tested comparisons keep their bootstrap seeds.
#[test]
fn single_runs_are_shown_as_differences_not_tests() {
    use quadrecomb::internals::report::Metric;
    use quadrecomb::internals::report::significance::Family;
    let runs = |algo: &str, h: Option<u32>, n: u32, q: f64, t: f64| -> Vec<RunRecord> {
        (0..n)
            .map(|i| {
                let line = record(
                    "sphere",
                    algo,
                    h,
                    i,
                    q + f64::from(i) * 0.01,
                    90.0,
                    t * (1.0 + f64::from(i) * 0.01),
                );
                serde_json::from_str(&line).unwrap()
            })
            .collect()
    };
    let greedy = runs("greedy", None, 1, 87.0, 0.02);
    let uniform1 = runs("uniform", Some(1), 1, 87.5, 0.03);
    let selective = runs("selective", Some(2), 30, 90.0, 0.05);
    let family = |metric| {
        Family::build(
            "t".into(),
            metric,
            vec![
                (
                    "uniform h=1".into(),
                    &uniform1[..],
                    "greedy".into(),
                    &greedy[..],
                ),
                (
                    "selective h=2".into(),
                    &selective[..],
                    "greedy".into(),
                    &greedy[..],
                ),
            ],
            SEED,
        )
    };
    let q = family(Metric::Quality);
    assert_eq!(q.pairs.len(), 1, "only the sample against greedy is tested");
    assert_eq!(q.pairs[0].first, "selective h=2");
    assert_eq!(q.untested.len(), 1);
    let text = q.summary();
    assert!(text.contains("Not tested: uniform h=1 vs greedy"), "{text}");
    assert!(text.contains("one run on each side"), "{text}");
    assert!(!text.contains("U = 1"), "{text}");
    let t = family(Metric::Time);
    assert!(t.pairs.is_empty(), "times tested against one timing");
    assert_eq!(t.untested.len(), 2);
    assert!(
        t.summary().contains("one timing on one side"),
        "{}",
        t.summary()
    );
}

/// Where greedy's sum of eta beats a configuration that leaves fewer triangles, the report
/// says why from the medians (fewer quads of a higher mean eta), naming both.
#[test]
fn report_explains_when_greedy_sums_more_but_recombines_less() {
    let tmp = tempfile::tempdir().unwrap();
    let mut lines = vec![record("sphere", "greedy", None, 0, 85.0, 80.0, 0.02)];
    for run in 0..5 {
        let q = 83.0 + f64::from(run) * 0.1;
        lines.push(record("sphere", "selective", Some(1), run, q, 99.0, 0.05));
    }
    std::fs::write(tmp.path().join("runs.jsonl"), lines.join("\n") + "\n").unwrap();
    let opts = ReportOptions {
        pictures: false,
        ..ReportOptions::default()
    };
    let md = std::fs::read_to_string(report::write(tmp.path(), &opts).unwrap().markdown).unwrap();
    let why = (md.lines())
        .find(|l| l.starts_with("Why greedy's sum can beat"))
        .unwrap_or_else(|| panic!("no explanation in {md}"));
    assert!(why.contains("selective h=1"), "{why}");
    assert!(why.contains("times fewer"), "{why}");
    // Nothing to explain when greedy also recombines more.
    let tmp = tempfile::tempdir().unwrap();
    synthetic_dir(tmp.path(), 8, SEED, 0.0);
    let md = std::fs::read_to_string(report::write(tmp.path(), &opts).unwrap().markdown).unwrap();
    assert!(!md.contains("Why greedy's sum"), "{md}");
}

/// Writes `runs.jsonl` for mesh "sphere": quality rises with the selective horizon, uniform h=2
/// is worse and much slower, like the paper's Table 1; `shift` moves every quality.
fn synthetic_dir(dir: &Path, runs: u32, seed: u64, shift: f64) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut lines = Vec::new();
    for (algo, h) in CONFIGS {
        let (q, r, t) = match (algo, h) {
            ("greedy", _) => (87.0, 85.0, 0.02),
            ("uniform", Some(1)) => (87.6, 86.0, 0.16),
            ("uniform", _) => (85.1, 82.7, 20.0),
            (_, Some(h)) => (
                90.8 + h as f64,
                98.0 + 0.2 * h as f64,
                0.03 * 1.8f64.powi(h as i32),
            ),
            _ => unreachable!(),
        };
        for run in 0..runs {
            let noise = |rng: &mut ChaCha8Rng, s: f64| (rng.random_range(-1.0..1.0)) * s;
            lines.push(record(
                "sphere",
                algo,
                h,
                run,
                q + shift + noise(&mut rng, 0.8),
                (r + noise(&mut rng, 0.6)).min(100.0),
                t * (1.0 + noise(&mut rng, 0.2)),
            ));
        }
    }
    std::fs::write(dir.join("runs.jsonl"), lines.join("\n") + "\n").unwrap();
}

/// Writes a manifest for the synthetic sphere sweep (optimum quality 950.0).
fn synthetic_manifest(dir: &Path, runs: u32) {
    use quadrecomb::internals::experiment::manifest::{
        Machine, Manifest, MeshEntry, OptimumEntry, SweepSpec,
    };
    let hash = "0123456789abcdef0123456789abcdef".to_string();
    Manifest {
        version: "0.1.0".into(),
        spec: SweepSpec {
            meshes: vec![MeshEntry {
                name: "sphere".into(),
                source: "sphere".into(),
                path: None,
                hash: hash.clone(),
                triangles: 2104,
            }],
            algos: vec!["greedy".into(), "uniform".into(), "selective".into()],
            horizons: vec![1, 2, 3],
            runs,
            baseline_runs: runs,
            seed: SEED,
            min_eta: 0.0,
            allow_invalid: false,
            plan_version: 2,
            budgets: Vec::new(),
            finish: None,
            time_budgets: Vec::new(),
            calibration: Vec::new(),
        },
        backend: "cpu-twin".into(),
        backend_requested: "cpu".into(),
        optimum: vec![OptimumEntry {
            mesh: "sphere".into(),
            mesh_hash: hash,
            eta_hash: "e".into(),
            quality: 950.0,
            quads: 1052,
            triangles_left: 0,
            time_s: 0.5,
            elements: Default::default(),
        }],
        shard: None,
        threads: 2,
        machine: Machine {
            cpu: "Test CPU 9000".into(),
            cores: 2,
            os: "linux".into(),
            host: "h".into(),
        },
        merged_from: Vec::new(),
        sessions: Vec::new(),
    }
    .write(dir)
    .unwrap();
    reseed(dir);
}

/// Gives the records of `dir/runs.jsonl` (if any) the seeds its manifest's plan gives their
/// runs (a report checks them), so that fixtures need not derive them.
fn reseed(dir: &Path) {
    use quadrecomb::internals::experiment::manifest::Manifest;
    let m = Manifest::read(dir).unwrap();
    let seeds: std::collections::BTreeMap<_, _> =
        quadrecomb::internals::experiment::plan::plan(&m.spec)
            .iter()
            .map(|j| (j.key(&m.spec), j.seed))
            .collect();
    let path = dir.join("runs.jsonl");
    let Ok(text) = std::fs::read_to_string(&path) else {
        return;
    };
    let lines: Vec<String> = text
        .lines()
        .map(|l| {
            let mut r: RunRecord = serde_json::from_str(l).unwrap();
            r.seed = seeds[&r.key()];
            r.to_json_line()
        })
        .collect();
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
}

/// Parses an SVG through usvg and renders it through resvg; returns the ids of its elements.
pub(crate) fn parse_and_render(svg: &str) -> Vec<String> {
    let tree = resvg::usvg::Tree::from_str(svg, &resvg::usvg::Options::default())
        .unwrap_or_else(|e| panic!("SVG does not parse: {e}"));
    let size = tree.size().to_int_size();
    let mut pixmap = resvg::tiny_skia::Pixmap::new(size.width(), size.height()).unwrap();
    resvg::render(
        &tree,
        resvg::tiny_skia::Transform::default(),
        &mut pixmap.as_mut(),
    );
    // Something was drawn besides the white background.
    assert!(
        pixmap
            .pixels()
            .iter()
            .any(|p| p.red() < 200 || p.blue() < 200),
        "blank rendering"
    );
    let mut ids = Vec::new();
    collect_ids(tree.root(), &mut ids);
    ids
}

fn collect_ids(group: &resvg::usvg::Group, ids: &mut Vec<String>) {
    for node in group.children() {
        if !node.id().is_empty() {
            ids.push(node.id().to_string());
        }
        if let resvg::usvg::Node::Group(g) = node {
            collect_ids(g, ids);
        }
    }
}

#[test]
fn report_names_every_configuration_and_draws_every_box() {
    let tmp = tempfile::tempdir().unwrap();
    synthetic_dir(tmp.path(), 30, SEED, 0.0);
    synthetic_manifest(tmp.path(), 30);
    let opts = ReportOptions {
        pictures: false,
        ..ReportOptions::default()
    };
    let paths = report::write(tmp.path(), &opts).unwrap();
    let md = std::fs::read_to_string(&paths.markdown).unwrap();
    // The manifest's machine and optimum.
    assert!(
        md.contains("Machine: Test CPU 9000 (2 logical cores)"),
        "{md}"
    );
    assert!(
        md.contains("Optimum quality: 950.0000 (the maximum-weight matching among those of maximum cardinality"),
        "{md}"
    );
    let html = std::fs::read_to_string(&paths.html).unwrap();
    for (algo, h) in CONFIGS {
        let label = match h {
            Some(h) => format!("{algo} h={h}"),
            None => algo.to_string(),
        };
        assert!(md.contains(&label), "report.md lacks {label}");
        assert!(html.contains(&label), "report.html lacks {label}");
    }
    // Table 1 rows: algorithm | horizon | runs.
    assert!(md.contains("| selective | 3 | 30 |"), "{md}");
    // The paper's numbers beside ours, labelled.
    assert!(md.contains("Beside the paper's numbers"));
    assert!(md.contains(" | 85.1 | "), "{md}");
    assert!(md.contains("| 225.6 |"), "{md}");
    assert!(md.contains("different mesh"));

    // The paper's branching factor is quoted for the selective tree only, and a fit through
    // two horizons (uniform h = 1..2 here) is called what it is.
    let uniform_time = (md.lines())
        .find(|l| l.contains("uniform: time") && l.contains("branching factor"))
        .unwrap_or_else(|| panic!("no uniform time caption in {md}"));
    assert!(
        uniform_time.contains("not comparable with the paper's 1.33"),
        "{uniform_time}"
    );
    assert!(
        uniform_time.contains("a line through two points"),
        "{uniform_time}"
    );
    let selective_time = (md.lines())
        .find(|l| l.contains("selective: time") && l.contains("branching factor"))
        .unwrap();
    assert!(selective_time.contains("the paper reports 1.33 for its selective tree"));
    assert!(
        !selective_time.contains("not comparable"),
        "{selective_time}"
    );
    // Figures: 3 box plots each for uniform and selective.
    assert_eq!(paths.figures.len(), 6, "{:?}", paths.figures);
    let mut boxes_seen = 0;
    for f in &paths.figures {
        let svg = std::fs::read_to_string(f).unwrap();
        let ids = parse_and_render(&svg);
        let name = f.file_name().unwrap().to_string_lossy();
        // Ids are "<figure stem>-box-h<H>".
        let prefix = format!("{}-", name.trim_end_matches(".svg"));
        let boxes: Vec<&str> = ids
            .iter()
            .filter_map(|i| i.strip_prefix(&prefix))
            .filter(|i| i.starts_with("box-h"))
            .collect();
        let want: Vec<&str> = if name.contains("uniform") {
            vec!["box-h1", "box-h2"]
        } else {
            vec!["box-h1", "box-h2", "box-h3"]
        };
        assert_eq!(boxes, want, "{name}");
        boxes_seen += boxes.len();
        // Inlined in the HTML too.
        assert!(html.contains(svg.lines().nth(1).unwrap_or("")));
        assert!(md.contains(&format!("figures/{name}")), "{name} not linked");
    }
    assert_eq!(boxes_seen, 3 * (2 + 3));
    // The time plot of selective carries the fitted branching factor.
    assert!(md.contains("branching factor alpha = 10^slope"));
}

#[test]
fn report_states_which_differences_are_significant() {
    let tmp = tempfile::tempdir().unwrap();
    synthetic_dir(tmp.path(), 40, SEED, 0.0);
    let opts = ReportOptions {
        pictures: false,
        ..ReportOptions::default()
    };
    let paths = report::write(tmp.path(), &opts).unwrap();
    let md = std::fs::read_to_string(&paths.markdown).unwrap();
    // Selective quality rises by 1 point per horizon with noise +-0.8: h=2 vs h=1 must be
    // significant with a large effect; uniform h=2 is far slower than h=1.
    assert!(
        md.contains("Consecutive horizons, quality: ") && md.contains("significant at 0.05"),
        "{md}"
    );
    let line = md
        .lines()
        .find(|l| l.starts_with("| selective h=2 vs selective h=1 | quality"))
        .expect("row for selective h=2 vs h=1");
    assert!(line.ends_with("| yes |"), "{line}");
    assert!(line.contains("(large)"), "{line}");

    // Greedy run once (the runner's default for deterministic baselines): the others are tested
    // against its value with signed ranks, and selective is still significantly better.
    let runs = tmp.path().join("runs.jsonl");
    let kept: Vec<String> = std::fs::read_to_string(&runs)
        .unwrap()
        .lines()
        .filter(|l| {
            let r: RunRecord = serde_json::from_str(l).unwrap();
            r.algo != "greedy" || r.run == 0
        })
        .map(String::from)
        .collect();
    std::fs::write(&runs, kept.join("\n") + "\n").unwrap();
    let md = std::fs::read_to_string(report::write(tmp.path(), &opts).unwrap().markdown).unwrap();
    let line = md
        .lines()
        .find(|l| l.starts_with("| selective h=3 vs greedy | quality"))
        .expect("row for selective h=3 vs greedy");
    assert!(line.contains("| T+ = 820 |"), "{line}");
    assert!(line.ends_with("| yes |"), "{line}");
}

#[test]
fn compare_two_directories() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b, c) = (
        tmp.path().join("a"),
        tmp.path().join("b"),
        tmp.path().join("c"),
    );
    for d in [&a, &b, &c] {
        std::fs::create_dir(d).unwrap();
    }
    synthetic_dir(&a, 30, SEED, 0.0);
    // Same distributions, other seed: nothing should differ in quality.
    synthetic_dir(&b, 30, SEED + 1, 0.0);
    // Quality shifted by 3 points: every configuration differs.
    synthetic_dir(&c, 30, SEED + 2, 3.0);
    let opts = |other: &Path| ReportOptions {
        pictures: false,
        compare: Some(other.to_path_buf()),
        ..ReportOptions::default()
    };
    let md_ab = std::fs::read_to_string(report::write(&a, &opts(&b)).unwrap().markdown).unwrap();
    assert!(
        md_ab.contains(
            "First vs second directory, quality: none of the 6 differences is significant"
        ),
        "{md_ab}"
    );
    let md_ac = std::fs::read_to_string(report::write(&a, &opts(&c)).unwrap().markdown).unwrap();
    assert!(
        md_ac.contains("First vs second directory, quality: 6 of 6 differences are significant"),
        "{md_ac}"
    );
}

/// A report of a sweep that was stopped says so: how many of the planned runs it holds
/// and how to finish; a finished sweep's report does not.
#[test]
fn report_of_an_unfinished_sweep_says_so() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let ok = |args: &[&str]| String::from_utf8_lossy(&run_ok(dir, args).stderr).into_owned();
    ok(&["generate", "grid", "--triangles", "300", "-o", "g.msh"]);
    ok(&[
        "sweep",
        "--mesh",
        "g.msh",
        "--algo",
        "greedy",
        "--algo",
        "selective",
        "--horizons",
        "1,2",
        "--runs",
        "4",
        "--out",
        "s",
        "--quiet",
        "--no-report",
    ]);
    let report_md = || {
        let err = ok(&["report", "s", "--no-pictures"]);
        (
            std::fs::read_to_string(dir.join("s/report.md")).unwrap(),
            err,
        )
    };
    let (md, err) = report_md();
    assert!(md.contains("9 runs in 3 configurations"), "{md}");
    assert!(!md.contains("Incomplete"), "{md}");
    assert!(!err.contains("warning"), "{err}");
    // Keep the first five records, as an interrupted sweep leaves them.
    let runs = dir.join("s/runs.jsonl");
    let text = std::fs::read_to_string(&runs).unwrap();
    let kept: Vec<&str> = text.lines().take(5).collect();
    std::fs::write(&runs, kept.join("\n") + "\n").unwrap();
    // Said on stderr too, for a script that does not read the report.
    let (md, err) = report_md();
    assert!(
        err.contains("warning: report: s: incomplete sweep: 5 of the 9 planned runs"),
        "{err}"
    );
    assert!(
        md.contains("Incomplete sweep: 5 of the 9 runs planned in this directory are recorded"),
        "{md}"
    );
    assert!(md.contains("with --resume"), "{md}");
}

#[test]
fn torn_last_line_is_skipped_and_other_bad_lines_are_errors() {
    let tmp = tempfile::tempdir().unwrap();
    synthetic_dir(tmp.path(), 5, SEED, 0.0);
    let runs = tmp.path().join("runs.jsonl");
    let mut text = std::fs::read_to_string(&runs).unwrap();
    text.push_str("{\"mesh\": \"sphere\", \"algo\"");
    std::fs::write(&runs, &text).unwrap();
    let opts = ReportOptions {
        pictures: false,
        ..ReportOptions::default()
    };
    let paths = report::write(tmp.path(), &opts).unwrap();
    let md = std::fs::read_to_string(paths.markdown).unwrap();
    assert!(md.contains("torn"), "{md}");
    assert!(
        paths
            .warnings
            .iter()
            .any(|w| w.contains("runs.jsonl is torn")),
        "{:?}",
        paths.warnings
    );
    assert!(md.starts_with("# quadrecomb report"));
    assert!(md.contains("30 runs in 6 configurations"), "{md}");

    // A bad line in the middle is an error naming the line.
    std::fs::write(&runs, format!("not json\n{text}")).unwrap();
    let err = report::write(tmp.path(), &opts).unwrap_err().to_string();
    assert!(
        err.contains("runs.jsonl") && err.contains("line 1"),
        "{err}"
    );
}

// ---------------------------------------------------------------------------------------------
// Mesh pictures.

/// A 4x3 grid of unit squares, each split into two triangles, in the plane z = 0.
fn grid_mesh() -> Mesh {
    let (nx, ny) = (4u32, 3u32);
    let mut data = MeshData::default();
    for j in 0..=ny {
        for i in 0..=nx {
            data.vertices.push([i as f64, j as f64, 0.0]);
        }
    }
    let v = |i: u32, j: u32| j * (nx + 1) + i;
    for j in 0..ny {
        for i in 0..nx {
            data.triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            data.triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    Mesh::new(data).unwrap()
}

/// Counts `<polygon` elements (one per quad or leftover triangle drawn).
fn polygons(svg: &str) -> usize {
    svg.matches("<polygon").count()
}

#[test]
fn planar_picture_draws_every_quad_and_leftover() {
    let mesh = grid_mesh();
    let table = CandidateTable::build(&mesh);
    // Recombine each square's diagonal pair in the first two rows; leave the third row.
    let chosen: Vec<u32> = (0..table.len() as u32)
        .filter(|&c| {
            let [a, b] = table.pairs[c as usize];
            a / 2 == b / 2 && a / 8 < 2
        })
        .collect();
    assert_eq!(chosen.len(), 8);
    let rec = recombined(&mesh, &table, &chosen);
    let (svg, counts) = mesh_svg(&mesh, &rec, &PictureOptions::default()).unwrap();
    assert_eq!((counts.quads, counts.leftover, counts.culled), (8, 8, 0));
    assert_eq!(polygons(&svg), 16);
    parse_and_render(&svg);
    // Unit squares have eta 1: the top of viridis; leftovers in red.
    assert!(svg.contains("#FDE725"), "eta-1 colour missing");
    assert!(svg.contains("#E61E1E"), "leftover colour missing");

    // Zoom into the lower-left 2x1 cells: 2 quads drawn (the ones touching it are clipped).
    let zoom = PictureOptions {
        zoom: Some([0.0, 0.0, 2.0, 1.0]),
        ..PictureOptions::default()
    };
    let (svg, counts) = mesh_svg(&mesh, &rec, &zoom).unwrap();
    assert_eq!((counts.quads, counts.leftover), (2, 0));
    assert_eq!(polygons(&svg), 2);
    parse_and_render(&svg);
}

/// The whole-mesh picture of a graded mesh: faces at sub-pixel coordinates, and an inset of
/// the densest region (borouchaki's: beside the hole, where the elements are smallest) drawn
/// below with its own faces and framed on the picture.
#[test]
fn picture_has_sub_pixel_faces_and_an_inset_of_the_densest_region() {
    let mesh = quadrecomb::internals::mesh::load("borouchaki").unwrap();
    let table = CandidateTable::build(&mesh);
    let out = quadrecomb::internals::search::run(
        &mesh,
        &table,
        quadrecomb::internals::search::Algo::greedy(),
        SEED,
    );
    let rec = recombined(&mesh, &table, &out.chosen);
    let opts = PictureOptions {
        inset: true,
        ..PictureOptions::default()
    };
    let (svg, counts) = mesh_svg(&mesh, &rec, &opts).unwrap();
    assert_eq!(counts.quads, rec.quads.len());
    let ([x0, y0, x1, y1], q, l) = counts.inset.expect("an inset");
    assert!(q > 100, "{q} quads in the inset");
    assert_eq!(polygons(&svg), counts.quads + counts.leftover + q + l);
    // Inside the unit square, its centre within 0.25 of the hole's (0.6, 0.75).
    assert!(0.0 <= x0 && x0 < x1 && x1 <= 1.0 && 0.0 <= y0 && y0 < y1 && y1 <= 1.0);
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    assert!(
        ((cx - 0.6).powi(2) + (cy - 0.75).powi(2)).sqrt() < 0.25,
        "inset at ({cx}, {cy})"
    );
    // Coordinates with two decimals, not whole pixels: most vertices are off the pixel grid.
    let coords: Vec<&str> = svg
        .split("<polygon points=\"")
        .skip(1)
        .flat_map(|p| p[..p.find('"').unwrap()].split([' ', ',']))
        .collect();
    let fractional = coords.iter().filter(|c| !c.ends_with(".00")).count();
    assert!(
        fractional * 2 > coords.len(),
        "{fractional} of {} coordinates off the pixel grid",
        coords.len()
    );
    assert!(
        svg.contains(r##"fill="none" stroke="#E61E1E""##),
        "inset not framed"
    );
    parse_and_render(&svg);
    // Without the option (and with a zoom) there is no inset.
    let (_, plain) = mesh_svg(&mesh, &rec, &PictureOptions::default()).unwrap();
    assert_eq!(plain.inset, None);
}

#[test]
fn closed_surface_picture_culls_back_faces() {
    // Octahedron: from the picture's view direction (1, -1.4, 1.1) four faces face the viewer.
    let data = MeshData {
        vertices: vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ],
        triangles: vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ],
        ..MeshData::default()
    };
    let mesh = Mesh::new(data).unwrap();
    let table = CandidateTable::build(&mesh);
    let rec = recombined(&mesh, &table, &[]);
    let (svg, counts) = mesh_svg(&mesh, &rec, &PictureOptions::default()).unwrap();
    assert_eq!((counts.leftover, counts.culled), (4, 4));
    assert_eq!(polygons(&svg), 4);
    parse_and_render(&svg);
    // Orientation flipped everywhere: the same faces are culled (outward is detected).
    let mut flipped = MeshData {
        vertices: mesh.vertices.clone(),
        triangles: mesh.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect(),
        ..MeshData::default()
    };
    flipped.triangle_surface = vec![1; 8];
    let mesh2 = Mesh::new(flipped).unwrap();
    let rec2 = recombined(&mesh2, &CandidateTable::build(&mesh2), &[]);
    let (_, counts2) = mesh_svg(&mesh2, &rec2, &PictureOptions::default()).unwrap();
    assert_eq!(counts2.culled, 4);
}

// ---------------------------------------------------------------------------------------------
// The subcommand.

#[test]
fn report_command_writes_files_and_rejects_bad_input() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("res");
    std::fs::create_dir(&dir).unwrap();
    synthetic_dir(&dir, 8, SEED, 0.0);
    let out = run_in(tmp.path(), &["report", "res", "--no-pictures"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.join("report.md").is_file() && dir.join("report.html").is_file());
    assert!(dir.join("figures/sphere-selective-time.svg").is_file());

    let out = run_in(tmp.path(), &["report", "res", "--zoom", "1,2,3"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--zoom"));
    let err = |out: &std::process::Output| String::from_utf8_lossy(&out.stderr).into_owned();
    let out = run_in(tmp.path(), &["report", "missing-dir"]);
    assert_eq!(out.status.code(), Some(3));
    assert!(
        err(&out).contains("missing-dir: no such directory"),
        "{}",
        err(&out)
    );
    let out = run_in(tmp.path(), &["report", "res/runs.jsonl"]);
    assert_eq!(out.status.code(), Some(3));
    assert!(err(&out).contains("not a directory"), "{}", err(&out));
    // A configuration to picture that the results do not hold is an error, not ignored.
    for bad in ["bogus", "selective:9"] {
        let out = run_in(tmp.path(), &["report", "res", "--picture", bad]);
        assert_eq!(out.status.code(), Some(2), "{}", err(&out));
        assert!(
            err(&out).contains(&format!("--picture {bad}: no such configuration")),
            "{}",
            err(&out)
        );
    }
    // Pictures asked for and refused at once is a usage error, not one of them ignored.
    for asked in [["--picture", "selective:1"], ["--zoom", "0,0,1,1"]] {
        let out = run_in(
            tmp.path(),
            &["report", "res", "--no-pictures", asked[0], asked[1]],
        );
        assert_eq!(out.status.code(), Some(2), "{}", err(&out));
        assert!(
            err(&out).contains("'--no-pictures' cannot be used with"),
            "{}",
            err(&out)
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Typical runs, re-run for the pictures.

/// A results directory holding real runs of the built-in sphere (CPU-twin eta), with a
/// manifest, as a sweep writes it. `tamper` changes the recorded quality of every run.
fn real_sphere_dir(dir: &Path, tamper: f64) {
    use quadrecomb::internals::experiment::{mesh_hash, seed::eta_hash};
    use quadrecomb::internals::gpu::Evaluator;
    use quadrecomb::internals::search::{self, Algo};
    let mesh = quadrecomb::internals::mesh::load("sphere").unwrap();
    let mut table = CandidateTable::topology_only(&mesh);
    Evaluator::cpu_twin()
        .fill(&mut [(&mesh, &mut table)])
        .unwrap();
    let table = table.restrict(&mesh, quadrecomb::internals::quality::Rule::default());
    let hash = mesh_hash(&mesh);
    synthetic_manifest(dir, 3);
    // The manifest's mesh and eta are the real ones.
    let path = dir.join("manifest.json");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("0123456789abcdef0123456789abcdef", &hash)
        .replace(
            "\"eta_hash\": \"e\"",
            &format!("\"eta_hash\": \"{}\"", eta_hash(&table.eta)),
        );
    std::fs::write(&path, text).unwrap();
    // Runs of three of its configurations, with the seeds its plan gives them.
    let manifest = quadrecomb::internals::experiment::manifest::Manifest::read(dir).unwrap();
    let jobs = quadrecomb::internals::experiment::plan::plan(&manifest.spec);
    let mut lines = Vec::new();
    for (algo, h) in [
        ("greedy", None),
        ("selective", Some(1)),
        ("selective", Some(2)),
    ] {
        for run in 0..3u32 {
            let seed = jobs
                .iter()
                .find(|j| j.algo == algo && j.horizon == h && j.run == run)
                .unwrap()
                .seed;
            let out = search::run(
                &mesh,
                &table,
                Algo::from_name(algo, h.unwrap_or(1)).unwrap(),
                seed,
            );
            let n = mesh.num_triangles();
            lines.push(
                RunRecord {
                    mesh: "sphere".into(),
                    mesh_hash: hash.clone(),
                    triangles: n,
                    algo: algo.into(),
                    horizon: h,
                    budget: None,
                    time_budget_s: None,
                    seed,
                    run,
                    quads: out.quads,
                    triangles_left: out.triangles_left,
                    recombined_pct: 100.0 * 2.0 * out.quads as f64 / n as f64,
                    quality: out.quality + tamper,
                    // Against the synthetic manifest's optimum.
                    quality_pct: Some(100.0 * (out.quality + tamper) / 950.0),
                    time_s: out.time_s,
                    nodes_expanded: Some(out.nodes_expanded),
                    trees: Some(out.trees),
                    decisions: out.decisions,
                    branching_factor: h.filter(|&h| h >= 2 && out.trees > 0).and_then(|h| {
                        effective_branching_factor(
                            out.nodes_expanded as f64 / out.trees as f64 - 1.0,
                            h - 1,
                        )
                    }),
                    worst_eta: None,
                    mean_eta: None,
                    quads_eta_below_0_1: None,
                    quads_eta_below_0_3: None,
                    min_eta: 0.0,
                    allow_invalid: false,
                    backend: "cpu-twin".into(),
                    version: "0.1.0".into(),
                    finish: None,
                }
                .to_json_line(),
            );
        }
    }
    std::fs::write(dir.join("runs.jsonl"), lines.join("\n") + "\n").unwrap();
}

#[test]
fn typical_runs_are_rerun_reproduced_and_drawn() {
    let tmp = tempfile::tempdir().unwrap();
    real_sphere_dir(tmp.path(), 0.0);
    let opts = ReportOptions {
        zoom: Some([-0.5, -0.5, 0.5, 0.5]),
        ..ReportOptions::default()
    };
    let paths = report::write(tmp.path(), &opts).unwrap();
    let default_pics = paths
        .figures
        .iter()
        .filter(|f| f.to_string_lossy().contains("-h-2-"))
        .count();
    assert_eq!(default_pics, 2, "{:?}", paths.figures);
    let opts = ReportOptions {
        picture_configs: vec![("greedy".into(), None), ("selective".into(), None)],
        ..opts
    };
    let paths = report::write(tmp.path(), &opts).unwrap();
    let md = std::fs::read_to_string(&paths.markdown).unwrap();
    // Default choice: the best selective horizon (h=2 here); whole and zoomed. Greedy asked for.
    let pics: Vec<String> = paths
        .figures
        .iter()
        .map(|f| f.file_name().unwrap().to_string_lossy().into_owned())
        .filter(|n| n.ends_with("-mesh.svg") || n.ends_with("-zoom.svg"))
        .collect();
    // greedy, selective h=1 and h=2 (ALGO without :H means every horizon), whole and zoomed.
    assert_eq!(pics.len(), 6, "{pics:?}");
    assert!(
        pics.contains(&"sphere-greedy-mesh.svg".to_string()),
        "{pics:?}"
    );
    assert!(
        pics.contains(&"sphere-greedy-zoom.svg".to_string()),
        "{pics:?}"
    );
    assert_eq!(
        md.matches("the re-run reproduces the recorded quads and quality exactly")
            .count(),
        6,
        "{md}"
    );
    assert!(md.contains("its eta hash matches the manifest's"), "{md}");
    assert!(md.contains("back faces culled"), "{md}");
    for f in paths
        .figures
        .iter()
        .filter(|f| f.to_string_lossy().ends_with("mesh.svg"))
    {
        let svg = std::fs::read_to_string(f).unwrap();
        parse_and_render(&svg);
        // About half the sphere faces the viewer.
        let drawn = polygons(&svg);
        assert!(drawn > 400 && drawn < 800, "{drawn} faces drawn");
    }

    // A record the re-run does not reproduce is said so, not hidden.
    let tmp2 = tempfile::tempdir().unwrap();
    real_sphere_dir(tmp2.path(), 0.5);
    let opts = ReportOptions {
        picture_configs: vec![("selective".into(), Some(2))],
        ..ReportOptions::default()
    };
    let paths = report::write(tmp2.path(), &opts).unwrap();
    let md = std::fs::read_to_string(&paths.markdown).unwrap();
    assert!(md.contains("the re-run gives"), "{md}");
    assert!(
        tmp2.path()
            .join("figures/sphere-selective-h-2-mesh.svg")
            .is_file()
    );
}

/// `--zoom` takes negative coordinates without `=` (clap read `-0.5,...` as a flag).
#[test]
fn zoom_takes_negative_values_without_equals() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("res");
    std::fs::create_dir(&dir).unwrap();
    real_sphere_dir(&dir, 0.0);
    let args = [
        "report",
        "res",
        "--picture",
        "greedy",
        "--zoom",
        "-0.5,-0.5,0.5,0.5",
    ];
    let out = run_in(tmp.path(), &args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(dir.join("figures/sphere-greedy-zoom.svg").is_file());
}

/// `--picture optimum` draws the optimum's matching, computed again (it was accepted and drew
/// nothing); a re-run of `report` removes the figures its previous run wrote and no longer
/// draws, and only those (a user's file in figures/ stays); the optimum's "nodes per tree" is
/// "–", not 0: it builds no tree.
#[test]
fn optimum_pictured_stale_figures_removed_no_tree_is_a_dash() {
    let tmp = tempfile::tempdir().unwrap();
    let err = |o: &std::process::Output| String::from_utf8_lossy(&o.stderr).into_owned();
    let sweep = [
        "sweep",
        "--mesh",
        "sphere",
        "--algo",
        "greedy",
        "optimum",
        "--backend",
        "cpu",
        "--no-report",
        "-q",
        "--out",
        "d",
    ];
    let o = run_in(tmp.path(), &sweep);
    assert!(o.status.success(), "{}", err(&o));
    let d = tmp.path().join("d");
    let o = run_in(tmp.path(), &["report", "d", "--picture", "greedy"]);
    assert!(o.status.success(), "{}", err(&o));
    assert!(d.join("figures/sphere-greedy-mesh.svg").is_file());
    std::fs::write(d.join("figures/mine.svg"), "<svg/>").unwrap();

    let o = run_in(tmp.path(), &["report", "d", "--picture", "optimum"]);
    assert!(o.status.success(), "{}", err(&o));
    let svg = std::fs::read_to_string(d.join("figures/sphere-optimum-mesh.svg")).unwrap();
    parse_and_render(&svg);
    assert!(polygons(&svg) > 400, "the optimum's quads are drawn");
    let md = std::fs::read_to_string(d.join("report.md")).unwrap();
    assert!(
        md.contains(
            "optimum (maximum-weight matching of maximum cardinality): 1052 quads, 0 triangles left"
        ) && md.contains("Matching computed again with eta from")
            && md.contains("reproduces the recorded quads and quality exactly"),
        "{md}"
    );
    // The greedy picture of the previous run is gone; the user's file is not.
    assert!(!d.join("figures/sphere-greedy-mesh.svg").exists());
    assert!(d.join("figures/mine.svg").is_file());
    // Table 1: the optimum's nodes per tree (7th column) is a dash.
    let row = md.lines().find(|l| l.starts_with("| optimum |")).unwrap();
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    assert_eq!(cells[7], "–", "{row}");
}

/// A report lists its meshes in the sweep's `--mesh` order (the manifest's), not in the
/// order in which runs happened to finish (which changed from one sweep to the next with
/// several threads, and with it the report's sections, tables and `across_meshes.csv`);
/// `replay` with no option replays the first configuration of that first mesh.
#[test]
fn meshes_are_reported_in_the_sweeps_order() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    run_ok(
        dir,
        &[
            "generate",
            "grid",
            "--triangles",
            "600",
            "--seed",
            "2",
            "-o",
            "g.msh",
        ],
    );
    run_ok(
        dir,
        &[
            "sweep",
            "--mesh",
            "sphere",
            "g.msh",
            "--algo",
            "greedy",
            "--backend",
            "cpu",
            "--out",
            "r",
            "-q",
            "--no-report",
        ],
    );
    // The runs of the second mesh first, as a thread that finished it first writes them.
    let runs = dir.join("r/runs.jsonl");
    let text = std::fs::read_to_string(&runs).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines.sort_by_key(|l| !l.contains("\"mesh\":\"g\""));
    assert!(lines[0].contains("\"mesh\":\"g\""), "{text}");
    std::fs::write(&runs, lines.join("\n") + "\n").unwrap();
    run_ok(dir, &["report", "r"]);
    let md = std::fs::read_to_string(dir.join("r/report.md")).unwrap();
    assert!(md.contains("2 meshes (sphere, g)"), "{md}");
    let csv = std::fs::read_to_string(dir.join("r/across_meshes.csv")).unwrap();
    assert!(csv.lines().nth(1).unwrap().starts_with("sphere,"), "{csv}");
    let out = run_ok(dir, &["replay", "r"]);
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(said.contains("sphere greedy run 0"), "{said}");
}

/// `report --compare` of two directories made under different quad-validity rules says so
/// for each mesh, with the two optima its quality percentages are of (a review's
/// comparison found recombined % "significant" with no word that the rule made it).
#[test]
fn a_comparison_across_validity_rules_says_so() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for (out, extra) in [
        ("a", None),
        ("b", Some("--allow-invalid")),
        ("c", Some("0.3")),
    ] {
        let mut args = vec![
            "sweep",
            "--mesh",
            "sphere",
            "--algo",
            "greedy",
            "selective",
            "--horizons",
            "1",
            "--runs",
            "4",
            "--backend",
            "cpu",
            "--out",
            out,
            "-q",
            "--no-report",
        ];
        match extra {
            Some("--allow-invalid") => args.push("--allow-invalid"),
            Some(e) => args.extend(["--min-eta", e]),
            None => {}
        }
        run_ok(dir, &args);
    }
    let compare = |first: &str, second: &str| {
        run_ok(
            dir,
            &["report", first, "--compare", second, "--no-pictures"],
        );
        std::fs::read_to_string(dir.join(first).join("report.md")).unwrap()
    };
    let md = compare("a", "b");
    assert!(
        md.contains(
            "sphere: the two directories used different quad-validity rules (valid quads \
             (eta \\> 0) vs all pairs, eta-0 quads included (paper-literal)): quality is a % \
             of each rule's own optimum (678.81 vs 678.81)"
        ),
        "{md}"
    );
    // Once per mesh, not per configuration.
    assert_eq!(
        md.matches("different quad-validity rules").count(),
        1,
        "{md}"
    );
    let md = compare("a", "c");
    assert!(
        md.contains("rules (valid quads (eta \\> 0) vs valid quads, eta \\>= 0.3)"),
        "{md}"
    );
    let md = compare("a", "a");
    assert!(!md.contains("quad-validity"), "{md}");
}
