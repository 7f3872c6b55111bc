//! `quadrecomb bench rss`: peak resident memory of `recombine` per triangle on every
//! generated shape (grid, strip, spiral, maze) at growing sizes. Each run is a child
//! process (this executable's `recombine`), so each peak is that run's alone: the kernel's
//! figure for the child (`ru_maxrss` of `wait4`), loading and the candidate table included.
//! A child that fails (out of memory under a limit, say) is reported with its exit status.

use crate::cli::UsageError;
use quadrecomb::internals::mesh::Recombined;
use quadrecomb::internals::mesh::generate::{self, Corridor, GridSpec};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode, Stdio};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Largest mesh (triangles); sizes grow tenfold from 10,000 up to it.
    #[arg(long, default_value_t = 1_000_000)]
    max_triangles: usize,
    /// Shapes, comma-separated, among grid, strip, spiral, maze.
    #[arg(long, value_delimiter = ',', default_value = "grid,strip,spiral,maze")]
    shapes: Vec<String>,
    /// Policies, comma-separated (`selective` and `uniform` run with --horizon).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "greedy-nocrit,greedy,selective"
    )]
    algos: Vec<String>,
    /// Horizon of the tree policies.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..))]
    horizon: u32,
}

/// What a child run left: its exit status, peak RSS in bytes and its search time.
struct Child {
    ok: bool,
    status: String,
    peak_bytes: u64,
    time_s: Option<f64>,
}

/// Runs `cmd` to its end and returns its status and peak resident set (`wait4`'s rusage).
#[allow(unsafe_code)] // wait4 and a zeroed rusage: the only way to a child's own peak
fn run_child(
    mut cmd: Command,
    stderr: &Path,
) -> std::io::Result<(std::process::ExitStatus, u64, String)> {
    use std::io::Read;
    use std::os::unix::process::ExitStatusExt;
    // Its stderr goes to a file (a pipe read after stdout could fill and stall it), for the
    // message of a child that fails.
    let err = std::fs::File::create(stderr)?;
    let mut child = cmd.stdout(Stdio::piped()).stderr(err).spawn()?;
    let mut out = String::new();
    if let Some(mut s) = child.stdout.take() {
        s.read_to_string(&mut out)?;
    }
    let pid = child.id() as libc::pid_t;
    let mut status: libc::c_int = 0;
    // SAFETY: rusage is plain data (zero is a valid value); wait4 writes into the two
    // out-parameters, which live for the call, and reaps `pid`, our own child, which std
    // has not waited for.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    if r != pid {
        return Err(std::io::Error::last_os_error());
    }
    // Linux reports ru_maxrss in KiB.
    let peak = u64::try_from(usage.ru_maxrss).unwrap_or(0) * 1024;
    Ok((std::process::ExitStatus::from_raw(status), peak, out))
}

fn recombine(exe: &Path, mesh: &Path, algo: &str, horizon: u32) -> anyhow::Result<Child> {
    let mut cmd = Command::new(exe);
    cmd.arg("recombine")
        .arg(mesh)
        .args(["--algo", algo, "--no-optimum", "--json"]);
    if algo == "selective" || algo == "uniform" {
        cmd.args(["--horizon", &horizon.to_string()]);
    }
    let err_path = mesh.with_extension("stderr.txt");
    let (status, peak_bytes, out) = run_child(cmd, &err_path)?;
    let time_s = serde_json::from_str::<serde_json::Value>(&out)
        .ok()
        .and_then(|v| v["time_s"].as_f64());
    // A failed child's last error line (its own message: out of memory, a bad mesh).
    let said = std::fs::read_to_string(&err_path).ok().and_then(|e| {
        e.lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .map(String::from)
    });
    let _ = std::fs::remove_file(&err_path);
    Ok(Child {
        ok: status.success(),
        status: match said {
            Some(said) if !status.success() => format!("{status}: {said}"),
            _ => status.to_string(),
        },
        peak_bytes,
        time_s,
    })
}

/// The mesh of `shape` with about `n` triangles.
fn build(shape: &str, n: usize) -> quadrecomb::internals::mesh::Mesh {
    match shape {
        "grid" => generate::grid(GridSpec {
            triangles: n,
            ..GridSpec::default()
        }),
        "strip" => generate::corridor(Corridor::Strip, n, 0),
        "spiral" => generate::corridor(Corridor::Spiral, n, 0),
        _ => generate::corridor(Corridor::Maze, n, 0),
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    for s in &args.shapes {
        if !["grid", "strip", "spiral", "maze"].contains(&s.as_str()) {
            return Err(UsageError(format!(
                "--shapes: unknown shape `{s}` (grid, strip, spiral, maze)"
            ))
            .into());
        }
    }
    for a in &args.algos {
        quadrecomb::internals::search::Algo::from_name(a, args.horizon)
            .map_err(|e| UsageError(format!("--algos: {e}")))?;
        if quadrecomb::internals::search::methods::find(a).is_some_and(|m| !m.search) {
            return Err(UsageError(format!(
                "--algos: {a} is not a search that `recombine` runs (`bench optimum` measures \
                 the optimum)"
            ))
            .into());
        }
    }
    if args.max_triangles < 10_000 {
        return Err(UsageError("--max-triangles must be at least 10000".into()).into());
    }
    let exe = std::env::current_exe()?;
    let dir = tempfile_dir()?;
    let result = measure(&args, &exe, &dir);
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// A fresh directory for the generated meshes (removed at the end).
fn tempfile_dir() -> anyhow::Result<PathBuf> {
    let dir = std::env::temp_dir().join(format!("quadrecomb-bench-rss-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

fn measure(args: &Args, exe: &Path, dir: &Path) -> anyhow::Result<ExitCode> {
    // What a process costs before any mesh: a run on the smallest mesh there is.
    let tiny = dir.join("tiny.msh");
    let mesh = generate::corridor(Corridor::Strip, 2, 0);
    quadrecomb::internals::mesh::msh::write(&tiny, &mesh, &Recombined::unrecombined(&mesh))?;
    let base = recombine(exe, &tiny, "greedy", 1)?;
    outln!(
        "peak RSS of `quadrecomb recombine MESH --algo A --no-optimum` (child processes); \
         a 2-triangle mesh: {:.1} MiB",
        base.peak_bytes as f64 / (1 << 20) as f64
    );
    outln!(
        "{:<7} {:>9} {:<14} {:>10} {:>9} {:>9}  status",
        "shape",
        "triangles",
        "algo",
        "peak MiB",
        "B/tri",
        "search s"
    );
    let mut failed = false;
    let mut n = 10_000;
    while n <= args.max_triangles {
        for shape in &args.shapes {
            let mesh = build(shape, n);
            let path = dir.join(format!("{shape}-{n}.msh"));
            quadrecomb::internals::mesh::msh::write(
                &path,
                &mesh,
                &Recombined::unrecombined(&mesh),
            )?;
            let nt = mesh.num_triangles();
            drop(mesh);
            for algo in &args.algos {
                let r = recombine(exe, &path, algo, args.horizon)?;
                failed |= !r.ok;
                let label = if algo == "selective" || algo == "uniform" {
                    format!("{algo} h={}", args.horizon)
                } else {
                    algo.clone()
                };
                outln!(
                    "{shape:<7} {nt:>9} {label:<14} {:>10.1} {:>9.0} {:>9}  {}",
                    r.peak_bytes as f64 / (1 << 20) as f64,
                    r.peak_bytes as f64 / nt as f64,
                    r.time_s.map_or("-".into(), |t| format!("{t:.3}")),
                    if r.ok { "ok" } else { &r.status },
                );
            }
            let _ = std::fs::remove_file(&path);
        }
        n = match n.checked_mul(10) {
            Some(m) => m,
            None => break,
        };
    }
    Ok(if failed {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    })
}
