//! `quadrecomb bench suite-eval`: filling the candidate tables of every mesh of a suite, three
//! ways: one batch for all meshes on the device (what `sweep` does), one submission per mesh
//! on the device, and the CPU twin (all threads); medians of `--repeat` timed repetitions
//! after a warm-up, and a check that the batch gives the same bits as the per-mesh runs.

use anyhow::Context;
use quadrecomb::internals::gpu::{Backend, Batch, Evaluator};
use quadrecomb::internals::mesh::{self, Mesh, suite};
use quadrecomb::internals::quality::CandidateTable;
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// The suite whose meshes are evaluated (`quadrecomb suite list`).
    #[arg(long, default_value = "default")]
    suite: String,
    /// Timed repetitions of each way (the median is reported, min and max beside it).
    #[arg(long, default_value_t = 7, value_parser = super::at_least_one())]
    repeat: usize,
    /// Skip the device (CPU twin only).
    #[arg(long)]
    cpu_only: bool,
    /// One JSON object on stdout instead of the table.
    #[arg(long)]
    json: bool,
}

/// The candidates of every mesh (topology only).
fn candidates(meshes: &[Mesh]) -> Vec<CandidateTable> {
    meshes.iter().map(CandidateTable::topology_only).collect()
}

/// One way of evaluating: batches built from the meshes, each evaluated in one call.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Way {
    /// One batch of every mesh (one submission, split only by the adapter's limits).
    Batched,
    /// One batch, so one submission, per mesh.
    PerMesh,
}

/// One timed evaluation: seconds per phase, summed over the submissions.
#[derive(Debug, Clone, Copy, Default)]
struct Sample {
    /// Building the batches (f64 to normalised hi/lo f32, global indices).
    prep_s: f64,
    upload_s: f64,
    kernel_s: f64,
    readback_s: f64,
    /// The whole evaluation, prep included (host clock).
    total_s: f64,
    /// CPU time of the whole process (every thread: lavapipe's workers, the twin's pool)
    /// during it: less sensitive than wall time to other jobs on a shared machine.
    cpu_s: f64,
    dispatches: usize,
}

/// Evaluates the tables' candidates `way`: the eta of every candidate in mesh order, and the
/// times.
fn evaluate(
    ev: &Evaluator,
    meshes: &[Mesh],
    tables: &[CandidateTable],
    way: Way,
) -> anyhow::Result<(Vec<f32>, Sample)> {
    let start = Instant::now();
    let cpu_start = process_cpu_s();
    let mut sample = Sample::default();
    let groups: Vec<Vec<usize>> = match way {
        Way::Batched => vec![(0..meshes.len()).collect()],
        Way::PerMesh => (0..meshes.len()).map(|i| vec![i]).collect(),
    };
    let mut eta = Vec::new();
    for group in groups {
        let t = Instant::now();
        let mut batch = Batch::with_capacity(
            group.iter().map(|&i| meshes[i].vertices.len()).sum(),
            group.iter().map(|&i| tables[i].quads.len()).sum(),
            group.len(),
        );
        for i in group {
            batch.push(&meshes[i].vertices, &tables[i].quads)?;
        }
        sample.prep_s += t.elapsed().as_secs_f64();
        let (e, t) = ev.evaluate(&batch)?;
        sample.upload_s += t.upload_s;
        sample.kernel_s += t.kernel_s;
        sample.readback_s += t.readback_s;
        sample.dispatches += t.dispatches.max(1);
        eta.extend(e);
    }
    sample.total_s = start.elapsed().as_secs_f64();
    sample.cpu_s = process_cpu_s() - cpu_start;
    Ok((eta, sample))
}

/// CPU time this process has used, all threads (seconds).
#[allow(unsafe_code)] // clock_gettime: std has no process CPU clock
fn process_cpu_s() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes one timespec, which `t` is.
    let r = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    if r != 0 {
        return f64::NAN;
    }
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// One way's figures: the medians, (min, max) of the totals, the eta, and each repetition's
/// sample in order.
type Timed = (Sample, (f64, f64), Vec<f32>, Vec<Sample>);

/// Per way: the median of `repeat` timed evaluations after an untimed one (each phase's
/// median on its own), the fastest and slowest totals, and the eta. The ways take turns in
/// every repetition, so that a machine whose load drifts slows them alike.
fn time(
    ways: &[(&Evaluator, Way)],
    meshes: &[Mesh],
    tables: &[CandidateTable],
    repeat: usize,
) -> anyhow::Result<Vec<Timed>> {
    let mut etas = Vec::new();
    for (ev, way) in ways {
        etas.push(evaluate(ev, meshes, tables, *way)?.0);
    }
    let mut samples: Vec<Vec<Sample>> = vec![Vec::new(); ways.len()];
    for _ in 0..repeat.max(1) {
        for (k, (ev, way)) in ways.iter().enumerate() {
            let (again, s) = evaluate(ev, meshes, tables, *way)?;
            anyhow::ensure!(again == etas[k], "{} is not deterministic", ev.name());
            samples[k].push(s);
        }
    }
    Ok((samples.iter().zip(etas))
        .map(|(samples, eta)| {
            let median = |f: fn(&Sample) -> f64| {
                let mut v: Vec<f64> = samples.iter().map(f).collect();
                v.sort_by(f64::total_cmp);
                v[v.len() / 2]
            };
            let totals: Vec<f64> = samples.iter().map(|s| s.total_s).collect();
            let range = (
                totals.iter().copied().fold(f64::INFINITY, f64::min),
                totals.iter().copied().fold(0.0, f64::max),
            );
            let sample = Sample {
                prep_s: median(|s| s.prep_s),
                upload_s: median(|s| s.upload_s),
                kernel_s: median(|s| s.kernel_s),
                readback_s: median(|s| s.readback_s),
                total_s: median(|s| s.total_s),
                cpu_s: median(|s| s.cpu_s),
                dispatches: samples[0].dispatches,
            };
            (sample, range, eta, samples.clone())
        })
        .collect())
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let members = suite::suite(&args.suite).ok_or_else(|| {
        super::super::UsageError(format!(
            "--suite {:?}: no such suite (suites: {})",
            args.suite,
            suite::suite_names()
        ))
    })?;
    let mut meshes = Vec::new();
    for m in &members {
        let spec = suite::spec(m);
        meshes.push(mesh::load(&spec).with_context(|| format!("loading {spec}"))?);
    }
    let tables = candidates(&meshes);
    let count: usize = tables.iter().map(|t| t.quads.len()).sum();
    let triangles: usize = meshes.iter().map(Mesh::num_triangles).sum();
    let cpu = Evaluator::new(Backend::Cpu)?;
    let gpu = if args.cpu_only {
        None
    } else {
        Evaluator::new(Backend::Gpu)
            .map_err(|e| noteln!("no device ({e}): CPU twin only"))
            .ok()
    };
    let mut ways: Vec<(&Evaluator, Way, &str)> = Vec::new();
    if let Some(ev) = &gpu {
        ways.push((ev, Way::Batched, "one batch for every mesh"));
        ways.push((ev, Way::PerMesh, "one submission per mesh"));
    }
    ways.push((&cpu, Way::Batched, "one batch for every mesh"));
    let plain: Vec<(&Evaluator, Way)> = ways.iter().map(|&(e, w, _)| (e, w)).collect();
    let timed = time(&plain, &meshes, &tables, args.repeat)?;
    let identical = gpu.as_ref().map(|_| timed[0].2 == timed[1].2);
    // The batch's time over the per-mesh time of the same repetition (they run one after the
    // other), median over repetitions: robust to a load that drifts between repetitions.
    let paired = |f: fn(&Sample) -> f64| {
        gpu.as_ref().map(|_| {
            let mut r: Vec<f64> = (timed[0].3.iter().zip(&timed[1].3))
                .map(|(a, b)| f(a) / f(b))
                .collect();
            r.sort_by(f64::total_cmp);
            r[r.len() / 2]
        })
    };
    let (paired, paired_cpu) = (paired(|s| s.total_s), paired(|s| s.cpu_s));
    let device = gpu.as_ref().map(|e| e.name().to_string());
    let rows: Vec<(String, &str, Sample, (f64, f64))> = (ways.iter().zip(&timed))
        .map(|((ev, _, how), (s, r, ..))| {
            let name = if ev.is_device() {
                ev.name().to_string()
            } else {
                format!("cpu-twin, {} threads", rayon::current_num_threads())
            };
            (name, *how, *s, *r)
        })
        .collect();
    if args.json {
        let v = serde_json::json!({
            "suite": args.suite,
            "meshes": meshes.len(),
            "triangles": triangles,
            "candidates": count,
            "repeat": args.repeat,
            "device": device,
            "batch_bit_identical_to_per_mesh": identical,
            "batch_over_per_mesh_paired_median": paired,
            "batch_over_per_mesh_cpu_paired_median": paired_cpu,
            "rows": rows.iter().map(|(backend, how, s, (min, max))| serde_json::json!({
                "backend": backend, "how": how, "dispatches": s.dispatches,
                "prep_s": s.prep_s, "upload_s": s.upload_s, "kernel_s": s.kernel_s,
                "readback_s": s.readback_s, "median_s": s.total_s, "cpu_s": s.cpu_s, "min_s": min, "max_s": max,
            })).collect::<Vec<_>>(),
        });
        outln!("{v}");
    } else {
        outln!(
            "suite {}: {} meshes, {triangles} triangles, {count} candidates; medians of {} \
             repetitions after a warm-up (each phase its own median; min - max of the totals)",
            args.suite,
            meshes.len(),
            args.repeat.max(1)
        );
        outln!(
            "| backend | how | dispatches | prep ms | upload ms | kernel ms | readback ms | \
             total ms | min - max ms | Mcand/s | CPU ms |"
        );
        outln!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
        for (backend, how, s, (min, max)) in &rows {
            outln!(
                "| {backend} | {how} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} - \
                 {:.2} | {:.1} | {:.1} |",
                s.dispatches,
                s.prep_s * 1e3,
                s.upload_s * 1e3,
                s.kernel_s * 1e3,
                s.readback_s * 1e3,
                s.total_s * 1e3,
                min * 1e3,
                max * 1e3,
                count as f64 / s.total_s / 1e6,
                s.cpu_s * 1e3
            );
        }
        if let [(_, _, one, _), (_, _, each, _), ..] = rows.as_slice() {
            outln!(
                "one batch takes {:.2}x the wall time of one submission per mesh (median \
                 totals; median of the per-repetition ratios {:.2}x) and {:.2}x its CPU time \
                 (per-repetition ratios {:.2}x); its eta is {} the per-mesh runs'",
                one.total_s / each.total_s,
                paired.unwrap_or(f64::NAN),
                one.cpu_s / each.cpu_s,
                paired_cpu.unwrap_or(f64::NAN),
                if identical == Some(true) {
                    "bit for bit"
                } else {
                    "NOT bit for bit"
                }
            );
        }
    }
    if identical == Some(false) {
        anyhow::bail!("the batched eta differs from the per-mesh eta");
    }
    Ok(ExitCode::SUCCESS)
}
