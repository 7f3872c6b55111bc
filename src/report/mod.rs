//! Reports: tables, box plots, mesh pictures and statistical comparisons from sweep results.
//!
//! [`write()`] reads a results directory (`runs.jsonl`, `manifest.json`) and writes `report.md`,
//! `report.html` (figures inlined) and the figures as SVG files under `figures/`. The report
//! holds, per mesh: a Table-1-style table (median quality % of optimum, recombined %, time,
//! nodes per tree per algorithm and horizon), the paper's own numbers beside ours, Fig.-8-style
//! box plots against horizon with the fitted branching factor, pictures of typical runs, and
//! Mann–Whitney/Holm/Vargha–Delaney/bootstrap comparisons of consecutive horizons and against
//! greedy; with [`ReportOptions::compare`], also one directory against another.

mod document;
mod format;
pub mod paper;
pub mod picture;
pub mod plots;
pub mod results;
pub mod significance;
pub mod typical;

pub use document::{Block, Document};
pub use results::{Config, Metric, Results, Run};

use crate::experiment::replay::Replayer;
use crate::stats::describe::{BoxStats, median};
use format::{fmt_opt, fmt_sig};
use plots::{Extras, HorizonBox, boxplot_svg};
use significance::Family;
use std::path::{Path, PathBuf};

/// Errors of report writing.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The directory is missing or holds no `runs.jsonl`.
    #[error("{dir}: {why}")]
    NotResults {
        /// The directory.
        dir: PathBuf,
        /// What is missing.
        why: String,
    },
    /// `runs.jsonl` holds no run.
    #[error("{path}: no runs recorded")]
    NoRuns {
        /// The file.
        path: PathBuf,
    },
    /// The runner's files (`runs.jsonl`, `manifest.json`) could not be read.
    #[error(transparent)]
    Results(#[from] crate::experiment::ExperimentError),
    /// `--picture` names a configuration the results do not hold.
    #[error("--picture {0}: no such configuration in these results (they hold: {1})")]
    NoSuchPicture(String, String),
    /// plotters failed to draw (an internal error).
    #[error("drawing a figure failed: {0}")]
    Plot(String),
}

/// What to put in a report besides the defaults.
#[derive(Debug, Clone)]
pub struct ReportOptions {
    /// Another results directory to compare with, configuration by configuration.
    pub compare: Option<PathBuf>,
    /// A window `[x0, y0, x1, y1]` of the mesh pictures to draw zoomed, besides the whole mesh.
    pub zoom: Option<[f64; 4]>,
    /// Draw mesh pictures of typical runs (re-running them).
    pub pictures: bool,
    /// Configurations (algorithm, horizon) whose typical run is pictured; empty: per look-ahead
    /// algorithm, the horizon with the best median quality.
    pub picture_configs: Vec<(String, Option<u32>)>,
    /// Seed of the bootstrap resampling.
    pub seed: u64,
}

impl Default for ReportOptions {
    fn default() -> Self {
        ReportOptions {
            compare: None,
            zoom: None,
            pictures: true,
            picture_configs: Vec::new(),
            seed: 0x5EED_2026,
        }
    }
}

/// The files a report wrote.
#[derive(Debug, Clone)]
pub struct ReportPaths {
    /// `report.md`.
    pub markdown: PathBuf,
    /// `report.html` (self-contained).
    pub html: PathBuf,
    /// SVG figures under `figures/`.
    pub figures: Vec<PathBuf>,
}

pub use crate::experiment::engine::FIGURES_DIR;

/// Reads `dir`'s results and writes `dir/report.md`, `dir/report.html` and `dir/figures/*.svg`.
pub fn write(dir: &Path, opts: &ReportOptions) -> Result<ReportPaths, ReportError> {
    let results = Results::read(dir)?;
    // The summary follows the runs it is made of (it was left stale after an edit).
    crate::experiment::summary::write(dir, &results.runs())?;
    let other = match &opts.compare {
        Some(d) => Some(Results::read(d)?),
        None => None,
    };
    let doc = build(&results, other.as_ref(), opts)?;
    let fig_dir = dir.join(FIGURES_DIR);
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| ReportError::Io { path, source }
    };
    std::fs::create_dir_all(&fig_dir).map_err(io(&fig_dir))?;
    let earlier = crate::experiment::engine::report_files(dir)?;
    let mut figures = Vec::new();
    let mut list = String::new();
    for (file, svg) in doc.figures() {
        let path = dir.join(file);
        crate::output::write_bytes(&path, svg.as_bytes()).map_err(io(&path))?;
        figures.push(path);
        list.push_str(file);
        list.push('\n');
    }
    // The list of what this report wrote (what `sweep --overwrite` may delete), then the
    // figures of the earlier report that this one no longer draws.
    let listed = dir.join(crate::experiment::engine::REPORT_FILES);
    crate::output::write_bytes(&listed, list.as_bytes()).map_err(io(&listed))?;
    for old in earlier {
        if !list.lines().any(|l| l == old) {
            let _ = std::fs::remove_file(dir.join(old));
        }
    }
    let markdown = dir.join("report.md");
    crate::output::write_bytes(&markdown, doc.to_markdown().as_bytes()).map_err(io(&markdown))?;
    let html = dir.join("report.html");
    let title = format!("quadrecomb report: {}", dir.display());
    crate::output::write_bytes(&html, doc.to_html(&title).as_bytes()).map_err(io(&html))?;
    Ok(ReportPaths {
        markdown,
        html,
        figures,
    })
}

/// Builds the report of `results` (compared with `other` if given) without writing anything.
pub fn build(
    results: &Results,
    other: Option<&Results>,
    opts: &ReportOptions,
) -> Result<Document, ReportError> {
    check_pictures(results, opts)?;
    let mut doc = Document::default();
    doc.heading(1, format!("quadrecomb report: {}", results.dir.display()));
    overview(&mut doc, results);
    let mut replayer = Replayer::new(&results.dir, results.manifest.as_ref());
    for (i, mesh) in results.meshes.iter().enumerate() {
        mesh_section(
            &mut doc,
            results,
            mesh,
            opts,
            opts.seed.wrapping_add(100_000 * i as u64),
            &mut replayer,
        )?;
    }
    if let Some(other) = other {
        compare_section(&mut doc, results, other, opts.seed.wrapping_add(7_777_777));
    }
    method_notes(&mut doc);
    Ok(doc)
}

/// Opening paragraph: what was run, where, by which version.
fn overview(doc: &mut Document, results: &Results) {
    let runs: Vec<&Run> = results.groups.values().flatten().collect();
    let mut versions: Vec<&str> = runs.iter().map(|r| r.version.as_str()).collect();
    versions.sort_unstable();
    versions.dedup();
    let mut backends: Vec<&str> = runs.iter().map(|r| r.backend.as_str()).collect();
    backends.sort_unstable();
    backends.dedup();
    doc.para(format!(
        "{} runs in {} configurations on {} mesh(es), made by quadrecomb {} with eta computed by {}.",
        results.num_runs(),
        results.groups.len(),
        results.meshes.len(),
        versions.join(", "),
        backends.join(", "),
    ));
    let mut rules: Vec<String> = runs.iter().map(|r| r.rule().to_string()).collect();
    rules.sort_unstable();
    rules.dedup();
    doc.para(format!(
        "Rule: {} (which pairs of triangles may be merged: set by --min-eta and --allow-invalid).",
        rules.join("; ")
    ));
    if let Some(m) = &results.manifest {
        let machine = |m: &crate::experiment::manifest::Machine| {
            format!("{} ({} logical cores), {}", m.cpu, m.cores, m.os)
        };
        if m.merged_from.is_empty() {
            doc.para(format!(
                "Machine: {}; {} worker thread(s). Base seed {}; {} runs per horizon, {} per \
                 baseline.",
                machine(&m.machine),
                m.threads,
                m.spec.seed,
                m.spec.runs,
                m.spec.baseline_runs,
            ));
        } else {
            let parts: Vec<String> = m
                .merged_from
                .iter()
                .map(|p| format!("{} ({} runs): {}", p.dir, p.records, machine(&p.machine)))
                .collect();
            doc.para(format!(
                "Merged from shards run on: {}. Base seed {}.",
                parts.join("; "),
                m.spec.seed
            ));
        }
    }
    if results.torn_bytes > 0 {
        doc.para(
            "The last line of runs.jsonl was torn (a run interrupted while being written) and is \
             not counted; `quadrecomb sweep --resume` redoes it.",
        );
    }
    let labels: Vec<String> = results
        .groups
        .iter()
        .map(|(c, r)| {
            let runs = if r.len() == 1 { "run" } else { "runs" };
            format!("{} {} ({} {runs})", c.mesh, c.label(), r.len())
        })
        .collect();
    doc.para(format!("Configurations: {}.", labels.join("; ")));
}

/// The optimum quality of `mesh` from the manifest, if recorded.
fn optimum_of(results: &Results, mesh: &str) -> Option<f64> {
    results
        .manifest
        .as_ref()?
        .optimum
        .iter()
        .find(|o| o.mesh == mesh)
        .map(|o| o.quality)
}

/// File-name-safe form of a mesh name: its [`slug`] when that is the name itself, else the
/// slug and 8 hex digits of the name's hash (`a b` and `a-b` both gave `a-b`, and their
/// figures overwrote each other).
fn mesh_slug(mesh: &str) -> String {
    let s = slug(mesh);
    if s == mesh {
        s
    } else {
        let h = blake3::hash(mesh.as_bytes()).to_hex();
        format!("{s}-{}", &h[..8])
    }
}

/// File-name-safe form of a label.
fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect::<String>()
        .split('-')
        .filter(|p| !p.is_empty())
        .collect::<Vec<_>>()
        .join("-")
}

/// Median of an optional field over runs, when every run has it.
fn median_opt(runs: &[Run], f: impl Fn(&Run) -> Option<f64>) -> Option<f64> {
    let v: Option<Vec<f64>> = runs.iter().map(f).collect();
    v.filter(|v| !v.is_empty()).map(|v| median(&v))
}

fn mesh_section(
    doc: &mut Document,
    results: &Results,
    mesh: &str,
    opts: &ReportOptions,
    seed: u64,
    replayer: &mut Replayer<'_>,
) -> Result<(), ReportError> {
    let configs: Vec<(&Config, &[Run])> = results.configs_of(mesh).collect();
    let first = &configs[0].1[0];
    doc.heading(2, format!("Mesh {mesh}"));
    let opt = optimum_of(results, mesh);
    doc.para(format!(
        "{} triangles (mesh hash {}). Optimum quality (maximum-weight matching): {}.",
        first.triangles,
        &first.mesh_hash[..first.mesh_hash.len().min(16)],
        opt.map_or("not recorded".to_string(), |q| format!("{q:.4}")),
    ));

    // Table 1.
    doc.heading(3, "Results (medians)");
    let rows: Vec<Vec<String>> = configs
        .iter()
        .map(|(c, runs)| {
            vec![
                c.algo.clone(),
                c.horizon.map_or("–".into(), |h| h.to_string()),
                runs.len().to_string(),
                fmt_opt(median_opt(runs, |r| r.quality_pct), 2),
                format!("{:.2}", median(&Metric::Recombined.values(runs))),
                fmt_sig(median(&Metric::Time.values(runs)), 3),
                fmt_sig(
                    median(&runs.iter().map(results::nodes_per_tree).collect::<Vec<_>>()),
                    3,
                ),
                fmt_opt(median_opt(runs, |r| r.branching_factor), 3),
            ]
        })
        .collect();
    doc.table(
        [
            "algorithm",
            "horizon",
            "runs",
            "quality (% of optimum)",
            "recombined (%)",
            "time (s)",
            "nodes per tree",
            "branching factor",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    );
    doc.para(
        "Medians over the runs of each configuration. Quality is the sum of eta over the quads as \
         a percentage of the optimum; recombined is the percentage of triangles merged into \
         quads; time is the search's wall time; nodes per tree is tree nodes expanded per \
         look-ahead tree (a selective decision whose root triangle has a single allowed action \
         builds none); the branching factor is the runner's effective branching factor, the b \
         with 1 + b + ... + b^(h-1) = nodes per tree (none at h = 1). Both measure the search \
         as run: the selective tree cuts, by exact branch and bound, the subtrees that cannot \
         hold the best leaf, so it expands fewer nodes than the tree it explores (whose \
         decisions are unchanged), and its time grows more slowly with the horizon.",
    );

    element_table(doc, &configs);
    paper_beside(doc, mesh, &configs);
    box_plots(doc, mesh, &configs)?;
    if opts.pictures {
        pictures(doc, mesh, &configs, opts, replayer)?;
    }

    doc.heading(3, "Statistical comparisons");
    let mut families: Vec<Family> = significance::consecutive_horizons(&configs, seed);
    families.extend(significance::against_greedy(&configs, seed));
    if families.is_empty() {
        doc.para("Nothing to compare: no two horizons of one algorithm and no greedy runs.");
    }
    family_blocks(doc, &families);
    Ok(())
}

/// The element quality of each configuration beside its sum: a high sum with many
/// triangles left, or with near-degenerate quads, is not a better mesh.
fn element_table(doc: &mut Document, configs: &[(&Config, &[Run])]) {
    if configs.iter().all(|(_, runs)| runs[0].mean_eta.is_none()) {
        return;
    }
    doc.heading(3, "Element quality (medians)");
    let count = |f: fn(&Run) -> Option<usize>| move |r: &Run| f(r).map(|n| n as f64);
    let rows: Vec<Vec<String>> = configs
        .iter()
        .map(|(c, runs)| {
            vec![
                c.algo.clone(),
                c.horizon.map_or("–".into(), |h| h.to_string()),
                fmt_opt(median_opt(runs, |r| r.mean_eta), 4),
                fmt_opt(median_opt(runs, |r| r.worst_eta), 4),
                fmt_opt(median_opt(runs, count(|r| r.quads_eta_below_0_1)), 1),
                fmt_opt(median_opt(runs, count(|r| r.quads_eta_below_0_3)), 1),
                format!(
                    "{}",
                    median(
                        &runs
                            .iter()
                            .map(|r| r.triangles_left as f64)
                            .collect::<Vec<_>>()
                    )
                ),
            ]
        })
        .collect();
    doc.table(
        [
            "algorithm",
            "horizon",
            "mean eta per quad",
            "worst eta",
            "quads with eta < 0.1",
            "quads with eta < 0.3",
            "triangles left",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    );
    doc.para(
        "The quality percentage above sums eta over the quads made; these say what those quads          are: the mean eta per quad, the worst quad, and how many are poor, beside the triangles          left unrecombined (which count nothing in the sum). A policy that makes fewer quads          can reach a similar sum with a higher mean and more triangles left: compare the          columns together.",
    );
}

/// Summary sentences and a table per family.
fn family_blocks(doc: &mut Document, families: &[Family]) {
    for f in families {
        doc.para(f.summary());
        doc.table(
            significance::header(),
            f.pairs.iter().map(|p| p.row()).collect(),
        );
    }
}

/// The paper's numbers beside ours, for meshes the paper has a case for.
/// The tree algorithms among `configs` (those with a horizon), each once, in order.
fn tree_algos<'c>(configs: &[(&'c Config, &[Run])]) -> Vec<&'c str> {
    let mut algos: Vec<&str> = configs
        .iter()
        .filter(|(c, _)| c.horizon.is_some())
        .map(|(c, _)| c.algo.as_str())
        .collect();
    algos.dedup();
    algos
}

fn paper_beside(doc: &mut Document, mesh: &str, configs: &[(&Config, &[Run])]) {
    let Some(case) = paper::case_for(mesh) else {
        return;
    };
    doc.heading(3, "Beside the paper's numbers");
    doc.para(format!(
        "The paper's numbers were measured on a different mesh ({}; ours has {} triangles) and \
         different hardware ({}); they show what to expect, not what must match.",
        case.mesh,
        configs[0].1[0].triangles,
        paper::PAPER_MACHINE
    ));
    let find = |algo: &str, h: Option<u32>| {
        configs
            .iter()
            .find(|(c, _)| c.algo == algo && c.horizon == h)
            .map(|(_, r)| *r)
    };
    let mut rows = Vec::new();
    for p in case.rows {
        let ours = find(p.algo, p.horizon);
        let ours_med = |m: Metric| {
            ours.and_then(|r| match m {
                Metric::Quality => median_opt(r, |x| x.quality_pct),
                _ => Some(median(&m.values(r))),
            })
        };
        rows.push(vec![
            p.algo.to_string(),
            p.horizon.map_or("–".into(), |h| h.to_string()),
            fmt_opt(ours_med(Metric::Quality), 2),
            paper_number(p.quality_pct),
            fmt_opt(ours_med(Metric::Recombined), 2),
            paper_number(p.recombined_pct),
            ours_med(Metric::Time).map_or("–".into(), |t| fmt_sig(t, 3)),
            paper_number(p.time_s),
            p.source.to_string(),
        ]);
    }
    doc.table(
        [
            "algorithm",
            "horizon",
            "quality % (ours)",
            "quality % (paper)",
            "recombined % (ours)",
            "recombined % (paper)",
            "time s (ours)",
            "time s (paper)",
            "paper's source",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    );
    doc.list(case.notes.iter().map(|n| format!("Paper: {n}")).collect());
}

/// A number of the paper as printed there, or "–".
fn paper_number(v: Option<f64>) -> String {
    v.map_or("–".into(), |v| format!("{v}"))
}

/// Fig.-8-style box plots for each algorithm with horizons.
fn box_plots(
    doc: &mut Document,
    mesh: &str,
    configs: &[(&Config, &[Run])],
) -> Result<(), ReportError> {
    let algos = tree_algos(configs);
    if algos.is_empty() {
        return Ok(());
    }
    doc.heading(3, "Box plots against horizon");
    let greedy = configs.iter().find(|(c, _)| c.algo == "greedy");
    for algo in algos {
        let group: Vec<(u32, &[Run])> = configs
            .iter()
            .filter(|(c, _)| c.algo == algo)
            .filter_map(|(c, r)| c.horizon.map(|h| (h, *r)))
            .collect();
        for metric in Metric::ALL {
            let all: Vec<Run> = group.iter().flat_map(|(_, r)| r.iter().cloned()).collect();
            let name = metric.name(&all);
            let boxes: Vec<HorizonBox> = group
                .iter()
                .filter_map(|(h, r)| {
                    BoxStats::of(&metric.values(r)).map(|stats| HorizonBox { horizon: *h, stats })
                })
                .collect();
            let mut extras = Extras::default();
            if let Some((g, gr)) = greedy {
                if metric.name(gr) == name {
                    extras
                        .baselines
                        .push((g.label(), median(&metric.values(gr))));
                }
            }
            let mut caption = format!(
                "{mesh}, {algo}: {name} against horizon ({} runs per horizon). Red lines: medians; \
                 blue boxes: interquartile ranges; whiskers: most extreme runs within 1.5 IQR; \
                 red crosses: outliers.",
                group.iter().map(|(_, r)| r.len()).max().unwrap_or(0)
            );
            let log_y = metric == Metric::Time;
            if log_y {
                // The runner's growth fits (as in summary.json): log10(median time) on h over
                // every horizon, and over the upper half where the paper reads alpha.
                let growth = crate::experiment::summary::summarize(&all).growth;
                let entry = growth.iter().find(|g| g.algo == algo);
                extras.fit = entry.and_then(|g| g.upper.clone().or_else(|| g.all.clone()));
                caption.push_str(" Logarithmic axis.");
                if let Some(f) = &extras.fit {
                    caption.push_str(&format!(
                        " Green: least-squares fit of log10(median time) on h = {}..{}, slope {:.3} \
                         per horizon, branching factor alpha = 10^slope = {:.3}",
                        f.h_min, f.h_max, f.fit.slope, f.alpha
                    ));
                    if let Some(a) = entry.and_then(|g| g.all.as_ref()) {
                        caption.push_str(&format!(
                            " (over every horizon h = {}..{}: alpha = {:.3})",
                            a.h_min, a.h_max, a.alpha
                        ));
                    }
                    caption.push_str("; the paper reports 1.33 on its Borouchaki mesh.");
                }
            }
            let stem = format!("{}-{}-{}", mesh_slug(mesh), slug(algo), metric.key());
            let svg = boxplot_svg(
                &format!("{stem}-"),
                &format!("{mesh}: {algo}"),
                name,
                &boxes,
                log_y,
                &extras,
            )?;
            let file = format!("{FIGURES_DIR}/{stem}.svg");
            doc.figure(file, svg, caption);
        }
    }
    Ok(())
}

/// Fails when a configuration asked for with `--picture` matches none of the results'.
fn check_pictures(results: &Results, opts: &ReportOptions) -> Result<(), ReportError> {
    let name = |a: &str, h: Option<u32>| match h {
        Some(h) => format!("{a}:{h}"),
        None => a.to_string(),
    };
    for (a, h) in &opts.picture_configs {
        let found = results
            .groups
            .keys()
            .any(|c| c.algo == *a && (h.is_none() || *h == c.horizon));
        if !found {
            let mut held: Vec<String> = Vec::new();
            for c in results.groups.keys() {
                let n = name(&c.algo, c.horizon);
                if !held.contains(&n) {
                    held.push(n);
                }
            }
            return Err(ReportError::NoSuchPicture(name(a, *h), held.join(", ")));
        }
    }
    Ok(())
}

/// The configurations whose typical run is pictured.
fn picture_choice<'a>(
    configs: &[(&'a Config, &'a [Run])],
    opts: &ReportOptions,
) -> Vec<(&'a Config, &'a [Run])> {
    if !opts.picture_configs.is_empty() {
        return configs
            .iter()
            .filter(|(c, _)| {
                opts.picture_configs
                    .iter()
                    .any(|(a, h)| *a == c.algo && (h.is_none() || *h == c.horizon))
            })
            .copied()
            .collect();
    }
    let mut out: Vec<(&Config, &[Run])> = Vec::new();
    let algos = tree_algos(configs);
    for algo in algos {
        // The best median quality; the smallest horizon among equals (the cheapest to re-run).
        let mut best: Option<(&Config, &[Run], f64)> = None;
        for (c, r) in configs.iter().filter(|(c, _)| c.algo == algo) {
            let q = median(&Metric::Quality.values(r));
            if best.is_none_or(|b| q > b.2) {
                best = Some((c, r, q));
            }
        }
        out.extend(best.map(|(c, r, _)| (c, r)));
    }
    out
}

/// Pictures of typical (median-quality) runs, re-run from their seeds.
fn pictures(
    doc: &mut Document,
    mesh: &str,
    configs: &[(&Config, &[Run])],
    opts: &ReportOptions,
    replayer: &mut Replayer<'_>,
) -> Result<(), ReportError> {
    let chosen = picture_choice(configs, opts);
    if chosen.is_empty() {
        return Ok(());
    }
    doc.heading(3, "Typical runs");
    for (c, runs) in chosen {
        if c.algo == "optimum" {
            continue;
        }
        let Some(run) = typical::median_run(runs) else {
            continue;
        };
        let t = match typical::rerun(replayer, run) {
            Ok(t) => t,
            Err(why) => {
                doc.para(format!("No picture of {mesh} {}: {why}.", c.label()));
                continue;
            }
        };
        let mut views = vec![(None, "mesh")];
        if let Some(z) = opts.zoom {
            views.push((Some(z), "zoom"));
        }
        for (zoom, kind) in views {
            let popts = picture::PictureOptions {
                title: format!(
                    "{mesh}: {}, typical run{}",
                    c.label(),
                    if zoom.is_some() { " (zoom)" } else { "" }
                ),
                zoom,
                ..picture::PictureOptions::default()
            };
            let (svg, counts) = picture::mesh_svg(t.mesh, &t.rec, &popts)?;
            let mut caption = format!(
                "{mesh}: {} Quads coloured by eta (colour bar), leftover triangles in red; \
                 {} quads and {} leftover triangles drawn",
                t.note, counts.quads, counts.leftover
            );
            if counts.culled > 0 {
                caption.push_str(&format!(", {} back faces culled", counts.culled));
            }
            if let Some([x0, y0, x1, y1]) = zoom {
                caption.push_str(&format!(", window x {x0}..{x1}, y {y0}..{y1}"));
            }
            caption.push('.');
            let file = format!(
                "{FIGURES_DIR}/{}-{}-{kind}.svg",
                mesh_slug(mesh),
                slug(&c.label())
            );
            doc.figure(file, svg, caption);
        }
    }
    Ok(())
}

/// DIR against DIR2, configuration by configuration.
fn compare_section(doc: &mut Document, a: &Results, b: &Results, seed: u64) {
    doc.heading(
        2,
        format!(
            "Comparison: {} (first) vs {} (second)",
            a.dir.display(),
            b.dir.display()
        ),
    );
    let mut common: Vec<(&Config, &[Run], &[Run])> = Vec::new();
    let mut only_a = Vec::new();
    for (c, ra) in &a.groups {
        match b.groups.get(c) {
            Some(rb) => common.push((c, ra, rb)),
            None => only_a.push(format!("{} {}", c.mesh, c.label())),
        }
    }
    let only_b: Vec<String> = b
        .groups
        .keys()
        .filter(|c| !a.groups.contains_key(*c))
        .map(|c| format!("{} {}", c.mesh, c.label()))
        .collect();
    let mut notes = Vec::new();
    if !only_a.is_empty() {
        notes.push(format!("Only in the first: {}.", only_a.join(", ")));
    }
    if !only_b.is_empty() {
        notes.push(format!("Only in the second: {}.", only_b.join(", ")));
    }
    for (c, ra, rb) in &common {
        if ra[0].mesh_hash != rb[0].mesh_hash {
            notes.push(format!(
                "{}: the two directories used different meshes under the same name (hashes \
                 differ).",
                c.mesh
            ));
        }
        if ra[0].backend != rb[0].backend {
            notes.push(format!(
                "{} {}: eta came from different backends ({} vs {}).",
                c.mesh,
                c.label(),
                ra[0].backend,
                rb[0].backend
            ));
        }
    }
    notes.dedup();
    doc.list(notes);
    if common.is_empty() {
        doc.para("The two directories share no configuration: nothing to compare.");
        return;
    }
    let mut families = Vec::new();
    for metric in Metric::ALL {
        let sides: Vec<(String, &[Run], String, &[Run])> = common
            .iter()
            .map(|(c, ra, rb)| {
                let l = format!("{} {}", c.mesh, c.label());
                (format!("{l} (first)"), *ra, format!("{l} (second)"), *rb)
            })
            .collect();
        families.push(Family::build(
            format!("First vs second directory, {}", metric.key()),
            metric,
            sides,
            seed.wrapping_add(1000 * metric as u64),
        ));
    }
    family_blocks(doc, &families);
}

/// How the statistics were computed.
fn method_notes(doc: &mut Document) {
    doc.heading(2, "Methods");
    doc.list(vec![
        "Box plots: quartiles interpolate linearly between order statistics (type 7); whiskers \
         reach the most extreme run within 1.5 IQR of the box; runs beyond are outliers."
            .to_string(),
        format!(
            "Differences between two sets of runs: two-sided Mann–Whitney U test (exact \
             distribution when the smaller sample has at most {} runs and there are no ties, \
             otherwise the normal approximation with tie and continuity corrections). Against a \
             configuration run once (a deterministic baseline such as greedy with one baseline \
             run), one value is not a sample to rank against: the other side is tested against \
             that value with the two-sided Wilcoxon signed-rank test (T+; exact for at most {} \
             differences without ties or zeros, otherwise normal with tie and continuity \
             corrections). p-values of one family (one question, one measure) are corrected \
             with Holm's step-down method; significant means Holm p < {}.",
            crate::stats::compare::EXACT_MAX_SIZE,
            crate::stats::compare::EXACT_MAX_SIGNED_RANK,
            significance::ALPHA
        ),
        "Effect size: Vargha–Delaney A = P(first > second) + P(equal)/2; |A - 0.5| of at least \
         0.06, 0.14, 0.21 (A = 0.56, 0.64, 0.71) is a small, medium, large effect."
            .to_string(),
        format!(
            "Median difference: 95% percentile bootstrap interval from {} seeded resamples \
             (ChaCha8).",
            crate::stats::compare::BOOTSTRAP_RESAMPLES
        ),
        "Branching factor of the time plots: least-squares slope of log10(median time) over \
         the upper half of the horizons; alpha = 10^slope, the growth factor per horizon of \
         the paper's n alpha^h complexity."
            .to_string(),
    ]);
}
