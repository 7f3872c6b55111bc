//! `quadrecomb info`: a mesh's size, topology and candidate quad qualities, with parse time.

use quadrecomb::internals::mesh;
use quadrecomb::internals::quality::{self, CandidateTable, Rule};
use serde::Serialize;
use std::fmt::Write as _;
use std::io::Write as _;
use std::process::ExitCode;

/// `writeln!` into a `String` (which cannot fail).
macro_rules! wln {
    ($s:expr, $($arg:tt)*) => {{
        let _ = writeln!($s, $($arg)*);
    }};
}
use std::time::Instant;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Mesh file (Gmsh MSH 2.2 or 4.1, ASCII or binary) or built-in name.
    mesh: String,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

/// Everything `info` reports; the JSON field names are stable.
#[derive(Debug, Serialize)]
struct Info {
    mesh: String,
    format: String,
    vertices: usize,
    triangles: usize,
    quads: usize,
    surfaces: usize,
    components: usize,
    odd_components: usize,
    boundary_edges: usize,
    /// Edges of three or more elements: where surfaces meet (shell models).
    junction_edges: usize,
    /// Edges between two triangles of one surface on which a line element of the input lies
    /// (an embedded curve, a closed surface's seam): no quad is made across them.
    curve_edges: usize,
    /// Element nodes at exactly the position of another element node (distinct tags): the
    /// elements there are not joined, the mesh has a crack (surfaces meshed apart, not
    /// merged). Each node beyond the first at a position counts.
    coincident_nodes: usize,
    /// Neighbouring triangles of one surface (dual-graph edges) whose normals, consistently
    /// oriented, are more than 150 degrees apart: the surface folds back over itself (in a
    /// plane, the two overlap), or a knife edge. 0 on a quad-only file.
    folded_pairs: usize,
    candidate_pairs: usize,
    /// Candidate pairs whose quad is strictly convex (eta > 0): the actions under the
    /// default rule.
    valid_pairs: usize,
    reoriented_triangles: usize,
    ignored_elements: usize,
    /// The ignored elements per Gmsh type: "N Name (type T)", in increasing type.
    ignored_by_type: Vec<String>,
    /// eta statistics of the candidates; absent (null) when there are none.
    eta: Option<EtaStats>,
    /// eta statistics of the input quads (a recombined mesh's quads: their mean times their
    /// number is the run's quality); absent (null) when there are none.
    quad_eta: Option<EtaStats>,
    time_ms: Times,
}

#[derive(Debug, Serialize)]
struct EtaStats {
    min: f64,
    mean: f64,
    max: f64,
    /// Counts in ten bins of width 0.1 over [0, 1] (eta = 1 in the last bin).
    histogram: [usize; 10],
}

#[derive(Debug, Serialize)]
struct Times {
    /// Reading the file's bytes.
    read: f64,
    /// Parsing the bytes into nodes and elements.
    parse: f64,
    /// Validation and topology (`Mesh::new`).
    topology: f64,
    /// Candidate table with eta (`CandidateTable::build`).
    candidates: f64,
    /// Wall time from the start of the read to the end of the candidate table: the steps
    /// above run one after the other, so their sum is at most this.
    total: f64,
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn eta_stats(eta: &[f64]) -> Option<EtaStats> {
    if eta.is_empty() {
        return None;
    }
    let mut histogram = [0usize; 10];
    for &e in eta {
        histogram[((e * 10.0) as usize).min(9)] += 1;
    }
    Some(EtaStats {
        min: eta.iter().copied().fold(f64::INFINITY, f64::min),
        mean: eta.iter().sum::<f64>() / eta.len() as f64,
        max: eta.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        histogram,
    })
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    use super::oom::{self, Phase};
    oom::phase(Phase::Reading);
    let start = Instant::now();
    let t = Instant::now();
    let src = mesh::source(&args.mesh)?;
    let read = ms(t);
    let t = Instant::now();
    let file = mesh::msh::parse(&src.path, &src.bytes)?;
    let parse = ms(t);
    // The file's bytes are not needed past the parse: free them before the mesh is built.
    let src = mesh::Source {
        bytes: Vec::new().into(),
        ..src
    };
    let format = format!(
        "msh {} {}",
        file.version,
        if file.binary { "binary" } else { "ascii" }
    );
    let ignored_elements = file.ignored_elements;
    let ignored_by_type: Vec<String> = file.skipped.iter().map(ToString::to_string).collect();
    if file.data.triangles.is_empty() && !file.data.quads.is_empty() {
        // Quads only (a fully recombined mesh, say): nothing to recombine, but its size and
        // quad quality are worth reporting, once its elements are checked as any mesh's.
        let mut data = file.data;
        data.check_elements()
            .map_err(|source| mesh::ReadError::Mesh {
                path: src.path.clone(),
                source,
            })?;
        let (boundary_edges, junction_edges) = quad_edge_counts(&data.quads);
        let coincident_nodes = coincident(&data.vertices, data.quads.iter().flatten());
        let info = Info {
            mesh: args.mesh,
            format,
            vertices: data.vertices.len(),
            triangles: 0,
            quads: data.quads.len(),
            surfaces: data.surfaces().len(),
            components: 0,
            odd_components: 0,
            boundary_edges,
            junction_edges,
            curve_edges: 0,
            coincident_nodes,
            folded_pairs: 0,
            candidate_pairs: 0,
            valid_pairs: 0,
            reoriented_triangles: 0,
            ignored_elements,
            ignored_by_type,
            eta: None,
            quad_eta: eta_stats(&quad_etas(&data.vertices, &data.quads)),
            time_ms: Times {
                read,
                parse,
                topology: 0.0,
                candidates: 0.0,
                total: ms(start),
            },
        };
        return print(&info, args.json);
    }
    oom::phase(Phase::Mesh);
    oom::mesh_size(file.data.triangles.len());
    let t = Instant::now();
    let m = file.into_mesh(&src.path)?;
    let topology = ms(t);
    oom::phase(Phase::Candidates);
    let t = Instant::now();
    let table = CandidateTable::build(&m);
    let candidates = ms(t);
    let total = ms(start);

    let topo = &m.topology;
    let info = Info {
        mesh: args.mesh,
        format,
        vertices: m.vertices.len(),
        triangles: m.num_triangles(),
        quads: m.quads.len(),
        surfaces: m.surfaces().len(),
        components: topo.component_sizes.len(),
        odd_components: topo.component_sizes.iter().filter(|&&s| s % 2 == 1).count(),
        boundary_edges: topo.num_boundary_edges,
        junction_edges: topo.num_junction_edges,
        curve_edges: topo.num_curve_edges,
        coincident_nodes: coincident(
            &m.vertices,
            m.triangles.iter().flatten().chain(m.quads.iter().flatten()),
        ),
        // More than 150 degrees: a fold, not the right-angle edge of a box meshed as one
        // surface (a coarse cylinder's 120 degrees neither).
        folded_pairs: (table.quads.iter())
            .filter(|q| quality::normals_cos(q.map(|v| m.vertices[v as usize])) < -0.866_025_4)
            .count(),
        candidate_pairs: table.len(),
        valid_pairs: (table.eta.iter().zip(&table.quads))
            .filter(|&(&e, q)| Rule::default().allows_pair(e, q.map(|v| m.vertices[v as usize])))
            .count(),
        reoriented_triangles: m.reoriented,
        ignored_elements,
        ignored_by_type,
        eta: eta_stats(&table.eta),
        quad_eta: eta_stats(&quad_etas(&m.vertices, &m.quads)),
        time_ms: Times {
            read,
            parse,
            topology,
            candidates,
            total,
        },
    };
    print(&info, args.json)
}

/// How many of the vertices that `used` names (with repeats) lie exactly where another of
/// them lies (each beyond the first at a position; -0 and 0 are one coordinate).
fn coincident<'a>(vertices: &[[f64; 3]], used: impl Iterator<Item = &'a u32>) -> usize {
    let mut seen = vec![false; vertices.len()];
    let mut at = Vec::new();
    for &v in used {
        if !std::mem::replace(&mut seen[v as usize], true) {
            // Adding 0.0 turns -0.0 into 0.0.
            at.push(vertices[v as usize].map(|x| (x + 0.0).to_bits()));
        }
    }
    at.sort_unstable();
    at.windows(2).filter(|w| w[0] == w[1]).count()
}

/// eta of each input quad (checked vertex indices): [`quality::input_quad_eta`], whose
/// diagonal runs from the first vertex to the third, as `recombine` writes them.
fn quad_etas(vertices: &[[f64; 3]], quads: &[[u32; 4]]) -> Vec<f64> {
    quads
        .iter()
        .map(|q| quality::input_quad_eta(q.map(|v| vertices[v as usize])))
        .collect()
}

/// Prints `info` as text or JSON.
fn print(info: &Info, json: bool) -> anyhow::Result<ExitCode> {
    let out = if json {
        serde_json::to_string_pretty(info)? + "\n"
    } else {
        text(info)
    };
    // A closed pipe (`| head`) is not an error worth a panic or a message.
    match std::io::stdout().write_all(out.as_bytes()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => Err(e.into()),
        _ => Ok(ExitCode::SUCCESS),
    }
}

fn text(i: &Info) -> String {
    let mut s = String::new();
    wln!(s, "mesh:                 {} ({})", i.mesh, i.format);
    wln!(s, "vertices:             {}", i.vertices);
    wln!(s, "triangles:            {}", i.triangles);
    wln!(s, "quads (input):        {}", i.quads);
    wln!(s, "surfaces:             {}", i.surfaces);
    wln!(
        s,
        "components:           {} ({} with an odd number of triangles)",
        i.components,
        i.odd_components
    );
    wln!(s, "boundary edges:       {}", i.boundary_edges);
    if i.junction_edges > 0 {
        wln!(
            s,
            "junction edges:       {} (three or more elements: surfaces meet there)",
            i.junction_edges
        );
    }
    if i.curve_edges > 0 {
        wln!(
            s,
            "curve edges:          {} (inside a surface, on a line element: an embedded curve or \
             a seam; no quad is made across them)",
            i.curve_edges
        );
    }
    if i.coincident_nodes > 0 {
        wln!(
            s,
            "coincident nodes:     {} (at the position of another node: the elements there are \
             not joined, a crack unless meant, e.g. a contact interface; to join them: Gmsh's \
             Coherence Mesh, gmsh.model.mesh.removeDuplicateNodes())",
            i.coincident_nodes
        );
    }
    if i.folded_pairs > 0 {
        wln!(
            s,
            "folded pairs:         {} (neighbouring triangles whose normals are more than 150 \
             degrees apart: the surface folds back over itself there, or in a plane the two \
             overlap; a mesh error unless meant, as a knife edge can be; no valid quad is made \
             of them)",
            i.folded_pairs
        );
    }
    wln!(
        s,
        "candidate pairs:      {} ({} make a valid quad, eta > 0)",
        i.candidate_pairs,
        i.valid_pairs
    );
    wln!(s, "reoriented triangles: {}", i.reoriented_triangles);
    if i.ignored_elements > 0 {
        wln!(
            s,
            "ignored elements:     {} ({})",
            i.ignored_elements,
            i.ignored_by_type.join(", ")
        );
    }
    match &i.eta {
        Some(e) => {
            wln!(
                s,
                "candidate eta:        min {:.4}  mean {:.4}  max {:.4}",
                e.min,
                e.mean,
                e.max
            );
            let top = e.histogram.iter().copied().max().unwrap_or(1).max(1);
            for (k, &n) in e.histogram.iter().enumerate() {
                let bar = "#".repeat((40 * n).div_ceil(top));
                wln!(
                    s,
                    "  [{:.1}, {:.1}{} {:>8}  {bar}",
                    k as f64 / 10.0,
                    (k + 1) as f64 / 10.0,
                    if k == 9 { "]" } else { ")" },
                    n
                );
            }
        }
        None => wln!(s, "candidate eta:        (no candidates)"),
    }
    if let Some(e) = &i.quad_eta {
        wln!(
            s,
            "quad eta (input):     min {:.4}  mean {:.4}  max {:.4}  (sum {:.4})",
            e.min,
            e.mean,
            e.max,
            e.mean * i.quads as f64
        );
    }
    let t = &i.time_ms;
    wln!(
        s,
        "time:                 read {:.2} ms, parse {:.2} ms, topology {:.2} ms, candidates \
         {:.2} ms, one after the other; {:.2} ms in all (wall)",
        t.read,
        t.parse,
        t.topology,
        t.candidates,
        t.total
    );
    s
}

/// Edges used by exactly one quad, and by three or more (a mesh of quads only has no
/// topology built).
fn quad_edge_counts(quads: &[[u32; 4]]) -> (usize, usize) {
    let mut edges: Vec<(u32, u32)> = quads
        .iter()
        .flat_map(|q| (0..4).map(move |i| (q[i].min(q[(i + 1) % 4]), q[i].max(q[(i + 1) % 4]))))
        .collect();
    edges.sort_unstable();
    let uses = || edges.chunk_by(|a, b| a == b).map(<[_]>::len);
    (
        uses().filter(|&n| n == 1).count(),
        uses().filter(|&n| n > 2).count(),
    )
}
