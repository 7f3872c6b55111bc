//! Reports: tables, box plots, mesh pictures and statistical comparisons from sweep results.
//!
//! [`write()`] reads a results directory (`runs.jsonl`, `manifest.json`) and writes `report.md`,
//! `report.html` (plots inlined, mesh pictures shown from their files) and the figures as SVG files under `figures/`. The report
//! holds, per mesh: a Table-1-style table (median quality % of optimum, recombined %, time,
//! nodes per tree per algorithm and horizon), the paper's own numbers beside ours, Fig.-8-style
//! box plots against horizon with the fitted branching factor, pictures of typical runs, and
//! Mann–Whitney/Holm/Vargha–Delaney/bootstrap comparisons of consecutive horizons and against
//! greedy; with [`ReportOptions::compare`], also one directory against another.

mod across;
mod beside_paper;
mod box_plots;
mod budget;
mod cd_diagram;
mod compare;
mod document;
mod finished;
mod format;
mod mesh_section;
mod methods;
mod overview;
pub mod paper;
pub mod picture;
mod pictures;
pub mod plots;
pub mod results;
pub mod significance;
mod summarized;
mod time_budget;
pub mod typical;

pub use document::{Block, Document};
pub use results::{Config, Metric, Results, Run};

use crate::experiment::replay::Replayer;
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
    /// `--baseline` names no method of the results.
    #[error("--baseline {0:?}: no such method in these results (they hold: {1})")]
    NoSuchBaseline(String, String),
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
    /// The method the "Across meshes" section compares every other with, as the report names
    /// it (e.g. "selective h=1"); `None`: selective h=1 if run on every mesh, else the first
    /// method that was.
    pub baseline: Option<String>,
}

impl Default for ReportOptions {
    fn default() -> Self {
        ReportOptions {
            compare: None,
            zoom: None,
            pictures: true,
            picture_configs: Vec::new(),
            seed: 0x5EED_2026,
            baseline: None,
        }
    }
}

/// The files a report wrote.
#[derive(Debug, Clone)]
pub struct ReportPaths {
    /// `report.md`.
    pub markdown: PathBuf,
    /// `report.html` (plots inlined, mesh pictures shown from `figures/`).
    pub html: PathBuf,
    /// SVG figures under `figures/`.
    pub figures: Vec<PathBuf>,
    /// `across_meshes.csv`, the per-mesh medians, written for two or more meshes.
    pub across_csv: Option<PathBuf>,
    /// What the report says that its reader should hear at once (an incomplete sweep, a
    /// torn last line), one line each.
    pub warnings: Vec<String>,
}

pub use crate::experiment::engine::FIGURES_DIR;

/// Reads `dir`'s results and writes `dir/report.md`, `dir/report.html` and `dir/figures/*.svg`.
pub fn write(dir: &Path, opts: &ReportOptions) -> Result<ReportPaths, ReportError> {
    let results = Results::read(dir)?;
    // Before anything is written: a file where the figures go would stop the report halfway.
    let fig_dir = dir.join(FIGURES_DIR);
    if let Ok(meta) = std::fs::metadata(&fig_dir)
        && !meta.is_dir()
    {
        return Err(ReportError::NotResults {
            dir: dir.to_path_buf(),
            why: format!(
                "{FIGURES_DIR} is {}, where the report writes its figures directory: rename or \
                 remove it",
                crate::mesh::file_kind(&meta)
            ),
        });
    }
    // A file the report writes that is a symbolic link to where no file can be made: the
    // write through it would fail after the pictures' runs.
    let reads = [
        crate::experiment::store::RUNS_FILE,
        crate::experiment::manifest::MANIFEST_FILE,
    ];
    for name in crate::experiment::engine::SWEEP_FILES
        .iter()
        .filter(|n| !reads.contains(n))
    {
        if let Some(target) = crate::output::dead_end_link(&dir.join(name)) {
            return Err(ReportError::NotResults {
                dir: dir.to_path_buf(),
                why: format!(
                    "{name} is a symbolic link to {}, where no file can be made: fix or remove \
                     the link",
                    target.display()
                ),
            });
        }
    }
    // The summary follows the runs it is made of (it was left stale after an edit).
    let summary = crate::experiment::summary::write(dir, &results.runs())?;
    let other = match &opts.compare {
        Some(d) => Some(Results::read(d)?),
        None => None,
    };
    let doc = build(&results, &summary, other.as_ref(), opts)?;
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| ReportError::Io { path, source }
    };
    std::fs::create_dir_all(&fig_dir).map_err(io(&fig_dir))?;
    let earlier = crate::experiment::engine::report_files(dir)?;
    let mut figures = Vec::new();
    let mut list = String::new();
    // The per-mesh medians (two or more meshes); a stale one of an earlier report goes.
    let across_path = dir.join(across::ACROSS_CSV);
    let across_csv = match across::csv(&results, &summary) {
        Some(csv) => {
            crate::output::write_bytes(&across_path, csv.as_bytes()).map_err(io(&across_path))?;
            Some(across_path)
        }
        None => {
            let _ = std::fs::remove_file(&across_path);
            None
        }
    };
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
        warnings: overview::warnings(&results),
        markdown,
        html,
        figures,
        across_csv,
    })
}

/// Builds the report of `results`, whose summary is `summary`
/// ([`crate::experiment::summary::summarize`] of its runs), compared with `other` if given,
/// without writing anything.
pub fn build(
    results: &Results,
    summary: &crate::experiment::summary::Summary,
    other: Option<&Results>,
    opts: &ReportOptions,
) -> Result<Document, ReportError> {
    pictures::check_pictures(results, opts)?;
    across::check_baseline(results, opts)?;
    let mut doc = Document::default();
    doc.heading(1, format!("quadrecomb report: {}", results.dir.display()));
    overview::overview(&mut doc, results);
    let mut replayer = Replayer::new(&results.dir, results.manifest.as_ref());
    for (i, mesh) in results.meshes.iter().enumerate() {
        mesh_section::mesh_section(
            &mut doc,
            results,
            summary,
            mesh,
            opts,
            opts.seed.wrapping_add(100_000 * i as u64),
            &mut replayer,
        )?;
    }
    across::across_meshes(&mut doc, results, summary, opts)?;
    if let Some(other) = other {
        compare::compare_section(&mut doc, results, other, opts.seed.wrapping_add(7_777_777));
    }
    methods::method_notes(&mut doc);
    Ok(doc)
}
