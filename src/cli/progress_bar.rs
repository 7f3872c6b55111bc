//! Feedback on long `recombine` runs: a warning when the measured cost says the run will be
//! long, and a progress bar once it has lasted a couple of seconds (stderr; indicatif draws
//! nothing when stderr is not a terminal). The library reports through a callback
//! ([`Searcher::set_progress`]) and prints nothing.

use indicatif::{ProgressBar, ProgressStyle};
use quadrecomb::internals::search::{Params, Progress, Searcher};

/// A run estimated to last longer than this gets a warning.
const WARN_ABOVE_S: f64 = 60.0;
/// Estimates are made once the run has lasted this long.
const ESTIMATE_AFTER_S: f64 = 1.0;
/// The bar appears once the run has lasted this long.
const BAR_AFTER_S: f64 = 2.0;
/// The bar is updated at most this often.
const REDRAW_S: f64 = 0.1;

/// The run's total time extrapolated from its progress so far (triangles recombined per
/// second), or `None` before anything is recombined.
pub fn estimate_s(p: &Progress) -> Option<f64> {
    (p.recombined > 0).then(|| p.elapsed_s * p.triangles as f64 / p.recombined as f64)
}

/// What makes a run faster, ending its [`cost_warning`]: `--horizon` (or `--horizons` in a
/// sweep) for the tree methods, `--budget(s)` for the budgeted ones, nothing for greedy.
pub fn faster_hint(params: Params, plural: bool) -> String {
    let s = if plural { "s" } else { "" };
    match (params.horizon, params.budget) {
        (Some(_), _) => format!("; a lower --horizon{s} is faster"),
        (None, Some(_)) => format!("; a lower --budget{s} is faster"),
        (None, None) => String::new(),
    }
}

/// The warning for a run whose estimated total passes [`WARN_ABOVE_S`], with what the
/// estimate rests on: the mean tree size and the branching factor it implies over `horizon`
/// levels (`b^h` nodes per tree); `hint` ends it ([`faster_hint`]).
pub fn cost_warning(p: &Progress, horizon: Option<u32>, hint: &str) -> Option<String> {
    let Some(total) = estimate_s(p) else {
        // Still in the first tree: its size so far is all there is to go by.
        return (p.nodes > 0 && p.elapsed_s >= ESTIMATE_AFTER_S).then(|| {
            format!(
                "warning: the first look-ahead tree has expanded {} nodes in {:.1} s and is \
                 not done; up to {} decisions follow{}: this run will be long{hint}",
                p.nodes,
                p.elapsed_s,
                p.triangles / 2,
                horizon.map_or(String::new(), |h| format!(
                    ", each with a tree of horizon {h}"
                ))
            )
        });
    };
    if total <= WARN_ABOVE_S {
        return None;
    }
    let mut why = format!(
        "{:.1} % recombined in {:.1} s",
        100.0 * p.recombined as f64 / p.triangles as f64,
        p.elapsed_s
    );
    // Uniform h = 1 runs greedy, which counts its trees (one per quad) only at the end.
    let trees = if p.trees > 0 {
        p.trees
    } else {
        p.recombined as u64 / 2
    };
    if let (Some(h), true) = (horizon, trees > 0) {
        let size = p.nodes as f64 / trees as f64;
        let b = size.powf(1.0 / f64::from(h.max(1)));
        why += &format!(
            "; {size:.0} tree nodes per decision, a branching factor of about {b:.2} over \
             {h} levels: each level more multiplies the time by about {b:.2}"
        );
    }
    Some(format!(
        "warning: this run should take about {} at its pace so far, longer if its later trees \
         are larger ({why}){hint}",
        duration(total)
    ))
}

fn duration(s: f64) -> String {
    if s < 120.0 {
        format!("{s:.0} s")
    } else if s < 7200.0 {
        format!("{:.0} min", s / 60.0)
    } else {
        format!("{:.1} h", s / 3600.0)
    }
}

/// Attaches the warning and the bar to `searcher`'s runs; the returned bar is to be
/// cleared ([`ProgressBar::finish_and_clear`]) when the run ends.
pub fn attach(searcher: &mut Searcher<'_>, params: Params) -> ProgressBar {
    let (horizon, hint) = (params.horizon, faster_hint(params, false));
    let bar = ProgressBar::hidden();
    let shown = bar.clone();
    let mut warned = false;
    let mut visible = false;
    let mut drawn_at = f64::NEG_INFINITY;
    searcher.set_progress(move |p| {
        // Estimated at every report once the run has lasted a second (the later trees can
        // be the larger ones), said once.
        if !warned
            && p.elapsed_s >= ESTIMATE_AFTER_S
            && let Some(w) = cost_warning(p, horizon, &hint)
        {
            warned = true;
            shown.suspend(|| noteln!("{w}"));
        }
        // Reports come every few hundred tree nodes; the bar is redrawn at most every
        // REDRAW_S.
        if p.elapsed_s < BAR_AFTER_S || p.elapsed_s < drawn_at + REDRAW_S {
            return;
        }
        drawn_at = p.elapsed_s;
        if !visible {
            visible = true;
            shown.set_length(p.triangles as u64);
            shown.set_style(
                ProgressStyle::with_template(
                    "{elapsed_precise} [{bar:40}] {pos}/{len} triangles recombined, {msg}, \
                     about {eta} left",
                )
                .expect("a valid template")
                .progress_chars("=> "),
            );
            shown.set_draw_target(indicatif::ProgressDrawTarget::stderr());
        }
        shown.set_message(format!("{} trees, {} nodes", p.trees, p.nodes));
        shown.set_position(p.recombined as u64);
    });
    bar
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(recombined: usize, elapsed_s: f64) -> Progress {
        Progress {
            triangles: 2000,
            recombined,
            trees: 100,
            nodes: 100 * 1024,
            elapsed_s,
        }
    }

    const H: &str = "; a lower --horizon is faster";

    #[test]
    fn the_hint_names_the_knob() {
        let p = |horizon, budget| Params { horizon, budget };
        assert_eq!(faster_hint(p(Some(3), None), false), H);
        assert_eq!(
            faster_hint(p(Some(3), None), true),
            "; a lower --horizons is faster"
        );
        assert_eq!(
            faster_hint(p(None, Some(64)), true),
            "; a lower --budgets is faster"
        );
        assert_eq!(faster_hint(p(None, None), false), "");
    }

    #[test]
    fn long_runs_are_estimated_and_warned_about() {
        assert_eq!(estimate_s(&at(0, 1.0)), None);
        assert_eq!(estimate_s(&at(20, 1.0)), Some(100.0));
        assert_eq!(
            cost_warning(&at(200, 1.0), Some(10), H),
            None,
            "10 s is fine"
        );
        let w = cost_warning(&at(20, 1.0), Some(10), H).expect("100 s is long");
        assert!(
            w.contains("about 100 s at its pace so far") && w.ends_with(H),
            "{w}"
        );
        assert!(w.contains("1024 tree nodes per decision"), "{w}");
        // 1024 = 2^10: a branching factor of 2 over 10 levels.
        assert!(
            w.contains("branching factor of about 2.00 over 10 levels"),
            "{w}"
        );
        let w = cost_warning(&at(2, 10.0), None, "").expect("10,000 s");
        assert!(w.contains("about 2.8 h") && !w.contains("branching"), "{w}");
        assert!(w.ends_with(')'), "greedy has no knob to lower: {w}");
        // Nothing recombined yet, a tree running for seconds: said too.
        let w = cost_warning(&at(0, 3.0), Some(100), H).expect("a first tree of 3 s");
        assert!(
            w.contains("first look-ahead tree") && w.contains("horizon 100") && w.ends_with(H),
            "{w}"
        );
        assert_eq!(
            cost_warning(&at(0, 0.5), Some(100), H),
            None,
            "too early to tell"
        );
    }
}
