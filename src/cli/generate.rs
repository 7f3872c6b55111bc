//! `quadrecomb generate`: procedural meshes of any size (jittered grid, icosphere), written as
//! MSH 4.1 ASCII.

use super::BadInput;
use quadrecomb::mesh::generate::{self, GridSpec, MAX_SUBDIVISIONS};
use quadrecomb::mesh::{Mesh, ReadError};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    shape: Shape,
}

#[derive(Debug, clap::Subcommand)]
enum Shape {
    /// A jittered right-triangle grid on the unit square, each cell split along a random
    /// diagonal.
    Grid(GridArgs),
    /// A subdivided icosahedron on the unit sphere (20 * 4^s triangles, closed).
    Icosphere(IcosphereArgs),
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
    /// Target number of triangles: the level whose count is closest.
    #[arg(long)]
    triangles: Option<usize>,
    /// Output file (.msh, written as MSH 4.1 ASCII).
    #[arg(short, long)]
    output: PathBuf,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let start = Instant::now();
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
            spec.validate().map_err(|e| BadInput(e.to_string()))?;
            check_output(&a.output)?;
            let (nx, ny) = spec.cells();
            let what = format!("grid of {nx} x {ny} cells, seed {}", spec.seed);
            (generate::grid(spec), what, a.output)
        }
        Shape::Icosphere(a) => {
            let s = match (a.subdivisions, a.triangles) {
                (Some(s), _) => s,
                (None, Some(n)) => generate::subdivisions_for(n),
                (None, None) => unreachable!("clap requires one of them"),
            };
            if s > MAX_SUBDIVISIONS {
                return Err(BadInput(format!(
                    "--subdivisions must be at most {MAX_SUBDIVISIONS} (got {s})"
                ))
                .into());
            }
            check_output(&a.output)?;
            (
                generate::icosphere(s),
                format!("icosphere, {s} subdivisions"),
                a.output,
            )
        }
    };
    let generated = start.elapsed().as_secs_f64();
    let start = Instant::now();
    write_msh(&output, &mesh)?;
    let written = start.elapsed().as_secs_f64();
    println!(
        "wrote {}: {} triangles, {} vertices ({what}); generated in {generated:.3} s, written in {written:.3} s",
        output.display(),
        mesh.num_triangles(),
        mesh.vertices.len(),
    );
    Ok(ExitCode::SUCCESS)
}

/// Fails early (before generating) if the output cannot be a new .msh file.
fn check_output(path: &Path) -> Result<(), BadInput> {
    if path
        .extension()
        .is_none_or(|e| !e.eq_ignore_ascii_case("msh"))
    {
        return Err(BadInput(format!(
            "{}: the output must be a .msh file",
            path.display()
        )));
    }
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty());
    if let Some(dir) = dir.filter(|d| !d.is_dir()) {
        return Err(BadInput(format!(
            "{}: directory {} does not exist",
            path.display(),
            dir.display()
        )));
    }
    Ok(())
}

/// Writes a plain triangle mesh as MSH 4.1 ASCII: one surface entity per surface tag, all
/// nodes in the first one's block, one triangle block per surface.
///
/// A stand-in until the io module's `quadrecomb::mesh::msh::write(path, mesh,
/// &Recombined::unrecombined(mesh))` is merged, which should replace this body.
fn write_msh(path: &Path, mesh: &Mesh) -> Result<(), ReadError> {
    let io = |source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let file = std::fs::File::create(path).map_err(io)?;
    let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
    write_msh_to(&mut w, mesh).map_err(io)?;
    w.flush().map_err(io)
}

fn write_msh_to(w: &mut impl Write, mesh: &Mesh) -> std::io::Result<()> {
    let surfaces = mesh.surfaces();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in &mesh.vertices {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;
    writeln!(w, "$Entities\n0 0 {} 0", surfaces.len())?;
    for s in &surfaces {
        writeln!(
            w,
            "{s} {:?} {:?} {:?} {:?} {:?} {:?} 0 0",
            lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]
        )?;
    }
    writeln!(w, "$EndEntities")?;

    let ids = &mesh.vertex_ids;
    let nv = ids.len();
    let (min, max) = (ids.iter().min(), ids.iter().max());
    writeln!(
        w,
        "$Nodes\n1 {nv} {} {}",
        min.unwrap_or(&0),
        max.unwrap_or(&0)
    )?;
    writeln!(w, "2 {} 0 {nv}", surfaces[0])?;
    for id in ids {
        writeln!(w, "{id}")?;
    }
    for p in &mesh.vertices {
        writeln!(w, "{:?} {:?} {:?}", p[0], p[1], p[2])?;
    }
    writeln!(w, "$EndNodes")?;

    let tids = &mesh.triangle_ids;
    let (min, max) = (tids.iter().min(), tids.iter().max());
    writeln!(
        w,
        "$Elements\n{} {} {} {}",
        surfaces.len(),
        tids.len(),
        min.unwrap_or(&0),
        max.unwrap_or(&0)
    )?;
    for &s in &surfaces {
        let block: Vec<usize> = (0..mesh.num_triangles())
            .filter(|&t| mesh.triangle_surface[t] == s)
            .collect();
        writeln!(w, "2 {s} 2 {}", block.len())?;
        for t in block {
            let [a, b, c] = mesh.triangles[t].map(|v| ids[v as usize]);
            writeln!(w, "{} {a} {b} {c}", tids[t])?;
        }
    }
    writeln!(w, "$EndElements")
}
