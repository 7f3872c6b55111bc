//! Extending a sweep (#27 item 6): `sweep --extend` adds horizons, algorithms and runs to a
//! results directory whose meshes, base seed and rule agree; `merge` of a directory and its
//! extension gives their union; `report --compare` of overlapping directories compares what
//! differs and names the rest.

use crate::runner::{assert_same, records, small_mesh, stderr, sweep, sweep_args, wait_for_lines};
use crate::util::{bin, run_in};
use quadrecomb::internals::experiment::manifest::Manifest;
use quadrecomb::internals::experiment::store;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

fn bytes(path: &Path) -> Vec<u8> {
    std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

/// The old run log is a prefix of the new one, byte for byte, and the new lines are new runs.
fn assert_prefix(old: &[u8], new: &[u8], what: &str) {
    assert!(
        new.len() > old.len() && new.starts_with(old),
        "{what}: the recorded lines were not kept byte for byte as the first lines"
    );
}

#[test]
fn extend_horizons_keeps_the_records_and_equals_a_fresh_sweep() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 300);
    let base = sweep(dir, &sweep_args(&mesh, "ext", 3, "1..2"), &[]);
    assert!(base.status.success(), "{}", stderr(&base));
    let old_runs = bytes(&dir.join("ext/runs.jsonl"));
    let old_manifest = bytes(&dir.join("ext/manifest.json"));

    // A plain --resume with more horizons is refused (results-directory conflict), says how
    // to extend, and changes nothing.
    let wider = sweep_args(&mesh, "ext", 3, "1..3");
    let refused = sweep(dir, &wider, &["--resume"]);
    assert_eq!(refused.status.code(), Some(4), "{}", stderr(&refused));
    assert!(
        stderr(&refused).contains("horizons [1, 2, 3] vs [1, 2]")
            && stderr(&refused).contains("pass --extend"),
        "{}",
        stderr(&refused)
    );
    assert_eq!(bytes(&dir.join("ext/runs.jsonl")), old_runs);
    assert_eq!(bytes(&dir.join("ext/manifest.json")), old_manifest);

    let extended = sweep(dir, &wider, &["--extend"]);
    assert!(extended.status.success(), "{}", stderr(&extended));
    let new_runs = bytes(&dir.join("ext/runs.jsonl"));
    assert_prefix(&old_runs, &new_runs, "extend 1..2 -> 1..3");
    let fresh = sweep(dir, &sweep_args(&mesh, "fresh", 3, "1..3"), &[]);
    assert!(fresh.status.success(), "{}", stderr(&fresh));
    let ext = records(&dir.join("ext"));
    // 3 horizons x 3 runs of selective + 2 greedy + 2 greedy-nocrit + 1 optimum.
    assert_eq!(ext.len(), 3 * 3 + 2 + 2 + 1);
    assert_same(&ext, &records(&dir.join("fresh")), "extended vs fresh 1..3");
    let m = Manifest::read(&dir.join("ext")).unwrap();
    assert_eq!(m.spec.horizons, vec![1, 2, 3]);
    assert_eq!(
        m.spec,
        Manifest::read(&dir.join("fresh")).unwrap().spec,
        "the manifest describes the extended sweep"
    );

    // The extended directory resumes with the extended command, as any sweep.
    let again = sweep(dir, &wider, &["--resume"]);
    assert!(again.status.success(), "{}", stderr(&again));
    assert_eq!(bytes(&dir.join("ext/runs.jsonl")), new_runs);
}

#[test]
fn extend_adds_an_algorithm_and_more_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 300);
    let algo = |args: &mut Vec<String>, algos: &[&str]| {
        args.push("--algo".into());
        args.extend(algos.iter().map(|a| a.to_string()));
    };

    // selective -> selective + uniform.
    let mut base = sweep_args(&mesh, "algo", 3, "1..2");
    algo(&mut base, &["selective"]);
    assert!(sweep(dir, &base, &[]).status.success());
    let old = bytes(&dir.join("algo/runs.jsonl"));
    let mut more = sweep_args(&mesh, "algo", 3, "1..2");
    algo(&mut more, &["selective", "uniform"]);
    let out = sweep(dir, &more, &["--extend"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_prefix(&old, &bytes(&dir.join("algo/runs.jsonl")), "add uniform");
    let mut fresh = sweep_args(&mesh, "algo-fresh", 3, "1..2");
    algo(&mut fresh, &["selective", "uniform"]);
    assert!(sweep(dir, &fresh, &[]).status.success());
    let a = records(&dir.join("algo"));
    // 2 horizons x (3 selective + 2 uniform, deterministic: --baseline-runs 2).
    assert_eq!(a.len(), 2 * (3 + 2));
    assert_same(
        &a,
        &records(&dir.join("algo-fresh")),
        "added uniform vs fresh",
    );

    // 3 -> 5 runs per configuration: runs 3 and 4 get their own seeds.
    let base = sweep_args(&mesh, "runs", 3, "1..2");
    assert!(sweep(dir, &base, &[]).status.success());
    let old = bytes(&dir.join("runs/runs.jsonl"));
    let out = sweep(dir, &sweep_args(&mesh, "runs", 5, "1..2"), &["--extend"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_prefix(&old, &bytes(&dir.join("runs/runs.jsonl")), "3 -> 5 runs");
    assert!(
        sweep(dir, &sweep_args(&mesh, "runs-fresh", 5, "1..2"), &[])
            .status
            .success()
    );
    let r = records(&dir.join("runs"));
    assert_eq!(r.len(), 2 * 5 + 2 + 2 + 1);
    assert_same(&r, &records(&dir.join("runs-fresh")), "5 runs vs fresh");
    let seeds: std::collections::BTreeSet<u64> = r.iter().map(|r| r.seed).collect();
    assert_eq!(seeds.len(), r.len(), "every run has its own seed");
}

#[test]
fn extend_refuses_what_would_change_or_drop_recorded_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 300);
    assert!(
        sweep(dir, &sweep_args(&mesh, "d", 5, "1..2"), &[])
            .status
            .success()
    );
    let runs = bytes(&dir.join("d/runs.jsonl"));
    let manifest = bytes(&dir.join("d/manifest.json"));
    let other_mesh = dir.join("other");
    std::fs::create_dir(&other_mesh).unwrap();
    let other_mesh = small_mesh(&other_mesh, 200);
    let with = |flag: &str, value: &str| {
        let mut a = sweep_args(&mesh, "d", 5, "1..3");
        let i = a.iter().position(|x| x == flag).unwrap();
        a[i + 1] = value.to_string();
        a
    };
    let mut rule = sweep_args(&mesh, "d", 5, "1..3");
    rule.extend(["--min-eta".to_string(), "0.2".to_string()]);
    let cases: Vec<(&str, Vec<String>, &str)> = vec![
        ("base seed", with("--seed", "7"), "seed 7 vs "),
        (
            "rule",
            rule,
            "rule valid quads, eta >= 0.2 vs valid quads (eta > 0)",
        ),
        (
            "mesh",
            with("--mesh", other_mesh.to_str().unwrap()),
            "meshes [small (",
        ),
        (
            "fewer runs",
            sweep_args(&mesh, "d", 3, "1..3"),
            "would leave out runs the directory's configuration plans, recorded or not yet \
             run: small selective h=1: runs 3..4; small selective h=2: runs 3..4",
        ),
        (
            "a horizon",
            sweep_args(&mesh, "d", 5, "2..3"),
            "small selective h=1: runs 0..4",
        ),
        (
            "fewer baseline runs",
            with("--baseline-runs", "1"),
            "small greedy: run 1; small greedy-nocrit: run 1",
        ),
    ];
    for (what, args, named) in cases {
        let out = sweep(dir, &args, &["--extend"]);
        assert_eq!(out.status.code(), Some(4), "{what}: {}", stderr(&out));
        assert!(
            stderr(&out).contains("cannot extend it") && stderr(&out).contains(named),
            "{what}: {}",
            stderr(&out)
        );
        assert_eq!(bytes(&dir.join("d/runs.jsonl")), runs, "{what}");
        assert_eq!(bytes(&dir.join("d/manifest.json")), manifest, "{what}");
    }
    // --extend slices no shard, and replaces nothing: usage errors.
    for extra in [
        &["--extend", "--shard", "1/2"][..],
        &["--extend", "--overwrite"],
    ] {
        let out = sweep(dir, &sweep_args(&mesh, "d", 5, "1..3"), extra);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {}", stderr(&out));
    }
}

#[test]
fn kill_9_during_an_extension_then_extend_again_equals_a_fresh_sweep() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 1000);
    assert!(
        sweep(dir, &sweep_args(&mesh, "k", 20, "1..2"), &[])
            .status
            .success()
    );
    let old = bytes(&dir.join("k/runs.jsonl"));
    let old_lines = old.iter().filter(|&&b| b == b'\n').count();
    let wider = sweep_args(&mesh, "k", 20, "1..6");
    let total = 6 * 20 + 2 + 2 + 1;
    let mut child = Command::new(bin())
        .args(&wider)
        .args(["--extend", "--threads", "2"])
        .current_dir(dir)
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let runs = dir.join("k/runs.jsonl");
    let seen = wait_for_lines(&runs, old_lines + 10, Duration::from_secs(60));
    child.kill().unwrap(); // SIGKILL
    child.wait().unwrap();
    let after = store::read(&runs).unwrap();
    assert!(seen >= old_lines + 10, "only {seen} lines before the kill");
    assert!(
        after.records.len() < total,
        "the extension finished before it was killed: make it longer"
    );
    assert!(bytes(&runs).starts_with(&old), "recorded lines kept");
    // The manifest is whole (old or new) and claims no run the log holds outside it.
    let m = Manifest::read(&dir.join("k")).unwrap();
    assert!(m.spec.horizons == vec![1, 2] || m.spec.horizons == (1..=6).collect::<Vec<_>>());

    let again = sweep(dir, &wider, &["--extend", "--threads", "2"]);
    assert!(again.status.success(), "{}", stderr(&again));
    assert!(
        sweep(
            dir,
            &sweep_args(&mesh, "kf", 20, "1..6"),
            &["--threads", "2"]
        )
        .status
        .success()
    );
    let k = records(&dir.join("k"));
    assert_eq!(k.len(), total);
    assert_same(&k, &records(&dir.join("kf")), "killed extension vs fresh");
}

#[test]
fn merge_of_a_sweep_and_its_extension_is_their_union() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 300);
    assert!(
        sweep(dir, &sweep_args(&mesh, "a", 3, "1..2"), &[])
            .status
            .success()
    );
    copy_dir(&dir.join("a"), &dir.join("b"));
    assert!(
        sweep(dir, &sweep_args(&mesh, "b", 3, "1..3"), &["--extend"])
            .status
            .success()
    );
    let out = run_in(dir, &["merge", "a", "b", "--out", "m", "--no-report"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(dir.join("m/runs.jsonl")).unwrap();
    let b = records(&dir.join("b"));
    assert_eq!(text.lines().count(), b.len(), "no run twice");
    assert_same(&records(&dir.join("m")), &b, "merge of a and its extension");
    let m = Manifest::read(&dir.join("m")).unwrap();
    assert_eq!(m.spec, Manifest::read(&dir.join("b")).unwrap().spec);
    assert_eq!(m.merged_from.len(), 2);
    // Either order gives the same union.
    let out = run_in(dir, &["merge", "b", "a", "--out", "m2", "--no-report"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_same(&records(&dir.join("m2")), &b, "merge b a");

    // Shards of a sweep of the new horizon alone merge with the first directory into the
    // extended sweep (a cluster extension).
    for i in 1..=2 {
        let mut args = sweep_args(&mesh, &format!("h3-{i}"), 3, "3");
        args.extend(["--algo".into(), "selective".into()]);
        let out = sweep(dir, &args, &["--shard", &format!("{i}/2")]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let out = run_in(
        dir,
        &["merge", "a", "h3-1", "h3-2", "--out", "m3", "--no-report"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_same(&records(&dir.join("m3")), &b, "a + shards of h=3");
    // Without one of those shards, the union misses runs and is refused.
    let out = run_in(dir, &["merge", "a", "h3-1", "--out", "m4", "--no-report"]);
    assert_eq!(out.status.code(), Some(3));
    assert!(
        stderr(&out).contains("of the union of the parts' configurations are missing"),
        "{}",
        stderr(&out)
    );

    // A shared run whose results differ is refused, naming the run.
    let lines: Vec<String> = text.lines().map(String::from).collect();
    let mut edited = std::fs::read_to_string(dir.join("b/runs.jsonl")).unwrap();
    let first = lines
        .iter()
        .find(|l| l.contains("\"algo\":\"greedy\""))
        .unwrap();
    let rec: serde_json::Value = serde_json::from_str(first).unwrap();
    let q = rec["nodes_expanded"].as_u64().unwrap();
    let changed = first.replace(
        &format!("\"nodes_expanded\":{q}"),
        &format!("\"nodes_expanded\":{}", q + 1),
    );
    assert_ne!(&changed, first);
    edited = edited.replace(first.as_str(), &changed);
    std::fs::write(dir.join("b/runs.jsonl"), edited).unwrap();
    let out = run_in(dir, &["merge", "a", "b", "--out", "m5", "--no-report"]);
    assert_eq!(out.status.code(), Some(3));
    assert!(
        stderr(&out).contains("with different results"),
        "{}",
        stderr(&out)
    );
}

#[test]
fn report_compare_of_overlapping_directories() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let mesh = small_mesh(dir, 300);
    assert!(
        sweep(dir, &sweep_args(&mesh, "a", 4, "1..2"), &[])
            .status
            .success()
    );
    copy_dir(&dir.join("a"), &dir.join("b"));
    assert!(
        sweep(dir, &sweep_args(&mesh, "b", 4, "1..3"), &["--extend"])
            .status
            .success()
    );
    // Another base seed on a third horizon range: independent runs of h = 2..3.
    let mut c = sweep_args(&mesh, "c", 4, "2..3");
    let i = c.iter().position(|x| x == "--seed").unwrap();
    c[i + 1] = "11".into();
    assert!(sweep(dir, &c, &[]).status.success());
    // And an extension to more runs: runs shared with a, but not all.
    copy_dir(&dir.join("a"), &dir.join("d"));
    assert!(
        sweep(dir, &sweep_args(&mesh, "d", 6, "1..2"), &["--extend"])
            .status
            .success()
    );

    let report = |first: &str, second: &str| {
        let out = run_in(
            dir,
            &["report", first, "--compare", second, "--no-pictures"],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        std::fs::read_to_string(dir.join(first).join("report.md")).unwrap()
    };
    let md = report("a", "b");
    assert!(
        md.contains("Only in the second: small selective h=3."),
        "{md}"
    );
    assert!(
        md.contains("not tested: small greedy-nocrit, small greedy, small selective h=1, small selective h=2, small optimum."),
        "{md}"
    );
    assert!(
        md.contains(
            "The configurations the two directories share hold the same runs: nothing to compare."
        ),
        "{md}"
    );

    let md = report("a", "c");
    assert!(
        md.contains("Only in the first: small selective h=1."),
        "{md}"
    );
    assert!(
        md.contains("Only in the second: small selective h=3."),
        "{md}"
    );
    // Another base seed: other seeds, no run shared (even the deterministic ones record
    // their seed); the common configurations are compared.
    assert!(
        !md.contains("not tested") && !md.contains("not independent"),
        "{md}"
    );
    assert!(md.contains("First vs second directory, quality"), "{md}");
    assert!(md.contains("small selective h=2 (first)"), "{md}");

    let md = report("a", "d");
    assert!(
        md.contains("so the two samples are not independent: small selective h=1 (4 runs), small selective h=2 (4 runs)."),
        "{md}"
    );
}
