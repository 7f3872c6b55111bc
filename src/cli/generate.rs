//! `quadrecomb generate`: procedural meshes of any size (jittered grid, icosphere, and
//! one-cell-wide strip, spiral and maze, jittered equilateral lattice), written as MSH 4.1
//! ASCII.

use super::UsageError;
use quadrecomb::internals::mesh::Recombined;
use quadrecomb::internals::mesh::generate::{
    self, Corridor, GridSpec, MAX_GRID_TRIANGLES, MAX_SUBDIVISIONS,
};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    shape: Shape,
    /// Print one JSON object on stdout (file, counts, what was made, times) instead of the
    /// "wrote" line.
    #[arg(long, global = true)]
    json: bool,
}

#[derive(Debug, clap::Subcommand)]
enum Shape {
    /// A jittered right-triangle grid on the unit square, each cell split along a random
    /// diagonal.
    Grid(GridArgs),
    /// A subdivided icosahedron on the unit sphere (20 * 4^s triangles, closed).
    Icosphere(IcosphereArgs),
    /// A straight strip one cell high (its dual graph is a path).
    Strip(CorridorArgs),
    /// A square spiral one cell wide, its turns one cell apart (a path).
    Spiral(CorridorArgs),
    /// A random perfect maze of one-cell corridors (its dual graph is a tree).
    Maze(CorridorArgs),
    /// A jittered equilateral triangle lattice (rows offset by half a step, interior vertices
    /// moved by up to 0.15 of an edge): the mesh `bench optimum` and `bench finish` time.
    Lattice(LatticeArgs),
}

#[derive(Debug, clap::Args)]
struct LatticeArgs {
    /// Target number of triangles, at least 2 (the lattice gets 2 * nx * ny, nx the rounded
    /// square root of the cells, the nearest count at or above it).
    #[arg(long)]
    triangles: usize,
    /// Seed of the jitter (`bench optimum` and `bench finish` use 2).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output file (.msh, written as MSH 4.1 ASCII).
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(Debug, clap::Args)]
struct CorridorArgs {
    /// Target number of triangles (two per unit cell; the mesh gets the nearest count at or
    /// below it that the shape allows).
    #[arg(long)]
    triangles: usize,
    /// Seed of the diagonals (and of the maze).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output file (.msh, written as MSH 4.1 ASCII).
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(Debug, clap::Args)]
struct GridArgs {
    /// Target number of triangles (the grid gets 2 * nx * ny, the closest with near-square
    /// cells, before --holes and --drop-triangles).
    #[arg(long)]
    triangles: usize,
    /// Seed of the diagonals, the jitter and the dropped triangles.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Largest vertex offset per axis, as a fraction of the cell size, in [0, 0.25).
    #[arg(long, default_value_t = 0.2)]
    jitter: f64,
    /// Cut a square hole out of the middle third of the square.
    #[arg(long)]
    holes: bool,
    /// Number of surfaces: vertical strips, so the dual graph splits along each interface.
    #[arg(long, default_value_t = 1)]
    surfaces: u32,
    /// Remove this many isolated interior triangles (each makes its component odd).
    #[arg(long, default_value_t = 0)]
    drop_triangles: usize,
    /// Output file (.msh, written as MSH 4.1 ASCII).
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("size").required(true).args(["subdivisions", "triangles"])))]
struct IcosphereArgs {
    /// Subdivision level s (0 to 10): 20 * 4^s triangles.
    #[arg(long)]
    subdivisions: Option<u32>,
    /// Target number of triangles (at least 1): the level whose count (20 * 4^s) is closest;
    /// the "wrote" line says so when it differs.
    #[arg(long)]
    triangles: Option<usize>,
    /// Output file (.msh, written as MSH 4.1 ASCII).
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    super::oom::phase(super::oom::Phase::Generate);
    let start = Instant::now();
    let json = args.json;
    let (mesh, what, output) = match args.shape {
        Shape::Grid(a) => {
            let spec = GridSpec {
                triangles: a.triangles,
                seed: a.seed,
                jitter: a.jitter,
                holes: a.holes,
                surfaces: a.surfaces,
                drop_triangles: a.drop_triangles,
            };
            spec.validate().map_err(|e| UsageError(e.to_string()))?;
            check_memory(a.triangles)?;
            check_output(&a.output)?;
            let (nx, ny) = spec.cells();
            let what = format!("grid of {nx} x {ny} cells, seed {}", spec.seed);
            (generate::grid(spec), what, a.output)
        }
        Shape::Icosphere(a) => {
            let s = match (a.subdivisions, a.triangles) {
                (Some(s), _) => s,
                (None, Some(0)) => {
                    return Err(UsageError(
                        "--triangles 0: an icosphere has at least 20 triangles (0 \
                         subdivisions); give a target of 1 or more, or --subdivisions"
                            .into(),
                    )
                    .into());
                }
                (None, Some(n)) => {
                    let largest = 20usize << (2 * MAX_SUBDIVISIONS);
                    if n > 2 * largest {
                        return Err(UsageError(format!(
                            "--triangles {n}: the largest icosphere has {largest} triangles \
                             ({MAX_SUBDIVISIONS} subdivisions)"
                        ))
                        .into());
                    }
                    generate::subdivisions_for(n)
                }
                (None, None) => unreachable!("clap requires one of them"),
            };
            if s > MAX_SUBDIVISIONS {
                return Err(UsageError(format!(
                    "--subdivisions must be at most {MAX_SUBDIVISIONS} (got {s})"
                ))
                .into());
            }
            check_output(&a.output)?;
            let made = 20usize << (2 * s);
            // --triangles picks the closest level: say so when the count is not the target.
            let what = match a.triangles {
                Some(n) if a.subdivisions.is_none() && n != made => format!(
                    "icosphere, {s} subdivisions: 20 * 4^{s} is the closest count to \
                     --triangles {n}"
                ),
                _ => format!("icosphere, {s} subdivisions"),
            };
            (generate::icosphere(s), what, a.output)
        }
        Shape::Strip(a) => corridor(Corridor::Strip, a)?,
        Shape::Spiral(a) => corridor(Corridor::Spiral, a)?,
        Shape::Maze(a) => corridor(Corridor::Maze, a)?,
        Shape::Lattice(a) => {
            if !(2..=MAX_GRID_TRIANGLES).contains(&a.triangles) {
                return Err(UsageError(format!(
                    "--triangles {}: a lattice has between 2 and {MAX_GRID_TRIANGLES} triangles",
                    a.triangles
                ))
                .into());
            }
            check_memory(a.triangles)?;
            check_output(&a.output)?;
            let (nx, ny) = generate::lattice_cells(a.triangles);
            let what = format!("equilateral lattice of {nx} x {ny} cells, seed {}", a.seed);
            (generate::lattice(a.triangles, a.seed), what, a.output)
        }
    };
    let generated = start.elapsed().as_secs_f64();
    let start = Instant::now();
    super::write_mesh_output(&output, &mesh, &Recombined::unrecombined(&mesh), false)?;
    let written = start.elapsed().as_secs_f64();
    if json {
        let v = serde_json::json!({
            "output": output,
            "triangles": mesh.num_triangles(),
            "vertices": mesh.vertices.len(),
            "shape": what,
            "generate_s": generated,
            "write_s": written,
        });
        outln!("{v}");
        return Ok(ExitCode::SUCCESS);
    }
    outln!(
        "wrote {}: {} triangles, {} vertices ({what}); generated in {generated:.3} s, written in {written:.3} s",
        output.display(),
        mesh.num_triangles(),
        mesh.vertices.len(),
    );
    Ok(ExitCode::SUCCESS)
}

/// Peak memory of `generate grid` per triangle (measured: 176 bytes at 10^6 and 4 * 10^6
/// triangles), rounded up.
const BYTES_PER_TRIANGLE: u64 = 200;

/// Refuses, before allocating, a grid that needs more memory than the machine has (it
/// aborted allocating instead).
fn check_memory(triangles: usize) -> Result<(), UsageError> {
    let Some(total) = std::fs::read_to_string("/proc/meminfo").ok().and_then(|s| {
        s.lines()
            .find_map(|l| l.strip_prefix("MemTotal:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
            .map(|kb| kb * 1024)
    }) else {
        return Ok(());
    };
    let need = (triangles as u64).saturating_mul(BYTES_PER_TRIANGLE);
    if need > total {
        let gib = |b: u64| b as f64 / (1u64 << 30) as f64;
        return Err(UsageError(format!(
            "--triangles {triangles}: generating needs about {:.1} GiB of memory (about \
             {BYTES_PER_TRIANGLE} bytes per triangle), more than this machine's {:.1} GiB; \
             at most about {} triangles here",
            gib(need),
            gib(total),
            total / BYTES_PER_TRIANGLE
        )));
    }
    Ok(())
}

/// A corridor mesh, its description and its output, after the checks.
fn corridor(
    shape: Corridor,
    a: CorridorArgs,
) -> anyhow::Result<(quadrecomb::internals::mesh::Mesh, String, PathBuf)> {
    generate::validate_corridor(shape, a.triangles).map_err(|e| UsageError(e.to_string()))?;
    check_output(&a.output)?;
    let what = format!("{}, seed {}", shape.name(), a.seed);
    Ok((
        generate::corridor(shape, a.triangles, a.seed),
        what,
        a.output,
    ))
}

/// Fails early (before generating) if the output cannot be a new .msh file.
fn check_output(path: &Path) -> Result<(), UsageError> {
    if path
        .extension()
        .is_none_or(|e| !e.eq_ignore_ascii_case("msh"))
    {
        return Err(UsageError(format!(
            "{}: the output must be a .msh file",
            path.display()
        )));
    }
    super::check_output_place(path)
}
