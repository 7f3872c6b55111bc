//! Benchmark meshes: the embedded built-in files and the procedural generators (grid,
//! icosphere), through the library and the `generate` subcommand.

use crate::util::{SEED, gmsh_available, python, repo_path, run_in};
use quadrecomb::internals::mesh::generate::{
    self, GenerateError, GridSpec, MAX_SUBDIVISIONS, grid, icosphere, icosphere_with_triangles,
};
use quadrecomb::internals::mesh::{Mesh, NONE, builtin};
use std::collections::HashSet;

/// V - E + F over the triangles.
fn euler(mesh: &Mesh) -> i64 {
    let used: HashSet<u32> = mesh.triangles.iter().flatten().copied().collect();
    used.len() as i64 - mesh.topology.num_edges as i64 + mesh.num_triangles() as i64
}

fn checked(mesh: Mesh) -> Mesh {
    mesh.sanity_check().expect("sanity check");
    assert_eq!(mesh.reoriented, 0, "generators orient consistently");
    mesh
}

fn spec(triangles: usize) -> GridSpec {
    GridSpec {
        triangles,
        seed: SEED,
        ..GridSpec::default()
    }
}

// ---------------------------------------------------------------- built-in meshes

/// Reads the header of the `$Elements` section of an MSH 4.1 binary file (8-byte size_t,
/// little endian) and the element type of every block: (element count, types).
fn msh41_binary_elements(bytes: &[u8]) -> (u64, Vec<i32>) {
    let at = |tag: &[u8]| {
        bytes
            .windows(tag.len())
            .position(|w| w == tag)
            .expect("section present")
            + tag.len()
    };
    let u64_at = |p: usize| u64::from_le_bytes(bytes[p..p + 8].try_into().unwrap());
    let i32_at = |p: usize| i32::from_le_bytes(bytes[p..p + 4].try_into().unwrap());
    let mut p = at(b"$Elements\n");
    let (blocks, count) = (u64_at(p), u64_at(p + 8));
    p += 32;
    let mut types = Vec::new();
    for _ in 0..blocks {
        let ty = i32_at(p + 8);
        let n = u64_at(p + 12) as usize;
        let nodes_per = match ty {
            2 => 3,
            3 => 4,
            _ => panic!("unexpected element type {ty}"),
        };
        types.push(ty);
        p += 20 + n * 8 * (1 + nodes_per);
    }
    assert_eq!(
        &bytes[p..],
        b"\n$EndElements\n",
        "element blocks fill the section"
    );
    (count, types)
}

/// The node count in the `$Nodes` header of an MSH 4.1 binary file.
fn msh41_binary_nodes(bytes: &[u8]) -> u64 {
    let p = bytes
        .windows(7)
        .position(|w| w == b"$Nodes\n")
        .expect("$Nodes")
        + 7;
    u64::from_le_bytes(bytes[p + 8..p + 16].try_into().unwrap())
}

#[test]
fn builtin_files_are_embedded_and_have_the_expected_triangles() {
    let expected = [("borouchaki", 34_456, 17_584), ("sphere", 2_104, 1_054)];
    assert_eq!(builtin::NAMES.len(), expected.len());
    for (name, triangles, nodes) in expected {
        assert!(builtin::NAMES.contains(&name));
        let bytes = builtin::bytes(name).expect("embedded");
        let on_disk = std::fs::read(repo_path(&format!("meshes/{name}.msh"))).unwrap();
        assert!(bytes == on_disk.as_slice(), "{name}: embedded bytes differ");
        let (count, types) = msh41_binary_elements(bytes);
        assert_eq!(count, triangles, "{name}");
        assert_eq!(msh41_binary_nodes(bytes), nodes, "{name}");
        assert!(types.iter().all(|&t| t == 2), "{name}: only triangles");
    }
    assert!(builtin::bytes("nope").is_none());
}

/// The committed files are what `scripts/make_meshes.py` makes (when Python has `gmsh`).
#[test]
fn builtin_files_are_reproducible_with_gmsh() {
    if !gmsh_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = std::process::Command::new("python3")
        .arg(repo_path("scripts/make_meshes.py"))
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The script itself fails on a count other than the expected one or on a rerun that
    // differs. Identical bytes to the committed file are expected with the same wheel on
    // x86_64 Linux, but floating-point paths may differ on other CPUs: counts must match,
    // bytes are reported.
    for name in builtin::NAMES {
        let made = std::fs::read(dir.path().join(format!("{name}.msh"))).unwrap();
        let committed = builtin::bytes(name).unwrap();
        assert_eq!(
            (msh41_binary_nodes(&made), msh41_binary_elements(&made)),
            (
                msh41_binary_nodes(committed),
                msh41_binary_elements(committed)
            ),
            "{name}: regenerated mesh differs in size from the committed one\n{text}"
        );
        if made != committed {
            eprintln!("note: {name}: regenerated file has the same counts, other bytes\n{text}");
        }
    }
}

/// The built-ins load by name (from any directory) into valid meshes of the expected size.
#[test]
fn builtin_meshes_load_by_name() {
    for (name, triangles, vertices, euler_characteristic, boundary) in [
        ("borouchaki", 34_456, 17_584, 0, true),
        ("sphere", 2_104, 1_054, 2, false),
    ] {
        let mesh = checked(quadrecomb::internals::mesh::load(name).expect(name));
        assert_eq!(mesh.num_triangles(), triangles, "{name}");
        assert_eq!(mesh.vertices.len(), vertices, "{name}");
        assert_eq!(mesh.surfaces(), vec![1], "{name}");
        assert_eq!(
            mesh.topology.component_sizes,
            vec![triangles as u32],
            "{name}"
        );
        assert_eq!(euler(&mesh), euler_characteristic, "{name}");
        assert_eq!((mesh.topology.num_boundary_edges > 0), boundary, "{name}");
    }
    // From another directory, through the CLI.
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), &["info", "borouchaki"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("34456"));
}

// ---------------------------------------------------------------- grid

#[test]
fn grid_counts_topology_and_geometry() {
    for target in [2usize, 3, 100, 1000, 12_345, 34_456] {
        let s = spec(target);
        let (nx, ny) = s.cells();
        let mesh = checked(grid(s));
        assert_eq!(mesh.num_triangles(), 2 * nx * ny, "{target}");
        assert_eq!(mesh.num_triangles(), s.triangle_count());
        // Within one row of cells of the target (and exact whenever 2 * nx * ny can be).
        assert!(mesh.num_triangles().abs_diff(target) <= 2 * nx, "{target}");
        assert_eq!(mesh.vertices.len(), (nx + 1) * (ny + 1));
        assert_eq!(
            mesh.topology.component_sizes,
            vec![mesh.num_triangles() as u32]
        );
        assert_eq!(mesh.surfaces(), vec![1]);
        assert_eq!(mesh.topology.num_boundary_edges, 2 * (nx + ny));
        assert_eq!(euler(&mesh), 1, "a disk");
        for v in &mesh.vertices {
            assert!((0.0..=1.0).contains(&v[0]) && (0.0..=1.0).contains(&v[1]) && v[2] == 0.0);
        }
        // Counter-clockwise in the plane.
        for t in 0..mesh.num_triangles() as u32 {
            let [a, b, c] = mesh.triangle_points(t);
            let area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
            assert!(area > 0.0);
        }
    }
    assert_eq!(grid(spec(1_000_000)).num_triangles(), 1_000_000);
}

#[test]
fn grid_is_deterministic_and_seeds_differ() {
    let a = grid(spec(2000));
    let s = spec(2000);
    #[allow(
        clippy::needless_borrows_for_generic_args,
        reason = "grid takes a reference too"
    )]
    let b = grid(&s);
    assert_eq!(s.triangles, 2000);
    assert_eq!(a.vertices, b.vertices);
    assert_eq!(a.triangles, b.triangles);
    let c = grid(GridSpec {
        seed: SEED + 1,
        ..spec(2000)
    });
    assert_eq!(c.num_triangles(), a.num_triangles());
    assert_ne!(a.vertices, c.vertices, "jitter depends on the seed");
    assert_ne!(a.triangles, c.triangles, "diagonals depend on the seed");
}

/// BLAKE3 of a mesh's coordinates (bits), triangles and surfaces.
fn mesh_hash(mesh: &Mesh) -> String {
    let mut h = blake3::Hasher::new();
    for v in &mesh.vertices {
        for c in v {
            h.update(&c.to_bits().to_le_bytes());
        }
    }
    for (t, s) in mesh.triangles.iter().zip(&mesh.triangle_surface) {
        for v in t {
            h.update(&v.to_le_bytes());
        }
        h.update(&s.to_le_bytes());
    }
    h.finalize().to_hex()[..16].to_string()
}

/// Golden values: the generators give the same meshes on every machine and in every version
/// (benchmarks and recorded results name meshes by their generator arguments). If a change
/// to the generator is intended, update these and say so in the commit.
#[test]
fn generators_are_stable_across_machines_and_versions() {
    let cases = [
        (mesh_hash(&grid(spec(1000))), "bdedd16ba0a31b4a"),
        (
            mesh_hash(&grid(GridSpec {
                holes: true,
                surfaces: 3,
                drop_triangles: 4,
                ..spec(3000)
            })),
            "1ada5f15f2598b80",
        ),
        (mesh_hash(&icosphere(3)), "4024f58d52615932"),
    ];
    let (got, want): (Vec<String>, Vec<&str>) = cases.into_iter().unzip();
    assert_eq!(got, want);
}

#[test]
fn grid_jitter_keeps_the_boundary_and_moves_the_interior() {
    let s = spec(800);
    let (nx, ny) = s.cells();
    let still = checked(grid(GridSpec { jitter: 0.0, ..s }));
    let moved = checked(grid(s));
    let on_lattice = |v: &[f64; 3]| {
        let (x, y) = (v[0] * nx as f64, v[1] * ny as f64);
        (x - x.round()).abs() < 1e-9 && (y - y.round()).abs() < 1e-9
    };
    assert!(still.vertices.iter().all(on_lattice));
    let off = moved.vertices.iter().filter(|v| !on_lattice(v)).count();
    let interior = (nx - 1) * (ny - 1);
    assert!(
        off >= interior,
        "{off} of {interior} interior vertices moved"
    );
    let edges = moved.edges();
    for &e in &edges.boundary_edges {
        for v in edges.edges[e as usize] {
            let [x, y, _] = moved.vertices[v as usize];
            assert!(
                x == 0.0 || x == 1.0 || y == 0.0 || y == 1.0,
                "({x}, {y}) left the boundary"
            );
        }
    }
    // Corners stay.
    for corner in [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ] {
        assert!(moved.vertices.contains(&corner));
    }
    // The largest legal jitter still gives a valid mesh.
    checked(grid(GridSpec {
        jitter: 0.2499,
        ..spec(5000)
    }));
}

#[test]
fn grid_with_hole() {
    let s = GridSpec {
        holes: true,
        ..spec(1800)
    };
    let (nx, ny) = s.cells();
    let (hx, hy) = (nx - 2 * (nx / 3), ny - 2 * (ny / 3));
    let mesh = checked(grid(s));
    assert_eq!(mesh.num_triangles(), 2 * (nx * ny - hx * hy));
    assert_eq!(mesh.num_triangles(), s.triangle_count());
    assert_eq!(mesh.topology.component_sizes.len(), 1);
    assert_eq!(euler(&mesh), 0, "an annulus");
    assert_eq!(
        mesh.topology.num_boundary_edges,
        2 * (nx + ny) + 2 * (hx + hy)
    );
    // No vertex left inside the hole.
    assert_eq!(
        mesh.vertices.len(),
        (nx + 1) * (ny + 1) - (hx - 1) * (hy - 1)
    );
    // The smallest grid that can have a hole.
    let tiny = checked(grid(GridSpec {
        holes: true,
        ..spec(18)
    }));
    assert_eq!(tiny.num_triangles(), 16);
    assert_eq!(euler(&tiny), 0);
}

#[test]
fn grid_with_surfaces_splits_the_dual_graph() {
    for surfaces in [2u32, 3, 5] {
        let s = GridSpec {
            surfaces,
            ..spec(1000)
        };
        let (nx, ny) = s.cells();
        let mesh = checked(grid(s));
        let tags: Vec<i32> = (1..=surfaces as i32).collect();
        assert_eq!(mesh.surfaces(), tags);
        assert_eq!(mesh.topology.component_sizes.len(), surfaces as usize);
        // Each strip is one component of 2 * ny * (its columns) triangles.
        let mut expected = vec![0u32; surfaces as usize];
        for i in 0..nx {
            expected[i * surfaces as usize / nx] += 2 * ny as u32;
        }
        assert_eq!(mesh.topology.component_sizes, expected);
        for (t, n) in mesh.topology.neighbours.iter().enumerate() {
            for &u in n {
                if u != NONE {
                    assert_eq!(mesh.triangle_surface[t], mesh.triangle_surface[u as usize]);
                }
            }
        }
        // The interface edges are shared (not boundary) but not dual edges.
        assert_eq!(mesh.topology.num_boundary_edges, 2 * (nx + ny));
        let dual_edges = 3 * mesh.num_triangles() - 2 * (nx + ny);
        assert_eq!(
            mesh.topology.num_dual_edges(),
            dual_edges / 2 - (surfaces as usize - 1) * ny
        );
    }
    // With an even number of columns, 2 surfaces meet at x = 0.5.
    let s = GridSpec {
        surfaces: 2,
        jitter: 0.0,
        ..spec(800)
    };
    assert_eq!(s.cells(), (20, 20));
    let mesh = grid(s);
    for t in 0..mesh.num_triangles() as u32 {
        let p = mesh.triangle_points(t);
        let cx = (p[0][0] + p[1][0] + p[2][0]) / 3.0;
        assert_eq!(
            mesh.triangle_surface[t as usize],
            if cx < 0.5 { 1 } else { 2 }
        );
    }
}

#[test]
fn grid_with_dropped_triangles_has_odd_components() {
    let s = GridSpec {
        drop_triangles: 1,
        ..spec(1000)
    };
    let mesh = checked(grid(s));
    assert_eq!(mesh.num_triangles(), 999);
    assert_eq!(mesh.topology.component_sizes, vec![999]);
    assert_eq!(euler(&mesh), 0, "the dropped triangle is a hole");

    let s = GridSpec {
        drop_triangles: 7,
        ..spec(5000)
    };
    let mesh = checked(grid(s));
    assert_eq!(mesh.num_triangles(), s.triangle_count());
    assert_eq!(mesh.topology.component_sizes.len(), 1);
    assert_eq!(euler(&mesh), 1 - 7);
    let other = grid(GridSpec {
        seed: SEED + 1,
        ..s
    });
    assert_ne!(mesh.triangles, other.triangles, "drops depend on the seed");

    // Everything at once: 2 strips around a hole, 3 drops: still one component per strip,
    // with parities flipped by the drops in it.
    let s = GridSpec {
        holes: true,
        surfaces: 2,
        drop_triangles: 3,
        ..spec(4000)
    };
    let (nx, ny) = s.cells();
    let mesh = checked(grid(s));
    assert_eq!(mesh.num_triangles(), s.triangle_count());
    assert_eq!(mesh.topology.component_sizes.len(), 2);
    assert_eq!(euler(&mesh), -3);
    let full = grid(GridSpec {
        drop_triangles: 0,
        ..s
    });
    // Components are numbered from their first triangle: the left strip is 0 in both.
    let mut drops = 0;
    for strip in 0..2 {
        let (before, after) = (
            full.topology.component_sizes[strip],
            mesh.topology.component_sizes[strip],
        );
        assert_eq!(before % 2, 0, "whole cells");
        assert!(after <= before);
        drops += before - after;
    }
    assert_eq!(drops, 3);
    assert!(mesh.topology.component_sizes.iter().any(|s| s % 2 == 1));
    assert!(nx >= 3 && ny >= 3);
}

#[test]
fn grid_rejects_bad_specs() {
    let bad = [
        (spec(1), GenerateError::TooFewTriangles(1)),
        (
            GridSpec {
                jitter: 0.25,
                ..spec(100)
            },
            GenerateError::Jitter(0.25),
        ),
        (
            GridSpec {
                jitter: -0.1,
                ..spec(100)
            },
            GenerateError::Jitter(-0.1),
        ),
        (
            GridSpec {
                holes: true,
                ..spec(8)
            },
            GenerateError::GridTooSmallForHole { nx: 2, ny: 2 },
        ),
        (
            GridSpec {
                surfaces: 0,
                ..spec(100)
            },
            GenerateError::Surfaces { surfaces: 0, nx: 7 },
        ),
        (
            GridSpec {
                surfaces: 8,
                ..spec(100)
            },
            GenerateError::Surfaces { surfaces: 8, nx: 7 },
        ),
        (
            GridSpec {
                drop_triangles: 10,
                ..spec(100)
            },
            GenerateError::TooManyDrops {
                asked: 10,
                available: 9,
            },
        ),
    ];
    let nx = spec(100).cells().0;
    assert_eq!(nx, 7);
    for (s, err) in bad {
        assert_eq!(s.validate(), Err(err.clone()), "{s:?}");
        let panic = std::panic::catch_unwind(|| grid(s));
        assert!(panic.is_err(), "grid({s:?}) must panic");
    }
    assert!(
        GridSpec {
            jitter: f64::NAN,
            ..spec(100)
        }
        .validate()
        .is_err()
    );
}

// ---------------------------------------------------------------- icosphere

#[test]
fn icosphere_is_a_closed_outward_unit_sphere() {
    for s in 0..=4u32 {
        let mesh = checked(icosphere(s));
        let n = 20 * 4usize.pow(s);
        assert_eq!(mesh.num_triangles(), n);
        assert_eq!(mesh.vertices.len(), 10 * 4usize.pow(s) + 2);
        assert!((mesh.topology.num_boundary_edges == 0));
        assert!(
            mesh.topology
                .neighbours
                .iter()
                .flatten()
                .all(|&u| u != NONE)
        );
        assert_eq!(mesh.topology.component_sizes, vec![n as u32]);
        assert_eq!(euler(&mesh), 2);
        for v in &mesh.vertices {
            let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            assert!((r - 1.0).abs() < 1e-12);
        }
        for t in 0..n as u32 {
            let [a, b, c] = mesh.triangle_points(t);
            let (u, w) = (
                [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
                [c[0] - a[0], c[1] - a[1], c[2] - a[2]],
            );
            let normal = [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ];
            let centre = [a[0] + b[0] + c[0], a[1] + b[1] + c[1], a[2] + b[2] + c[2]];
            let out: f64 = (0..3).map(|k| normal[k] * centre[k]).sum();
            assert!(out > 0.0, "triangle {t} of level {s} faces inward");
        }
    }
}

#[test]
fn icosphere_by_triangle_count() {
    assert_eq!(icosphere_with_triangles(2104).num_triangles(), 1280);
    assert_eq!(icosphere_with_triangles(5000).num_triangles(), 5120);
    assert_eq!(icosphere_with_triangles(1).num_triangles(), 20);
    assert_eq!(generate::subdivisions_for(usize::MAX), MAX_SUBDIVISIONS);
    assert!(std::panic::catch_unwind(|| icosphere(MAX_SUBDIVISIONS + 1)).is_err());
}

// ---------------------------------------------------------------- `quadrecomb generate`

/// Reads a small MSH 4.1 ASCII file as written by `generate`: (node count, triangles with
/// their entity tags), checking the section counts against the content.
fn read_msh41_ascii(text: &str) -> (usize, Vec<(i32, [u64; 3])>) {
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("$MeshFormat"));
    assert_eq!(lines.next(), Some("4.1 0 8"));
    let mut nodes = HashSet::new();
    let mut triangles = Vec::new();
    let nums = |l: &str| -> Vec<f64> { l.split_whitespace().map(|w| w.parse().unwrap()).collect() };
    while let Some(line) = lines.next() {
        match line {
            "$Nodes" => {
                let h = nums(lines.next().unwrap());
                let mut seen = 0;
                for _ in 0..h[0] as usize {
                    let b = nums(lines.next().unwrap());
                    let n = b[3] as usize;
                    let tags: Vec<u64> = (0..n)
                        .map(|_| lines.next().unwrap().trim().parse().unwrap())
                        .collect();
                    for _ in 0..n {
                        assert_eq!(nums(lines.next().unwrap()).len(), 3);
                    }
                    seen += n;
                    nodes.extend(tags);
                }
                assert_eq!(seen, h[1] as usize);
                assert_eq!(lines.next(), Some("$EndNodes"));
            }
            "$Elements" => {
                let h = nums(lines.next().unwrap());
                for _ in 0..h[0] as usize {
                    let b = nums(lines.next().unwrap());
                    assert_eq!(b[2], 2.0, "triangles");
                    for _ in 0..b[3] as usize {
                        let e = nums(lines.next().unwrap());
                        let tri = [e[1] as u64, e[2] as u64, e[3] as u64];
                        assert!(tri.iter().all(|v| nodes.contains(v)));
                        triangles.push((b[1] as i32, tri));
                    }
                }
                assert_eq!(triangles.len(), h[1] as usize);
                assert_eq!(lines.next(), Some("$EndElements"));
            }
            _ => {}
        }
    }
    (nodes.len(), triangles)
}

#[test]
fn cli_generate_grid_writes_the_library_grid() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(
        dir.path(),
        &[
            "generate",
            "grid",
            "--triangles",
            "1000",
            "--seed",
            "7",
            "--surfaces",
            "2",
            "-o",
            "g.msh",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("1000 triangles"), "{stdout}");
    let text = std::fs::read_to_string(dir.path().join("g.msh")).unwrap();
    let (nodes, triangles) = read_msh41_ascii(&text);
    // The same arguments write the same file.
    let again = run_in(
        dir.path(),
        &[
            "generate",
            "grid",
            "--triangles",
            "1000",
            "--seed",
            "7",
            "--surfaces",
            "2",
            "-o",
            "g2.msh",
        ],
    );
    assert!(again.status.success());
    assert!(text == std::fs::read_to_string(dir.path().join("g2.msh")).unwrap());
    let mesh = grid(GridSpec {
        triangles: 1000,
        seed: 7,
        surfaces: 2,
        ..GridSpec::default()
    });
    assert_eq!(nodes, mesh.vertices.len());
    let expected: Vec<(i32, [u64; 3])> = mesh
        .triangles
        .iter()
        .zip(&mesh.triangle_surface)
        .map(|(t, &s)| (s, t.map(|v| mesh.vertex_ids[v as usize])))
        .collect();
    let (mut a, mut b) = (triangles, expected);
    a.sort_unstable();
    b.sort_unstable();
    assert_eq!(a, b);
    // Read back by the library: same coordinates (exactly) per node, same topology.
    let back = checked(quadrecomb::internals::mesh::msh::read(&dir.path().join("g.msh")).unwrap());
    let by_id = |m: &Mesh| {
        let mut v: Vec<(u64, [f64; 3])> = m
            .vertex_ids
            .iter()
            .copied()
            .zip(m.vertices.iter().copied())
            .collect();
        v.sort_unstable_by_key(|p| p.0);
        v
    };
    assert!(
        by_id(&back) == by_id(&mesh),
        "coordinates round-trip exactly"
    );
    assert_eq!(back.topology.component_sizes, mesh.topology.component_sizes);
    assert_eq!(back.surfaces(), vec![1, 2]);

    // Gmsh opens it with the same counts.
    if !gmsh_available() {
        return;
    }
    let script = "import gmsh, sys\n\
        gmsh.initialize(readConfigFiles=False)\n\
        gmsh.option.setNumber('General.Terminal', 0)\n\
        gmsh.open(sys.argv[1])\n\
        types, tags, _ = gmsh.model.mesh.getElements(2)\n\
        print(len(gmsh.model.mesh.getNodes()[0]), sum(len(t) for t in tags), \n\
              len(gmsh.model.getEntities(2)), [int(t) for t in types])\n";
    let line = python(script, &[&dir.path().join("g.msh")]);
    assert_eq!(
        line.trim(),
        format!("{} {} 2 [2]", mesh.vertices.len(), mesh.num_triangles())
    );
}

#[test]
fn cli_generate_icosphere() {
    let dir = tempfile::tempdir().unwrap();
    for (args, n) in [
        (&["--subdivisions", "2"][..], 320),
        (&["--triangles", "5000"][..], 5120),
    ] {
        let mut all = vec!["generate", "icosphere"];
        all.extend(args);
        all.extend(["-o", "s.msh"]);
        let out = run_in(dir.path(), &all);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = std::fs::read_to_string(dir.path().join("s.msh")).unwrap();
        let (nodes, triangles) = read_msh41_ascii(&text);
        assert_eq!(triangles.len(), n);
        assert_eq!(nodes, n / 2 + 2);
    }
}

#[test]
fn cli_generate_rejects_bad_arguments_with_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["generate", "grid", "--triangles", "1", "-o", "x.msh"][..],
        &[
            "generate",
            "grid",
            "--triangles",
            "100",
            "--jitter",
            "0.3",
            "-o",
            "x.msh",
        ],
        &[
            "generate",
            "icosphere",
            "--subdivisions",
            "11",
            "-o",
            "x.msh",
        ],
        &[
            "generate",
            "icosphere",
            "--triangles",
            "18446744073709551615",
            "-o",
            "x.msh",
        ],
        &[
            "generate",
            "grid",
            "--triangles",
            "100",
            "-o",
            "no/such/dir/x.msh",
        ],
    ] {
        let out = run_in(dir.path(), args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.starts_with("error: "), "{err}");
    }
    assert!(!dir.path().join("x.msh").exists());
    // Usage errors (clap): neither or both of --subdivisions / --triangles.
    let out = run_in(dir.path(), &["generate", "icosphere", "-o", "x.msh"]);
    assert_eq!(out.status.code(), Some(2));
}
