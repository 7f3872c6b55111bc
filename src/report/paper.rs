//! The numbers the paper reports (Table 1, Sections 4 and 6.2, Figs. 4, 6, 7 and 8), to be shown
//! beside ours. They were measured on the authors' meshes (a 2,152-triangle sphere, a
//! 34,562-triangle Borouchaki mesh generated with delquad) and hardware (MacBook Pro Retina, Mid
//! 2012), not on ours: the report labels them so.

/// One configuration's numbers in the paper; `None` where the paper gives none.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperRow {
    /// Algorithm name in our terms.
    pub algo: &'static str,
    /// Horizon, for the look-ahead policies.
    pub horizon: Option<u32>,
    /// Quality, % of the Blossom-quad optimum.
    pub quality_pct: Option<f64>,
    /// % of triangles recombined.
    pub recombined_pct: Option<f64>,
    /// Time in seconds.
    pub time_s: Option<f64>,
    /// Where the numbers come from and what they are (median, single run, ...).
    pub source: &'static str,
}

/// The paper's test case a mesh corresponds to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperCase {
    /// Description of the paper's mesh.
    pub mesh: &'static str,
    /// Triangles of the paper's mesh.
    pub triangles: usize,
    /// The reported numbers.
    pub rows: &'static [PaperRow],
    /// Further statements of the paper about this case.
    pub notes: &'static [&'static str],
}

/// Where the paper's timings were measured.
pub const PAPER_MACHINE: &str = "MacBook Pro Retina, Mid 2012";

/// The sphere (Section 4, Section 6.1, Table 1, Figs. 4 and 6).
pub const SPHERE: PaperCase = PaperCase {
    mesh: "sphere of 2,152 triangles",
    triangles: 2152,
    rows: &[
        PaperRow {
            algo: "uniform",
            horizon: Some(1),
            quality_pct: Some(87.6),
            recombined_pct: Some(86.0),
            time_s: Some(0.16),
            source: "Table 1 (one run; Fig. 4b: 1,850 triangles recombined)",
        },
        PaperRow {
            algo: "uniform",
            horizon: Some(2),
            quality_pct: Some(85.1),
            recombined_pct: Some(82.7),
            time_s: Some(225.6),
            source: "Table 1 (one run; Fig. 4c: 1,780 triangles recombined)",
        },
        PaperRow {
            algo: "selective",
            horizon: Some(1),
            quality_pct: Some(91.8),
            recombined_pct: Some(98.2),
            time_s: Some(0.037),
            source: "Table 1 (median of 100 runs)",
        },
        PaperRow {
            algo: "selective",
            horizon: Some(2),
            quality_pct: Some(92.8),
            recombined_pct: Some(98.3),
            time_s: Some(0.084),
            source: "Table 1 (median of 100 runs)",
        },
        PaperRow {
            algo: "selective",
            horizon: Some(3),
            quality_pct: Some(94.0),
            recombined_pct: Some(98.7),
            time_s: Some(0.146),
            source: "Table 1 (median of 100 runs)",
        },
    ],
    notes: &[
        "Fig. 6 shows one selective h=3 run with 2,120 of 2,152 triangles recombined and a quality of 93.8%.",
        "The paper could not run the uniform look-ahead tree beyond h=2 on its machine.",
    ],
};

/// The Borouchaki–Frey test case (Section 6.2, Figs. 7 and 8).
pub const BOROUCHAKI: PaperCase = PaperCase {
    mesh: "Borouchaki mesh of 34,562 triangles (delquad; optimum quality 10,451.61)",
    triangles: 34562,
    rows: &[
        PaperRow {
            algo: "greedy-nocrit",
            horizon: None,
            quality_pct: None,
            // 2 * 15,472 / 34,562 triangles = 89.53%.
            recombined_pct: Some(89.53),
            time_s: Some(0.98),
            source: "Section 6.2: 15,472 recombinations; quality not comparable (isolated triangles left)",
        },
        PaperRow {
            algo: "greedy",
            horizon: None,
            quality_pct: Some(88.5),
            recombined_pct: Some(86.0),
            time_s: Some(1.32),
            source: "Section 6.2: greedy with the criterion of Definition 2",
        },
        PaperRow {
            algo: "selective",
            horizon: Some(1),
            quality_pct: None,
            recombined_pct: None,
            time_s: Some(1.6),
            source: "Section 6.2: \"around 1.6 s\"",
        },
        PaperRow {
            algo: "selective",
            horizon: Some(2),
            quality_pct: None,
            recombined_pct: None,
            time_s: Some(3.4),
            source: "Section 6.2",
        },
        PaperRow {
            algo: "selective",
            horizon: Some(5),
            quality_pct: Some(93.17),
            recombined_pct: Some(98.8),
            time_s: None,
            source: "Fig. 7: one typical run, not a median",
        },
    ],
    notes: &[
        "Fig. 8: quality and recombinations increase significantly from h=1 to h=6 (128 runs per horizon, h=1..10).",
        "Fig. 8: at high horizons time grows with slope 0.49 per 4 horizons in log10, a branching factor of 10^(0.49/4) = 1.33.",
    ],
};

/// The paper's case for a mesh of ours, recognised by name ("sphere", "borouchaki").
pub fn case_for(mesh: &str) -> Option<&'static PaperCase> {
    let name = mesh.to_ascii_lowercase();
    if name.contains("borouchaki") {
        Some(&BOROUCHAKI)
    } else if name.contains("sphere") {
        Some(&SPHERE)
    } else {
        None
    }
}
