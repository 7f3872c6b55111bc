//! Merging the results directories of shards of one sweep, or of sweeps that extend each other.
//!
//! The parts must agree on the version, backend, meshes, base seed, rule and plan version;
//! their configurations may differ (a directory and its extension, shards of sweeps with other
//! horizons): the merged directory's is their union, and together the parts must hold every run
//! of its run list. Shards of one configuration hold disjoint runs; a run that parts of
//! different configurations share is the same run (all fields but time) and is kept once, from
//! the first part given. The merged directory gets the runs in canonical order, a manifest
//! naming the parts and their machines, and a fresh summary.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::ExperimentError;
use super::engine::check_records;
use super::manifest::{MANIFEST_FILE, Manifest, MergedPart};
use super::plan::plan;
use super::record::{RunKey, RunRecord};
use super::store::{self, RUNS_FILE};
use super::summary;

/// What a merge wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Merged {
    /// Records written.
    pub records: usize,
    /// Parts merged.
    pub parts: usize,
}

/// Merges `parts` into `out` (which must not hold runs already).
pub fn merge(parts: &[PathBuf], out: &Path) -> Result<Merged, ExperimentError> {
    if parts.is_empty() {
        return Err(ExperimentError::Merge("no directories to merge".into()));
    }
    if let Ok(meta) = std::fs::metadata(out)
        && !meta.is_dir()
    {
        return Err(ExperimentError::NotADirectory {
            dir: out.to_path_buf(),
            kind: crate::mesh::file_kind(&meta).to_string(),
        });
    }
    for (i, p) in parts.iter().enumerate() {
        let canonical = |q: &Path| std::fs::canonicalize(q).ok();
        let same = |q: &PathBuf| q == p || canonical(q).is_some_and(|c| Some(c) == canonical(p));
        if let Some(q) = parts[..i].iter().find(|q| same(q)) {
            let also = if q == p {
                String::new()
            } else {
                format!(" (also as {})", q.display())
            };
            return Err(ExperimentError::Merge(format!(
                "{}: given twice{also}",
                p.display()
            )));
        }
    }
    let mut manifests = Vec::new();
    for p in parts {
        if !p.is_dir() {
            let why = if p.exists() {
                "not a directory (give a sweep's results directory)"
            } else {
                "no such results directory"
            };
            return Err(ExperimentError::Merge(format!("{}: {why}", p.display())));
        }
        super::store::refuse_irregular(&p.join(MANIFEST_FILE))?;
        if !p.join(MANIFEST_FILE).is_file() {
            return Err(ExperimentError::Merge(format!(
                "{}: not a sweep's results directory (no {MANIFEST_FILE})",
                p.display()
            )));
        }
        manifests.push(Manifest::read(p)?);
    }
    let first = &manifests[0];
    for (p, m) in parts.iter().zip(&manifests).skip(1) {
        // Shards of one configuration are cut from one run list with one shard count.
        if let (Some(a), Some(b)) = (first.shard, m.shard)
            && a.count != b.count
            && first.spec == m.spec
        {
            return Err(ExperimentError::Merge(format!(
                "{} is shard {}/{} but {} is shard {}/{}: shards of one sweep are cut with the same shard count",
                parts[0].display(),
                a.index,
                a.count,
                p.display(),
                b.index,
                b.count
            )));
        }
        if let Some(why) = first.base_incompatibility(m) {
            return Err(ExperimentError::Merge(format!(
                "{} and {} are not parts of the same sweep: {why}",
                parts[0].display(),
                p.display()
            )));
        }
        for (a, b) in first.optimum.iter().zip(&m.optimum) {
            if a.eta_hash != b.eta_hash {
                return Err(ExperimentError::Merge(format!(
                    "{} and {} computed the optimum of {} from different eta",
                    parts[0].display(),
                    p.display(),
                    a.mesh
                )));
            }
        }
    }
    // A time budget calibrated twice into different knobs made different runs under one
    // name: such parts are not one sweep (the union would keep one calibration and lose the
    // other's runs).
    for (i, m) in manifests.iter().enumerate().skip(1) {
        for (j, earlier) in manifests[..i].iter().enumerate() {
            if let Some(why) = calibration_conflict(&earlier.spec, &m.spec) {
                return Err(ExperimentError::Merge(format!(
                    "{} and {} are not parts of the same sweep: {why} (each calibration makes its \
                     own runs; merge only parts made from one calibration, such as a directory \
                     and its --resume or --extend)",
                    parts[j].display(),
                    parts[i].display()
                )));
            }
        }
    }
    // Parts of different configurations (a directory and its extension, or shards of
    // sweeps that add horizons, algorithms or runs to each other) merge into the union of
    // their configurations; the runs they share are the same runs (same seeds).
    let mut spec = first.spec.clone();
    for m in &manifests[1..] {
        spec = super::manifest::union_spec(&spec, &m.spec);
    }
    super::config::check_size(
        spec.meshes.len(),
        &spec.algos,
        spec.horizons.len(),
        spec.budgets.len(),
        spec.time_budgets.len(),
        spec.runs,
        spec.baseline_runs,
    )
    .map_err(|e| ExperimentError::Merge(format!("the union of the parts' configurations: {e}")))?;
    let jobs = plan(&spec);
    let mut by_key: BTreeMap<RunKey, (RunRecord, String, usize)> = BTreeMap::new();
    let mut merged_from = Vec::new();
    for (i, (p, m)) in parts.iter().zip(&manifests).enumerate() {
        let loaded = store::read(&p.join(RUNS_FILE))?;
        if loaded.torn_bytes > 0 {
            return Err(ExperimentError::TornPart {
                path: p.join(RUNS_FILE),
            });
        }
        // Every record must be a run of its part's whole list with the right seed (a shard's
        // records are runs of the whole list too).
        check_records(p, m, &plan(&m.spec), &loaded)?;
        for (r, line) in loaded.records.iter().zip(&loaded.lines) {
            if let Some((earlier, _, j)) = by_key.get(&r.key()) {
                // Shards of one configuration are disjoint: a run in two of them means a
                // part given twice (or copied). Parts of different configurations overlap
                // where one extends the other; a shared run must be the same run.
                let (pj, pi) = (parts[*j].display(), p.display());
                if manifests[*j].spec == m.spec {
                    return Err(ExperimentError::Merge(format!(
                        "run {} is in both {pj} and {pi}",
                        r.key()
                    )));
                }
                if !earlier.same_result(r) {
                    return Err(ExperimentError::Merge(format!(
                        "run {} is in both {pj} and {pi} with different results (every field \
                         but time_s should agree)",
                        r.key()
                    )));
                }
                continue;
            }
            by_key.insert(r.key(), (r.clone(), line.clone(), i));
        }
        merged_from.push(MergedPart {
            dir: p.display().to_string(),
            shard: m.shard,
            machine: m.machine.clone(),
            records: loaded.records.len(),
            builds: m.builds(),
        });
    }
    let missing: Vec<RunKey> = jobs
        .iter()
        .map(|j| j.key(&spec))
        .filter(|k| !by_key.contains_key(k))
        .collect();
    if !missing.is_empty() {
        let list: Vec<String> = missing.iter().take(5).map(|k| k.to_string()).collect();
        let union = if manifests.iter().any(|m| m.spec != spec) {
            " of the union of the parts' configurations"
        } else {
            ""
        };
        return Err(ExperimentError::Merge(format!(
            "{} of {} runs{union} are missing (a shard not given, not finished, or cut with another shard count?), e.g.: {}",
            missing.len(),
            jobs.len(),
            list.join("; ")
        )));
    }

    // Every record must land in the merged directory: one the union does not plan would be
    // lost without a word.
    let planned: std::collections::BTreeSet<RunKey> = jobs.iter().map(|j| j.key(&spec)).collect();
    if let Some((key, (_, _, i))) = by_key.iter().find(|(k, _)| !planned.contains(k)) {
        return Err(ExperimentError::Merge(format!(
            "run {key} of {} is not a run of the union of the parts' configurations, so the \
             merged directory would lose it",
            parts[*i].display()
        )));
    }
    std::fs::create_dir_all(out).map_err(|e| ExperimentError::io(out, e))?;
    // One writer at a time, as for a sweep: a sweep or another merge writing `out` now is
    // refused, and none can start there until this merge ends.
    let _lock = super::lock::DirLock::acquire(out)?;
    let out_runs = out.join(RUNS_FILE);
    let existing = store::read(&out_runs)?;
    if !existing.records.is_empty() || existing.torn_bytes > 0 {
        return Err(ExperimentError::MergeTargetNotEmpty {
            dir: out.to_path_buf(),
            records: existing.records.len(),
        });
    }
    super::engine::refuse_foreign_files(out)?;
    let mut manifest = first.clone();
    manifest.spec = spec.clone();
    manifest.shard = None;
    manifest.threads = manifests.iter().map(|m| m.threads).max().unwrap_or(1);
    manifest.machine = super::manifest::Machine::current();
    manifest.merged_from = merged_from;
    // The merge runs nothing; its parts' builds are in `merged_from`.
    manifest.sessions = Vec::new();
    manifest.write(out)?;
    // The runs whole or not at all (a full disk leaves no runs, and the merge can be done
    // again): the manifest alone is a sweep with no runs yet.
    let mut records = Vec::with_capacity(jobs.len());
    let mut lines = Vec::with_capacity(jobs.len());
    for j in &jobs {
        let (r, line, _) = by_key.remove(&j.key(&spec)).expect("checked: none missing");
        lines.push(line);
        records.push(r);
    }
    crate::output::write_atomic(&out_runs, |w| {
        lines.iter().try_for_each(|line| writeln!(w, "{line}"))
    })
    .map_err(|e| ExperimentError::io(&out_runs, e))?;
    summary::write(out, &records)?;
    Ok(Merged {
        records: records.len(),
        parts: parts.len(),
    })
}

/// The first time budget that `a` and `b` calibrated into different knobs (same mesh, method,
/// given horizon and budget), in words.
fn calibration_conflict(
    a: &super::manifest::SweepSpec,
    b: &super::manifest::SweepSpec,
) -> Option<String> {
    use super::plan::has_budget;
    b.calibration.iter().find_map(|c| {
        let given = has_budget(&c.algo).then_some(c.horizon);
        let d = a
            .calibration
            .iter()
            .find(|d| d.is_for(&c.mesh, &c.algo, given, c.time_budget_s))?;
        let knob = |x: &super::calibrate::Calibrated| match x.budget {
            Some(n) => format!("node budget {n} at h={}", x.horizon),
            None => format!("horizon {}", x.horizon),
        };
        (d.knob() != c.knob() || d.horizon != c.horizon).then(|| {
            format!(
                "they calibrated the time budget {} s of {} on {} differently ({} vs {})",
                c.time_budget_s.seconds(),
                c.algo,
                c.mesh,
                knob(d),
                knob(c)
            )
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::engine::run;
    use crate::experiment::engine::tests::{manifest, opts};
    use crate::experiment::exec::tests::FakeFactory;
    use crate::experiment::manifest::Shard;
    use std::sync::atomic::AtomicBool;

    const OK: FakeFactory = FakeFactory { fail_on_run: None };

    fn sweep(dir: &Path, shard: Option<Shard>) {
        run(
            &manifest(shard),
            &OK,
            &opts(dir, 2, false),
            &AtomicBool::new(false),
            &mut |_| {},
        )
        .unwrap();
    }

    fn sorted(dir: &Path) -> Vec<RunRecord> {
        let mut r = store::read(&dir.join(RUNS_FILE)).unwrap().records;
        r.sort_by_key(|r| r.key());
        r
    }

    #[test]
    fn three_shards_merge_into_the_whole() {
        let tmp = tempfile::tempdir().unwrap();
        let whole = tmp.path().join("whole");
        sweep(&whole, None);
        let parts: Vec<PathBuf> = (1..=3)
            .map(|i| {
                let d = tmp.path().join(format!("s{i}"));
                sweep(&d, Some(Shard { index: i, count: 3 }));
                d
            })
            .collect();
        let out = tmp.path().join("merged");
        let m = merge(&parts, &out).unwrap();
        assert_eq!(m.records, 40);
        let a = sorted(&whole);
        let b = sorted(&out);
        assert_eq!(a.len(), b.len());
        assert!(a.iter().zip(&b).all(|(x, y)| x.same_result(y)));
        // Lines are copied byte for byte.
        let lines = |d: &Path| -> std::collections::BTreeSet<String> {
            std::fs::read_to_string(d.join(RUNS_FILE))
                .unwrap()
                .lines()
                .map(String::from)
                .collect()
        };
        let union: std::collections::BTreeSet<String> =
            parts.iter().flat_map(|p| lines(p)).collect();
        assert_eq!(lines(&out), union);
        let man = Manifest::read(&out).unwrap();
        assert_eq!(man.merged_from.len(), 3);
        assert!(man.shard.is_none());
        // The merged summary equals the whole sweep's except for times.
        let sa = std::fs::read_to_string(whole.join("summary.csv")).unwrap();
        let sb = std::fs::read_to_string(out.join("summary.csv")).unwrap();
        let strip = |s: &str| -> Vec<String> {
            s.lines()
                .filter(|l| !l.contains(",time_s,"))
                .map(String::from)
                .collect()
        };
        assert_eq!(strip(&sa), strip(&sb));
        // Merging again into the same directory is refused.
        assert!(matches!(
            merge(&parts, &out),
            Err(ExperimentError::MergeTargetNotEmpty { .. })
        ));
    }

    #[test]
    fn merge_rejects_missing_duplicated_and_foreign_parts() {
        let tmp = tempfile::tempdir().unwrap();
        let s: Vec<PathBuf> = (1..=3)
            .map(|i| {
                let d = tmp.path().join(format!("s{i}"));
                sweep(&d, Some(Shard { index: i, count: 3 }));
                d
            })
            .collect();
        let err = merge(&s[..2], &tmp.path().join("o1"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("runs are missing"), "{err}");
        let dup = vec![s[0].clone(), s[1].clone(), s[2].clone(), s[0].clone()];
        let err = merge(&dup, &tmp.path().join("o2")).unwrap_err().to_string();
        assert!(err.ends_with("s1: given twice"), "{err}");
        // A copy is another directory holding the same runs.
        let copy = tmp.path().join("copy");
        std::fs::create_dir(&copy).unwrap();
        for e in std::fs::read_dir(&s[0]).unwrap() {
            let e = e.unwrap();
            if e.file_type().unwrap().is_file() {
                std::fs::copy(e.path(), copy.join(e.file_name())).unwrap();
            }
        }
        let dup = vec![s[0].clone(), s[1].clone(), s[2].clone(), copy];
        let err = merge(&dup, &tmp.path().join("o2")).unwrap_err().to_string();
        assert!(err.contains("is in both"), "{err}");

        let other = tmp.path().join("other");
        let mut m = manifest(Some(Shard { index: 3, count: 3 }));
        m.spec.seed += 1;
        run(
            &m,
            &OK,
            &opts(&other, 1, false),
            &AtomicBool::new(false),
            &mut |_| {},
        )
        .unwrap();
        let err = merge(&[s[0].clone(), s[1].clone(), other], &tmp.path().join("o3"))
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("not parts of the same sweep") && err.contains("seed"),
            "{err}"
        );

        // A torn line in a part is named.
        let runs = s[2].join(RUNS_FILE);
        let mut text = std::fs::read(&runs).unwrap();
        text.truncate(text.len() - 3);
        std::fs::write(&runs, text).unwrap();
        let err = merge(&s, &tmp.path().join("o4")).unwrap_err().to_string();
        assert!(err.contains("torn line"), "{err}");
    }
}
