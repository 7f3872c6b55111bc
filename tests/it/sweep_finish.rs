//! `sweep --finish`: records keep the raw fields and add a `finish` object, the summary and
//! report add "+ finish" rows, resume and extension keep the finish settings, replay
//! reproduces the finish.

use crate::runner::{records, stderr, sweep};
use crate::util::{SEED, run_in};
use quadrecomb::internals::experiment::manifest::Manifest;

fn args(mesh: &str, out: &str, runs: u32, finish: &[&str]) -> Vec<String> {
    let mut a: Vec<String> = [
        "sweep",
        "--mesh",
        mesh,
        "--algo",
        "greedy",
        "selective",
        "optimum",
        "--horizons",
        "1,3",
        "--runs",
        &runs.to_string(),
        "--seed",
        &SEED.to_string(),
        "--backend",
        "cpu",
        "--threads",
        "2",
        "--out",
        out,
        "-q",
    ]
    .map(String::from)
    .to_vec();
    a.extend(finish.iter().map(|s| s.to_string()));
    a
}

#[test]
fn sweep_finish_records_reports_resumes_and_replays() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    // Even (34456 triangles) and perfectly matchable; the searches leave triangles on it.
    let mesh = "borouchaki";
    let fin = ["--finish", "--window", "4"];
    let out = sweep(dir, &args(mesh, "fin", 2, &fin), &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let manifest = Manifest::read(&dir.join("fin")).unwrap();
    let settings = manifest
        .spec
        .finish
        .expect("the manifest records the finish");
    assert_eq!((settings.rings, settings.window), (2, 4));
    let opt = &manifest.optimum[0];
    assert_eq!(opt.triangles_left, 0, "borouchaki is perfectly matchable");

    let recs = records(&dir.join("fin"));
    assert_eq!(recs.len(), 1 + 2 * 2 + 1);
    let (mut left_raw, mut lower, mut higher) = (0, 0, 0);
    for r in &recs {
        if r.algo == "optimum" {
            assert!(r.finish.is_none(), "the optimum is not finished");
            continue;
        }
        let f = r.finish.as_ref().expect("every search run is finished");
        assert_eq!((f.rings, f.window), (2, 4));
        left_raw += r.triangles_left;
        assert_eq!(
            f.triangles_left,
            0,
            "{}: the finish pairs every triangle",
            r.key()
        );
        assert_eq!(f.quads, opt.quads);
        assert_eq!(f.recombined_pct, 100.0);
        assert!(f.quads >= r.quads);
        // The finish never loses eta without gaining quads: elimination may trade eta for a
        // quad (cardinality first, as in the optimum; docs/finish.md), improvement only
        // raises eta. (On a 600-triangle grid one run does end below its raw quality.)
        if f.quads == r.quads {
            assert!(
                f.quality >= r.quality,
                "{}: {f:?} vs raw {}",
                r.key(),
                r.quality
            );
        }
        lower += usize::from(f.quality < r.quality);
        higher += usize::from(f.quality > r.quality);
        assert!(f.quality <= opt.quality * (1.0 + 1e-9));
        assert!((f.time_s - f.eliminate_s - f.improve_s).abs() < 1e-12);
    }
    assert!(
        left_raw > 0,
        "the searches leave triangles: nothing was tested"
    );

    assert!(
        higher > lower,
        "the finish raised quality in {higher} runs, lowered it in {lower}"
    );

    // Without --finish the records have no finish key at all.
    let out = sweep(dir, &args(mesh, "raw", 2, &[]), &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    let raw_text = std::fs::read_to_string(dir.join("raw/runs.jsonl")).unwrap();
    assert!(!raw_text.contains("finish"), "{raw_text}");
    let raw_manifest = std::fs::read_to_string(dir.join("raw/manifest.json")).unwrap();
    assert!(!raw_manifest.contains("finish"));
    let raw_csv = std::fs::read_to_string(dir.join("raw/summary.csv")).unwrap();
    assert!(!raw_csv.contains("finish"));
    let raw_report = std::fs::read_to_string(dir.join("raw/report.md")).unwrap();
    assert!(!raw_report.contains("finish"));

    // Summary and report: finished rows beside the raw ones.
    let csv = std::fs::read_to_string(dir.join("fin/summary.csv")).unwrap();
    assert!(csv.starts_with("mesh,algo,horizon,finish,metric,"), "{csv}");
    assert!(csv.contains(",selective,3,finish,quality_pct,2,"), "{csv}");
    assert!(csv.contains(",selective,3,,quality_pct,2,"), "{csv}");
    let json = std::fs::read_to_string(dir.join("fin/summary.json")).unwrap();
    assert!(json.contains("\"finished\": true"), "{json}");
    let report = std::fs::read_to_string(dir.join("fin/report.md")).unwrap();
    assert!(
        report.contains("| selective + finish | 3 | 2 | "),
        "{report}"
    );
    assert!(report.contains("| greedy + finish | – | "), "{report}");
    assert!(report.contains("### What the finish added"), "{report}");
    let added = report.split("### What the finish added").nth(1).unwrap();
    assert!(added.contains("| selective | 1 | 2 | "), "{added}");

    // Resume after losing the last runs: the same records.
    let runs = dir.join("fin/runs.jsonl");
    let text = std::fs::read_to_string(&runs).unwrap();
    let kept: Vec<&str> = text.lines().take(3).collect();
    std::fs::write(&runs, kept.join("\n") + "\n").unwrap();
    let out = sweep(dir, &args(mesh, "fin", 2, &fin), &["--resume"]);
    assert!(out.status.success(), "{}", stderr(&out));
    crate::runner::assert_same(&records(&dir.join("fin")), &recs, "resumed with --finish");

    // Other finish settings, or none, are refused on resume and extension.
    for (extra, finish, why) in [
        ("--resume", &[][..], "no finish vs finish rings 2 window 4"),
        (
            "--resume",
            &["--finish"][..],
            "finish rings 2 window 8 vs finish rings 2 window 4",
        ),
        (
            "--extend",
            &["--finish", "--rings", "3", "--window", "4"][..],
            "cannot extend it: finish rings 3 window 4 vs finish rings 2 window 4",
        ),
    ] {
        let runs = if extra == "--extend" { 3 } else { 2 };
        let out = sweep(dir, &args(mesh, "fin", runs, finish), &[extra]);
        assert!(!out.status.success(), "{extra} {finish:?} was accepted");
        assert!(stderr(&out).contains(why), "{}", stderr(&out));
        assert_eq!(
            Manifest::read(&dir.join("fin")).unwrap().spec.finish,
            Some(settings)
        );
    }
    // The same settings extend it.
    let out = sweep(dir, &args(mesh, "fin", 3, &fin), &["--extend"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        records(&dir.join("fin"))
            .iter()
            .all(|r| (r.algo == "optimum") == r.finish.is_none())
    );

    // Replay reproduces the finish.
    let out = run_in(
        dir,
        &[
            "replay",
            "fin",
            "2",
            "--algo",
            "selective",
            "--horizon",
            "3",
            "--json",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["reproduced"], true);
    assert_eq!(v["finish"]["quads"], v["recorded"]["finish"]["quads"]);
    assert_eq!(v["finish"]["quality"], v["recorded"]["finish"]["quality"]);
    assert_eq!(v["finish"]["triangles_left"], 0);
}
