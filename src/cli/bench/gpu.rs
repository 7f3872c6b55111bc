//! `quadrecomb bench gpu`: candidates per second of the quality evaluation on the f64
//! reference, the CPU twin (1 thread, all threads) and every Vulkan adapter (lavapipe, a real
//! GPU), split into upload, kernel and readback, against the device's memory-bandwidth bound.

mod bandwidth;

use anyhow::Context;
use quadrecomb::internals::gpu::layout::LOCAL_QUAD_BYTES;
use quadrecomb::internals::gpu::{self, Batch, Kernel, KernelOptions, Layout, Timings, synthetic};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Candidate counts to measure (about; a jittered grid of ~n/3 cells^2 is generated).
    #[arg(long, value_delimiter = ',', value_parser = parse_count,
          default_value = "1e4,1e5,1e6,1e7")]
    sizes: Vec<usize>,
    /// Timed repetitions per size and backend (the best is reported), after one warm-up.
    #[arg(long, default_value_t = 3, value_parser = super::at_least_one())]
    repeat: usize,
    /// Skip the 1-thread CPU rows (f64 reference and twin) above this many candidates.
    #[arg(long, value_parser = parse_count, default_value = "1e7")]
    serial_max: usize,
    /// Skip the Vulkan adapters (CPU rows only).
    #[arg(long)]
    cpu_only: bool,
    /// Seed of the jittered grid.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Dispatches timed per kernel for the warm kernel time (their median).
    #[arg(long, default_value_t = 20)]
    dispatches: u32,
    /// Untimed back-to-back dispatches before those, in milliseconds of device time, so the
    /// GPU runs at its working clock (an idle H100 stays at 345 MHz for lone dispatches).
    #[arg(long, default_value_t = 1000)]
    warm_up_ms: u64,
    /// Also compare launch shapes (layout x workgroup size, and the memory-only
    /// diagnostics) at the largest size, on every adapter.
    #[arg(long)]
    shapes: bool,
}

fn parse_count(s: &str) -> Result<usize, String> {
    let v: f64 = s.trim().parse().map_err(|e| format!("{s:?}: {e}"))?;
    if !(1.0..=1e10).contains(&v) {
        return Err(format!("{s:?}: expected a count between 1 and 1e10"));
    }
    Ok(v.round() as usize)
}

/// One measured row.
struct Row {
    backend: String,
    candidates: usize,
    t: Timings,
    total_s: f64,
    max_diff_f64: Option<f64>,
    /// Median device time of dispatches after a warm-up (seconds), where measured.
    warm_s: Option<f64>,
    /// Device kernels: the time the kernel's bytes take at the measured bandwidth (seconds),
    /// the bound the kernel time is compared with.
    floor_s: Option<f64>,
}

/// Bytes per candidate a kernel of `layout` must move for `batch` (read + written).
fn kernel_bytes(layout: Layout, batch: &Batch) -> f64 {
    match layout {
        Layout::Indexed => batch.bytes_per_candidate(),
        Layout::Local => (LOCAL_QUAD_BYTES + 4) as f64,
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn best_of<T>(
    repeat: usize,
    mut f: impl FnMut() -> anyhow::Result<(T, Timings, f64)>,
) -> anyhow::Result<(T, Timings, f64)> {
    let mut best: Option<(T, Timings, f64)> = None;
    for _ in 0..repeat.max(1) {
        let r = f()?;
        if best.as_ref().is_none_or(|b| r.2 < b.2) {
            best = Some(r);
        }
    }
    Ok(best.expect("at least one repetition"))
}

fn max_diff(eta: &[f32], reference: &[f64]) -> f64 {
    eta.iter()
        .zip(reference)
        .map(|(&a, &b)| (a as f64 - b).abs())
        .fold(0.0, f64::max)
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let threads = rayon::current_num_threads();
    let warm_up = std::time::Duration::from_millis(args.warm_up_ms);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .context("building a 1-thread pool")?;

    // Devices, opened once: (name, device, queue, kernel, bandwidth).
    let mut devices = Vec::new();
    if !args.cpu_only {
        let adapters = gpu::adapters();
        if adapters.is_empty() {
            noteln!("no Vulkan adapter found: CPU rows only");
        }
        for a in adapters {
            let info = a.get_info();
            let name = gpu::adapter_name(&info);
            let opened = gpu::open_device(&a).and_then(|(d, q)| Ok((Kernel::new(&d)?, d, q)));
            let (kernel, device, queue) = match opened {
                Ok(x) => x,
                Err(e) => {
                    noteln!("skipping {name}: {e}");
                    continue;
                }
            };
            let probe = if gpu::is_software(&info) {
                64 << 20
            } else {
                1 << 30
            };
            let copy = bandwidth::copy_bandwidth(&device, &queue, probe)
                .with_context(|| format!("measuring the copy bandwidth of {name}"))?;
            let stream = bandwidth::stream_bandwidth(&device, &queue, probe)
                .with_context(|| format!("measuring the stream bandwidth of {name}"))?;
            let bw = copy.max(stream);
            outln!(
                "device: {name} ({:?}, driver {} {}), bandwidth (read + write): buffer copy \
                 {:.1} GB/s, compute stream copy {:.1} GB/s; kernel timing: {}",
                info.device_type,
                info.driver,
                info.driver_info,
                copy / 1e9,
                stream / 1e9,
                if kernel.has_timestamps() {
                    "timestamp queries"
                } else {
                    "submit + wait"
                }
            );
            let kernels = vec![
                (kernel, "indexed", true, Layout::Indexed),
                (
                    Kernel::with_layout(&device, Layout::Local)?,
                    "local edges",
                    true,
                    Layout::Local,
                ),
                (
                    Kernel::memory_only(&device, Layout::Indexed)?,
                    "indexed, memory accesses only, diagnostic",
                    false,
                    Layout::Indexed,
                ),
                (
                    Kernel::memory_only(&device, Layout::Local)?,
                    "local edges, memory accesses only, diagnostic",
                    false,
                    Layout::Local,
                ),
            ];
            devices.push((name, device, queue, kernels, bw));
        }
    }
    outln!("host: {threads} threads for the CPU rows");

    let mut rows = Vec::new();
    for &size in &args.sizes {
        let n = ((size as f64 / 3.0).sqrt().ceil() as usize).max(1);
        let (vertices, quads) = synthetic::jittered_grid(n, 0.2, args.seed);
        let t = Instant::now();
        let mut batch = Batch::new();
        batch.push(&vertices, &quads)?;
        let prepare_s = t.elapsed().as_secs_f64();
        let c = batch.len();
        outln!(
            "\n{c} candidates ({n}x{n} jittered grid, {} vertices): host batch preparation \
             (f64 -> hi/lo f32, index offsets) {:.2} ms; at least {:.1} bytes per candidate \
             indexed, {} with local edges",
            vertices.len(),
            prepare_s * 1e3,
            kernel_bytes(Layout::Indexed, &batch),
            kernel_bytes(Layout::Local, &batch)
        );
        let reference: Vec<f64> = {
            use rayon::prelude::*;
            quads
                .par_iter()
                .map(|q| quadrecomb::internals::quality::quad_eta(q.map(|v| vertices[v as usize])))
                .collect()
        };

        let cpu_row = |name: String, f: &dyn Fn() -> Vec<f32>| -> anyhow::Result<Row> {
            let _ = f();
            let (eta, t, total) = best_of(args.repeat, || {
                let s = Instant::now();
                let eta = f();
                let e = s.elapsed().as_secs_f64();
                Ok((
                    eta,
                    Timings {
                        kernel_s: e,
                        ..Timings::default()
                    },
                    e,
                ))
            })?;
            Ok(Row {
                backend: name,
                candidates: c,
                t,
                total_s: total,
                max_diff_f64: Some(max_diff(&eta, &reference)),
                warm_s: None,
                floor_s: None,
            })
        };
        if c <= args.serial_max {
            // The f64 reference, serial: what `CandidateTable::build` costs.
            let s = Instant::now();
            let r64: Vec<f64> = quads
                .iter()
                .map(|q| quadrecomb::internals::quality::quad_eta(q.map(|v| vertices[v as usize])))
                .collect();
            let e = s.elapsed().as_secs_f64();
            assert_eq!(r64.len(), c);
            rows.push(Row {
                backend: "f64 reference, 1 thread".into(),
                candidates: c,
                t: Timings {
                    kernel_s: e,
                    ..Timings::default()
                },
                total_s: e,
                max_diff_f64: Some(0.0),
                warm_s: None,
                floor_s: None,
            });
            rows.push(cpu_row("cpu-twin, 1 thread".into(), &|| {
                one.install(|| gpu::cpu::quad_quality(&batch))
            })?);
        }
        rows.push(cpu_row(format!("cpu-twin, {threads} threads"), &|| {
            gpu::cpu::quad_quality(&batch)
        })?);

        for (name, device, queue, kernels, bw) in &devices {
            for (k, what, is_eta, layout) in kernels {
                let label = format!("{name} [{what}]");
                k.run(device, queue, &batch)?; // warm-up
                let (eta, t, total) = best_of(args.repeat, || {
                    let s = Instant::now();
                    let (eta, t) = k.run(device, queue, &batch)?;
                    Ok((eta, t, s.elapsed().as_secs_f64()))
                })?;
                let warm = k
                    .dispatch_times(device, queue, args.dispatches, warm_up)?
                    .map(median);
                rows.push(Row {
                    backend: label,
                    candidates: c,
                    t,
                    total_s: total,
                    max_diff_f64: is_eta.then(|| max_diff(&eta, &reference)),
                    warm_s: warm,
                    floor_s: Some(c as f64 * kernel_bytes(*layout, &batch) / bw),
                });
            }
        }
        print_rows(
            &rows[rows.len() - rows.iter().rev().take_while(|r| r.candidates == c).count()..],
        );
        if args.shapes && Some(&size) == args.sizes.iter().max() {
            for (name, device, queue, _, bw) in &devices {
                shapes(name, device, queue, &batch, *bw, args.dispatches, warm_up)?;
            }
        }
    }
    outln!("\nAll sizes:");
    print_rows(&rows);
    outln!(
        "\nkernel, run = the run's dispatch (or dispatches, each after its upload), device \
         timestamps where supported, else submit + wait, at whatever clock the GPU is at; \
         warm = median of {} dispatches after {} ms of back-to-back ones (the GPU at its \
         working clock; only for a single-dispatch run); total = upload + kernel + readback \
         on the host clock, batch preparation excluded; Mcand/s kernel and the bound use the \
         warm time where there is one; bound = kernel bytes per second (bytes per candidate \
         above) / the better measured bandwidth.",
        args.dispatches,
        args.warm_up_ms
    );
    Ok(ExitCode::SUCCESS)
}

fn print_rows(rows: &[Row]) {
    outln!(
        "| backend | candidates | upload ms | kernel ms, run | kernel ms, warm | readback ms | \
         total ms | Mcand/s kernel | Mcand/s total | % of bandwidth bound | \
         max abs diff vs f64 |"
    );
    outln!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let dash = || "-".to_string();
    for r in rows {
        let k = r.t.kernel_best_s();
        // Throughput and bound from the warm time where there is one.
        let kt = r.warm_s.unwrap_or(k);
        let bound = r.floor_s.map(|f| 100.0 * f / kt);
        outln!(
            "| {} | {} | {:.3} | {:.3} | {} | {:.3} | {:.3} | {:.1} | {:.1} | {} | {} |",
            r.backend,
            r.candidates,
            r.t.upload_s * 1e3,
            k * 1e3,
            r.warm_s.map_or_else(dash, |s| format!("{:.3}", s * 1e3)),
            r.t.readback_s * 1e3,
            r.total_s * 1e3,
            r.candidates as f64 / kt / 1e6,
            r.candidates as f64 / r.total_s / 1e6,
            bound.map_or_else(dash, |p| format!("{p:.0}%")),
            r.max_diff_f64.map_or_else(dash, |d| format!("{d:.1e}"))
        );
    }
}

/// The launch-shape comparison (`--shapes`): every layout x workgroup size, eta and
/// memory-only, on `batch`; warm median and best dispatch.
fn shapes(
    name: &str,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    batch: &Batch,
    bw: f64,
    dispatches: u32,
    warm_up: std::time::Duration,
) -> anyhow::Result<()> {
    let c = batch.len() as f64;
    outln!(
        "\nLaunch shapes on {name}, {} candidates, {dispatches} dispatches each after {} ms \
         of warm-up:",
        batch.len(),
        warm_up.as_millis()
    );
    outln!("| kernel | median ms | best ms | Gcand/s | % of bandwidth bound |");
    outln!("|---|---:|---:|---:|---:|");
    let max_wg = device.limits().max_compute_invocations_per_workgroup;
    for layout in [Layout::Indexed, Layout::Local] {
        let floor_s = c * kernel_bytes(layout, batch) / bw;
        for memory_only in [false, true] {
            for workgroup in [64, 256, 1024].into_iter().filter(|&w| w <= max_wg) {
                let options = KernelOptions {
                    layout,
                    workgroup,
                    memory_only,
                };
                let k = Kernel::with_options(device, options)?;
                k.run(device, queue, batch)?;
                let Some(times) = k.dispatch_times(device, queue, dispatches, warm_up)? else {
                    outln!(
                        "| {options} | no warm time (no timestamps, or several dispatches) | | | |"
                    );
                    continue;
                };
                let best = times.iter().copied().fold(f64::INFINITY, f64::min);
                let med = median(times);
                outln!(
                    "| {options} | {:.4} | {:.4} | {:.2} | {:.0}% |",
                    med * 1e3,
                    best * 1e3,
                    c / med / 1e9,
                    100.0 * floor_s / med
                );
            }
        }
    }
    Ok(())
}
