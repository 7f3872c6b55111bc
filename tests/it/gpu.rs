//! GPU quality kernel: naga validation of every shader (no GPU needed), and differential
//! tests of the kernel on a Vulkan adapter (lavapipe in CI) against the f64 reference
//! `CandidateTable::build` / `quality::quad_eta` and the f32 CPU twin.
//!
//! Without an adapter the device tests print "SKIPPED: no Vulkan adapter" and pass, except
//! when `CI` is set: then they fail.

use crate::util::{SEED, repo_path};
use quadrecomb::internals::gpu::{
    self, Backend, Batch, Evaluator, Kernel, KernelOptions, Layout, layout::Vertex,
};
use quadrecomb::internals::mesh::{Mesh, MeshData};
use quadrecomb::internals::quality::{self, CandidateTable};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Largest |GPU - f64| allowed.
const TOL: f64 = 1e-5;
/// Largest |GPU - CPU twin| allowed (same f32 function; only rounding order and FMA differ).
const TWIN_TOL: f64 = 2e-6;
/// Angles within DELTA of the convexity limits (0 and pi) are borderline: there f32 may
/// decide either way (eta there is at most 2 DELTA / pi < TOL, so the tolerance still holds).
/// Outside that band the decision eta = 0 must be the same as in f64.
const DELTA: f64 = 1e-5;

#[test]
fn every_shader_parses_and_validates_with_naga() {
    let dir = repo_path("shaders");
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).expect("shaders/ exists") {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "wgsl") {
            continue;
        }
        let source = std::fs::read_to_string(&path).unwrap();
        let shown = path
            .strip_prefix(repo_path(""))
            .unwrap_or(&path)
            .display()
            .to_string();
        if let Err(e) = gpu::shader::validate(&source, &shown) {
            panic!("{e}");
        }
        seen += 1;
    }
    assert!(seen >= 1, "no shader found in {}", dir.display());
    // The embedded copy is the file on disk.
    let on_disk = std::fs::read_to_string(repo_path(gpu::shader::QUAD_QUALITY_PATH)).unwrap();
    assert_eq!(on_disk, gpu::shader::QUAD_QUALITY);
}

struct Dev {
    device: wgpu::Device,
    queue: wgpu::Queue,
    kernel: Kernel,
    local: Kernel,
}

/// The test device, opened once: the first adapter the loader gives (point
/// `VK_DRIVER_FILES` at lavapipe to choose it). None, with a visible message, when there is
/// no adapter; a failure when `CI` is set.
fn dev() -> Option<&'static Dev> {
    static DEV: OnceLock<Option<Dev>> = OnceLock::new();
    let dev = DEV.get_or_init(|| {
        let adapters = gpu::adapters();
        for a in &adapters {
            eprintln!(
                "adapter found: {} ({:?})",
                gpu::adapter_name(&a.get_info()),
                a.get_info().device_type
            );
        }
        let adapter = adapters.first()?;
        let (device, queue) = gpu::open_device(adapter).expect("open the device");
        let kernel = Kernel::new(&device).expect("build the kernel");
        let name = gpu::adapter_name(&adapter.get_info());
        eprintln!(
            "GPU tests run on: {name} (timestamps: {})",
            kernel.has_timestamps()
        );
        let local = Kernel::with_layout(&device, Layout::Local).expect("build the local kernel");
        Some(Dev {
            device,
            queue,
            kernel,
            local,
        })
    });
    if dev.is_none() {
        if std::env::var_os("CI").is_some() {
            panic!("no Vulkan adapter found and CI is set: install lavapipe (mesa-vulkan-drivers)");
        }
        eprintln!("SKIPPED: no Vulkan adapter");
    }
    dev.as_ref()
}

fn run(d: &Dev, batch: &Batch) -> Vec<f32> {
    d.kernel
        .run(&d.device, &d.queue, batch)
        .expect("kernel runs")
        .0
}

/// The precomputed-edges layout on the device and its CPU twin.
fn run_local(d: &Dev, batch: &Batch) -> (Vec<f32>, Vec<f32>) {
    let eta = d
        .local
        .run(&d.device, &d.queue, batch)
        .expect("local kernel runs")
        .0;
    (
        eta,
        gpu::cpu::quad_quality_local(&batch.local_quads(0..batch.len())),
    )
}

/// f64 angles of the quad, as `quality::quad_eta` computes them.
fn angles64(p: [[f64; 3]; 4]) -> [f64; 4] {
    let [s0, o1, s1, o0] = p;
    [
        quality::angle(s0, s1, o0) + quality::angle(s0, o1, s1),
        quality::angle(o1, s0, s1),
        quality::angle(s1, o0, s0) + quality::angle(s1, s0, o1),
        quality::angle(o0, s1, s0),
    ]
}

/// Cosine of the angle between the normals of the quad's two triangles `(s0, s1, o0)` and
/// `(s1, s0, o1)`: at or below 0 the pair is folded over its diagonal (no quad).
fn fold_cos(p: [[f64; 3]; 4]) -> f64 {
    let [s0, o1, s1, o0] = p;
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let n0 = cross(sub(s1, s0), sub(o0, s0));
    let n1 = cross(sub(s0, s1), sub(o1, s1));
    let dot: f64 = (0..3).map(|k| n0[k] * n1[k]).sum();
    let norm = |n: [f64; 3]| (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    dot / (norm(n0) * norm(n1)).max(f64::MIN_POSITIVE)
}

#[derive(Debug, Default)]
struct Report {
    n: usize,
    worst: f64,
    worst_twin: f64,
    borderline: usize,
    zero: usize,
}

/// Checks the device's eta against f64 (tolerance and decisions) and the CPU twin.
fn compare(what: &str, points: &[[[f64; 3]; 4]], gpu_eta: &[f32], twin: &[f32]) -> Report {
    assert_eq!(gpu_eta.len(), points.len());
    let mut r = Report {
        n: points.len(),
        ..Report::default()
    };
    for (i, p) in points.iter().enumerate() {
        let want = quality::quad_eta(*p);
        let got = gpu_eta[i] as f64;
        let diff = (got - want).abs();
        assert!(
            diff <= TOL,
            "{what}: candidate {i} {p:?}: device eta {got} vs f64 {want} (diff {diff:e})"
        );
        assert!(
            (0.0..=1.0).contains(&got),
            "{what}: candidate {i}: eta {got} out of [0, 1]"
        );
        r.worst = r.worst.max(diff);
        r.worst_twin = r.worst_twin.max((got - twin[i] as f64).abs());
        let a = angles64(*p);
        let (amin, amax) = (
            a.iter().cloned().fold(f64::MAX, f64::min),
            a.iter().cloned().fold(0.0, f64::max),
        );
        let fold = fold_cos(*p);
        if amax >= PI + DELTA || amin <= 0.0 || fold <= -DELTA {
            assert_eq!(
                got, 0.0,
                "{what}: candidate {i} {p:?} is non-convex or folded (angles {a:?}, normals' \
                 cosine {fold}) but device eta is {got}"
            );
        } else if amax <= PI - DELTA && amin >= DELTA && fold >= DELTA {
            assert!(
                got > 0.0,
                "{what}: candidate {i} {p:?} is convex (angles {a:?}) but device eta is 0"
            );
        } else {
            r.borderline += 1;
        }
        if want == 0.0 {
            r.zero += 1;
        }
    }
    assert!(
        r.worst_twin <= TWIN_TOL,
        "{what}: device vs CPU twin differ by {:e}",
        r.worst_twin
    );
    eprintln!(
        "{what}: {} candidates, max |device - f64| = {:.2e}, max |device - twin| = {:.2e}, {} eta = 0, {} borderline",
        r.n, r.worst, r.worst_twin, r.zero, r.borderline
    );
    r
}

/// Runs `meshes` through the device in one batch and compares every table with f64.
fn check_meshes(d: &Dev, meshes: &[(String, Mesh)]) {
    let mut tables: Vec<CandidateTable> = meshes
        .iter()
        .map(|(_, m)| CandidateTable::topology_only(m))
        .collect();
    let mut batch = Batch::new();
    for ((_, m), t) in meshes.iter().zip(&tables) {
        batch.push(&m.vertices, &t.quads).unwrap();
    }
    let eta = run(d, &batch);
    let twin = gpu::cpu::quad_quality(&batch);
    let (eta_local, twin_local) = run_local(d, &batch);
    for (((name, m), t), span) in meshes.iter().zip(&mut tables).zip(&batch.meshes) {
        let points: Vec<_> = t
            .quads
            .iter()
            .map(|q| q.map(|v| m.vertices[v as usize]))
            .collect();
        let r = span.candidates.clone();
        compare(name, &points, &eta[r.clone()], &twin[r.clone()]);
        compare(
            &format!("{name} [local edges]"),
            &points,
            &eta_local[r.clone()],
            &twin_local[r],
        );
        // The reference table built the usual way agrees too.
        let reference = CandidateTable::build(m);
        assert_eq!(reference.quads, t.quads);
    }
}

fn jittered_grid_mesh(n: u32, jitter: f64, z: impl Fn(f64, f64) -> f64, seed: u64) -> Mesh {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let w = n + 1;
    let mut vertices = Vec::new();
    for j in 0..w {
        for i in 0..w {
            let x = i as f64 + jitter * (2.0 * rng.random::<f64>() - 1.0);
            let y = j as f64 + jitter * (2.0 * rng.random::<f64>() - 1.0);
            vertices.push([x, y, z(x, y)]);
        }
    }
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let p = |a: u32, b: u32| (j + b) * w + i + a;
            if rng.random::<bool>() {
                triangles.push([p(0, 0), p(1, 0), p(1, 1)]);
                triangles.push([p(0, 0), p(1, 1), p(0, 1)]);
            } else {
                triangles.push([p(0, 0), p(1, 0), p(0, 1)]);
                triangles.push([p(1, 0), p(1, 1), p(0, 1)]);
            }
        }
    }
    Mesh::new(MeshData {
        vertices,
        triangles,
        ..MeshData::default()
    })
    .unwrap()
}

fn icosphere(subdiv: u32) -> Mesh {
    quadrecomb::internals::mesh::generate::icosphere(subdiv)
}

fn mapped(m: &Mesh, f: impl Fn([f64; 3]) -> [f64; 3]) -> Mesh {
    Mesh::new(MeshData {
        vertices: m.vertices.iter().map(|&p| f(p)).collect(),
        triangles: m.triangles.clone(),
        ..MeshData::default()
    })
    .unwrap()
}

#[test]
fn device_matches_f64_on_generated_and_builtin_meshes() {
    let Some(d) = dev() else { return };
    let grid = jittered_grid_mesh(40, 0.3, |_, _| 0.0, SEED);
    let wavy = jittered_grid_mesh(
        30,
        0.35,
        |x, y| (0.7 * x).sin() * (0.5 * y).cos() * 3.0,
        SEED + 1,
    );
    let sphere = icosphere(4);
    // Vertices moved by up to 0.6 of a cell: triangles folded over their neighbours, whose
    // pairs make no quad (eta 0 in f64; the sums of unsigned angles alone read them as
    // convex).
    let tangled = jittered_grid_mesh(30, 0.6, |_, _| 0.0, SEED + 2);
    let mut meshes = vec![
        ("jittered grid 40x40".to_string(), grid.clone()),
        ("tangled grid 30x30".to_string(), tangled),
        ("wavy surface grid 30x30".to_string(), wavy),
        ("icosphere(4)".to_string(), sphere.clone()),
        (
            "grid at 1e8 offset".to_string(),
            mapped(&grid, |p| [p[0] + 1e8, p[1] - 1e8, p[2] + 1e8]),
        ),
        (
            "grid scaled 1e-8".to_string(),
            mapped(&grid, |p| p.map(|x| x * 1e-8)),
        ),
        (
            "sphere scaled 1e8".to_string(),
            mapped(&sphere, |p| p.map(|x| x * 1e8 + 3e8)),
        ),
    ];
    for name in ["borouchaki", "sphere"] {
        match quadrecomb::internals::mesh::load(name) {
            Ok(m) => meshes.push((format!("built-in {name}"), m)),
            Err(e) => eprintln!("NOTE: built-in mesh {name} not tested: it does not load ({e})"),
        }
    }
    check_meshes(d, &meshes);
}

/// Adversarial candidates: (label, quad points) evaluated as raw batch candidates.
fn adversarial(rng: &mut ChaCha8Rng) -> Vec<(&'static str, [[f64; 3]; 4])> {
    let mut out = Vec::new();
    let z = [0.0, 0.0, 0.0];
    // Degenerate: coincident points, collinear points, zero diagonal.
    out.push(("all coincident", [z; 4]));
    out.push(("zero diagonal", [z, [1.0, -1.0, 0.0], z, [1.0, 1.0, 0.0]]));
    out.push((
        "coincident opposite",
        [z, [1.0, 1.0, 0.0], [2.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
    ));
    out.push((
        "collinear",
        [z, [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0]],
    ));
    out.push((
        "o0 on the diagonal",
        [z, [1.0, -1.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
    ));
    // Non-convex darts, strongly and mildly.
    for x in [0.3, 0.9, 0.99, 0.999, 1.01, 1.5] {
        out.push((
            "dart",
            [z, [1.0, -1.0, 0.0], [x, 0.0, 0.0], [1.0, 1.0, 0.0]],
        ));
    }
    // Borderline: the angle sum at s1 is pi + eps.
    for eps in [
        -1e-3, -1e-4, -2e-5, -1e-5, -1e-6, -1e-7, 0.0, 1e-7, 1e-6, 1e-5, 2e-5, 1e-4, 1e-3,
    ] {
        let b = (PI + eps) / 2.0;
        let (c, s) = (b.cos(), b.sin());
        for scale in [1.0, 1e-8, 1e8] {
            let q =
                [[-1.0, 0.0, 0.0], [-c, -s, 0.0], z, [-c, s, 0.0]].map(|p| p.map(|x| x * scale));
            out.push(("angle sum pi + eps", q));
        }
    }
    // Nearly flat: slivers (angles near 0 and pi).
    for h in [1e-2, 1e-4, 1e-6, 1e-8] {
        out.push((
            "sliver pair",
            [z, [0.5, -h, 0.0], [1.0, 0.0, 0.0], [0.5, h, 0.0]],
        ));
        out.push((
            "flat kite",
            [z, [0.5, -h, 0.0], [1.0, 0.0, 0.0], [0.3, h, 0.0]],
        ));
    }
    // Huge and tiny coordinates and sizes.
    let square = [z, [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
    let rhombus = [z, [0.5, -0.8, 0.0], [1.0, 0.0, 0.0], [0.5, 0.7, 0.0]];
    for (off, scale) in [
        (1e8, 1.0),
        (1e8, 1e8),
        (1e-8, 1e-8),
        (0.0, 1e-8),
        (-1e8, 1e-3),
        (1.0, 1e-8),
    ] {
        for q in [square, rhombus] {
            out.push(("huge/tiny", q.map(|p| p.map(|x| x * scale + off))));
        }
    }
    // 3D folded along the diagonal, by random angles, randomly rotated and placed.
    for _ in 0..300 {
        let fold = rng.random::<f64>() * PI;
        let (u, w) = (
            rng.random::<f64>() * 2.0 - 1.0,
            rng.random::<f64>() * 2.0 - 1.0,
        );
        let o1 = [
            0.5 + 0.6 * u,
            -0.8 * fold.cos().abs().max(0.1),
            0.8 * fold.sin(),
        ];
        let o0 = [0.5 + 0.6 * w, 0.9, 0.0];
        let q = [z, o1, [1.0, 0.0, 0.0], o0];
        let (a, b) = (rng.random::<f64>() * 2.0 * PI, rng.random::<f64>() * PI);
        let rot = |p: [f64; 3]| {
            let (x, y) = (
                p[0] * a.cos() - p[1] * a.sin(),
                p[0] * a.sin() + p[1] * a.cos(),
            );
            let (y, zz) = (y * b.cos() - p[2] * b.sin(), y * b.sin() + p[2] * b.cos());
            [x, y, zz]
        };
        let scale = 10f64.powf(rng.random::<f64>() * 16.0 - 8.0);
        let off = 10f64.powf(rng.random::<f64>() * 16.0 - 8.0) * (rng.random::<f64>() - 0.5);
        out.push(("3D folded", q.map(|p| rot(p).map(|x| x * scale + off))));
    }
    // Random quads in 3D (anything: convex, non-convex, twisted).
    for _ in 0..2000 {
        let q: [[f64; 3]; 4] =
            std::array::from_fn(|_| std::array::from_fn(|_| rng.random::<f64>() * 2.0 - 1.0));
        out.push(("random 3D", q));
        let mut p = q;
        for v in &mut p {
            v[2] *= 1e-6;
        }
        out.push(("random nearly planar", p));
    }
    out
}

#[test]
fn device_matches_f64_on_adversarial_candidates() {
    let Some(d) = dev() else { return };
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let cases = adversarial(&mut rng);
    // Each candidate is its own mesh in the batch (own normalisation, like real meshes).
    let mut batch = Batch::new();
    for (_, q) in &cases {
        batch.push(q, &[[0, 1, 2, 3]]).unwrap();
    }
    let eta = run(d, &batch);
    let twin = gpu::cpu::quad_quality(&batch);
    let points: Vec<_> = cases.iter().map(|c| c.1).collect();
    let r = compare("adversarial (one mesh each)", &points, &eta, &twin);
    let (eta_local, twin_local) = run_local(d, &batch);
    compare(
        "adversarial (one mesh each) [local edges]",
        &points,
        &eta_local,
        &twin_local,
    );
    assert!(r.zero > 100, "the adversarial set has non-convex cases");
    assert!(r.borderline >= 4, "the set exercises the borderline band");
    let size = |q: &[[f64; 3]; 4]| {
        let mut m = 0.0f64;
        for a in q {
            for b in q {
                m = m.max((0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max));
            }
        }
        m
    };
    // Many in one mesh: one normalisation (centre and extent) for all. A translation by
    // the centre cannot keep a quad much smaller than the mesh's extent exact (not even in
    // f64), so the documented contract is for quads at least 1e-7 of the extent. Here: the
    // unit-sized cases, once in place and once translated far away (georeferenced-like
    // coordinates around 1e6, an extent of 2e6).
    let unit: Vec<[[f64; 3]; 4]> = points
        .iter()
        .copied()
        .filter(|q| q.iter().flatten().all(|x| x.abs() <= 10.0) && size(q) >= 0.5)
        .collect();
    let far = unit
        .iter()
        .map(|q| q.map(|p| [p[0] + 1e6, p[1] - 2e6, p[2] + 5e5]));
    let shared: Vec<[[f64; 3]; 4]> = unit.iter().copied().chain(far).collect();
    let extent = shared
        .iter()
        .flatten()
        .flatten()
        .fold(0.0f64, |m, &x| m.max(x.abs()));
    assert!(shared.iter().all(|q| size(q) >= 1e-7 * extent));
    eprintln!(
        "shared normalisation: {} candidates, extent {extent:e}",
        shared.len()
    );
    assert!(shared.len() > 4000);
    let mut batch = Batch::new();
    let verts: Vec<[f64; 3]> = shared.iter().flatten().copied().collect();
    let quads: Vec<[u32; 4]> = (0..shared.len() as u32)
        .map(|i| [4 * i, 4 * i + 1, 4 * i + 2, 4 * i + 3])
        .collect();
    batch.push(&verts, &quads).unwrap();
    let shared_eta = run(d, &batch);
    let (shared_local, shared_twin_local) = run_local(d, &batch);
    compare(
        "adversarial (one mesh, shared normalisation) [local edges]",
        &shared,
        &shared_local,
        &shared_twin_local,
    );
    compare(
        "adversarial (one mesh, shared normalisation)",
        &shared,
        &shared_eta,
        &gpu::cpu::quad_quality(&batch),
    );
    // Named expectations.
    for (i, (label, q)) in cases.iter().enumerate() {
        match *label {
            "all coincident" | "zero diagonal" | "collinear" | "o0 on the diagonal" => {
                assert_eq!(eta[i], 0.0, "{label} {q:?}")
            }
            _ => {}
        }
    }
}

#[test]
fn chunked_dispatches_and_vertex_compaction_give_identical_results() {
    let Some(d) = dev() else { return };
    let mesh = jittered_grid_mesh(30, 0.3, |x, y| 0.1 * x * y, SEED + 2);
    let table = CandidateTable::topology_only(&mesh);
    let mut batch = Batch::new();
    batch.push(&mesh.vertices, &table.quads).unwrap();
    batch
        .push(
            &icosphere(2).vertices,
            &CandidateTable::topology_only(&icosphere(2)).quads,
        )
        .unwrap();
    let (whole, t) = d.kernel.run(&d.device, &d.queue, &batch).unwrap();
    assert_eq!(t.dispatches, 1);
    let chunked = Kernel::new(&d.device).unwrap().with_caps(1000, usize::MAX);
    let (a, t) = chunked.run(&d.device, &d.queue, &batch).unwrap();
    assert_eq!(t.dispatches, batch.len().div_ceil(1000));
    let compacted = Kernel::new(&d.device).unwrap().with_caps(usize::MAX, 800);
    let (b, t) = compacted.run(&d.device, &d.queue, &batch).unwrap();
    assert!(
        t.dispatches > 1,
        "800 vertices per dispatch forces compaction"
    );
    assert_eq!(a, whole);
    assert_eq!(b, whole);
    // The local layout, whole and in chunks of 1000 candidates (plane stride per chunk).
    let (local_whole, _) = d.local.run(&d.device, &d.queue, &batch).unwrap();
    let chunked_local = Kernel::with_layout(&d.device, Layout::Local)
        .unwrap()
        .with_caps(1000, usize::MAX);
    let (c, t) = chunked_local.run(&d.device, &d.queue, &batch).unwrap();
    assert_eq!(t.dispatches, batch.len().div_ceil(1000));
    assert_eq!(c, local_whole);
    let empty = d.kernel.run(&d.device, &d.queue, &Batch::new()).unwrap().0;
    assert!(empty.is_empty());
}

/// The candidates of a 23 x 23 jittered grid, and the default kernel's eta on each layout
/// (one dispatch, one row): what other launch shapes must reproduce bit for bit.
fn grid_batch(d: &Dev, seed: u64) -> (Batch, [(Layout, Vec<f32>); 2]) {
    let mesh = jittered_grid_mesh(23, 0.3, |x, y| 0.1 * x * y, seed);
    let mut batch = Batch::new();
    batch
        .push(&mesh.vertices, &CandidateTable::topology_only(&mesh).quads)
        .unwrap();
    let (indexed, _) = d.kernel.run(&d.device, &d.queue, &batch).unwrap();
    let (local, _) = d.local.run(&d.device, &d.queue, &batch).unwrap();
    (batch, [(Layout::Indexed, indexed), (Layout::Local, local)])
}

#[test]
fn launch_shapes_give_identical_results() {
    let Some(d) = dev() else { return };
    let (batch, references) = grid_batch(d, SEED + 5);
    for (layout, want) in &references {
        let layout = *layout;
        // Workgroup sizes that leave partial last workgroups; chunks of 997
        // candidates (a prime) make every chunk's tail differ.
        for (workgroup, chunk) in [(64, usize::MAX), (32, usize::MAX), (128, 997), (1, 997)] {
            let options = KernelOptions {
                layout,
                workgroup,
                memory_only: false,
            };
            let k = Kernel::with_options(&d.device, options)
                .unwrap()
                .with_caps(chunk, usize::MAX);
            let (got, _) = k.run(&d.device, &d.queue, &batch).unwrap();
            assert_eq!(&got, want, "{options}");
            let times = k
                .dispatch_times(&d.device, &d.queue, 3, std::time::Duration::from_millis(5))
                .unwrap();
            if chunk < batch.len() {
                // Several dispatches: only the last one's data is on the device.
                assert!(times.is_none(), "{options}");
            } else if k.has_timestamps() {
                let times = times.expect("a single dispatch with timestamps");
                assert_eq!(times.len(), 3);
                assert!(times.iter().all(|t| t.is_finite() && *t > 0.0), "{times:?}");
            }
        }
    }
    let too_many = KernelOptions {
        workgroup: d.device.limits().max_compute_invocations_per_workgroup + 1,
        ..KernelOptions::default()
    };
    let err = Kernel::with_options(&d.device, too_many).unwrap_err();
    assert!(err.to_string().contains("invocations here"), "{err}");
}

/// The 2D grid (a dispatch of more workgroups than one dimension holds: above 16.7 million
/// candidates on real devices, which lavapipe's dispatch cap does not reach) with the
/// workgroups per dimension capped: every candidate is evaluated once and in its place, on
/// both layouts, whole rows and a partial last row, one dispatch and several.
#[test]
fn two_dimensional_grids_give_identical_results() {
    let Some(d) = dev() else { return };
    let (batch, references) = grid_batch(d, SEED + 6);
    let n = batch.len();
    let (_, t) = d.kernel.run(&d.device, &d.queue, &batch).unwrap();
    assert_eq!(t.grid_rows, 1, "{n} candidates fit one row");
    for (layout, want) in &references {
        let layout = *layout;
        // (workgroup, groups per dimension, candidates per dispatch): square grids full
        // and partial, a tall one, chunks with a partial last row.
        for (workgroup, groups, chunk) in [
            (4, 7, usize::MAX),
            (1, 40, usize::MAX),
            (8, 25, 997),
            (2, 300, usize::MAX),
        ] {
            let options = KernelOptions {
                layout,
                workgroup,
                memory_only: false,
            };
            let k = Kernel::with_options(&d.device, options)
                .unwrap()
                .with_caps(chunk, usize::MAX)
                .with_group_cap(groups);
            let (got, t) = k.run(&d.device, &d.queue, &batch).unwrap();
            // A dispatch holds at most a square grid of workgroups.
            let square = (groups * groups * workgroup) as usize;
            let per_dispatch = chunk.min(n).min(square);
            let rows = per_dispatch
                .div_ceil(workgroup as usize)
                .div_ceil(groups as usize);
            assert!(rows > 1, "{options}: the grid is 2D");
            assert_eq!(t.grid_rows, rows, "{options}, {groups} groups per row");
            assert_eq!(t.dispatches, n.div_ceil(per_dispatch), "{options}");
            assert_eq!(&got, want, "{options}, {groups} groups per row");
        }
    }
}

#[test]
fn evaluator_fills_tables_of_many_meshes_on_each_backend() {
    let meshes = [
        jittered_grid_mesh(12, 0.3, |_, _| 0.0, SEED + 3),
        icosphere(2),
        jittered_grid_mesh(5, 0.1, |x, _| x * x, SEED + 4),
    ];
    let mut evaluators = vec![Evaluator::new(Backend::Cpu).unwrap()];
    assert_eq!(evaluators[0].name(), "cpu-twin");
    if dev().is_some() {
        let e = Evaluator::new(Backend::Gpu).expect("an adapter exists, so --backend gpu works");
        eprintln!("Evaluator(gpu) = {}", e.name());
        assert!(e.name().starts_with("vulkan: "));
        evaluators.push(e);
    }
    if dev().is_none() {
        let err = Evaluator::new(Backend::Gpu).unwrap_err();
        assert!(matches!(err, gpu::GpuError::NoAdapter), "{err}");
    }
    let auto = Evaluator::new(Backend::Auto).unwrap();
    assert_eq!(
        auto.is_device(),
        dev().is_some(),
        "auto uses an adapter when there is one"
    );
    for ev in &evaluators {
        let mut tables: Vec<CandidateTable> =
            meshes.iter().map(CandidateTable::topology_only).collect();
        let mut jobs: Vec<(&Mesh, &mut CandidateTable)> =
            meshes.iter().zip(tables.iter_mut()).collect();
        ev.fill(&mut jobs).unwrap();
        for (m, t) in meshes.iter().zip(&tables) {
            let reference = CandidateTable::build(m);
            assert_eq!(t.eta.len(), reference.eta.len());
            let worst = t
                .eta
                .iter()
                .zip(&reference.eta)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(worst <= TOL, "{}: {worst:e}", ev.name());
        }
        // Deterministic per backend: a second fill gives the same bits.
        let mut again: Vec<CandidateTable> =
            meshes.iter().map(CandidateTable::topology_only).collect();
        let mut jobs: Vec<(&Mesh, &mut CandidateTable)> =
            meshes.iter().zip(again.iter_mut()).collect();
        ev.fill(&mut jobs).unwrap();
        for (a, b) in tables.iter().zip(&again) {
            assert_eq!(a.eta, b.eta, "{} is deterministic", ev.name());
        }
    }
}

#[test]
fn bad_candidate_index_is_an_error_not_a_crash() {
    let mut batch = Batch::new();
    let err = batch.push(&[[0.0; 3]; 3], &[[0, 1, 2, 3]]).unwrap_err();
    assert!(err.to_string().contains("vertex 3"), "{err}");
    assert_eq!(Vertex::default().hi, [0.0; 4]);
}

/// A successful run prints no line that begins with "error:", also with `XDG_RUNTIME_DIR`
/// unset, where Mesa's device-selection layer (installed with lavapipe) printed
/// `error: XDG_RUNTIME_DIR is invalid or not set in the environment.` for every instance.
#[test]
fn no_error_lines_from_mesa_without_xdg_runtime_dir() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &[
            "recombine",
            "sphere",
            "--algo",
            "greedy",
            "--backend",
            "gpu",
            "--no-optimum",
        ][..],
        &[
            "sweep",
            "--mesh",
            "sphere",
            "--algo",
            "greedy",
            "--runs",
            "1",
            "--no-report",
            "-q",
            "--out",
            "s",
        ],
    ] {
        let out = std::process::Command::new(crate::util::bin())
            .args(args)
            .current_dir(dir.path())
            .env_remove("XDG_RUNTIME_DIR")
            .env_remove("NODEVICE_SELECT")
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        if !out.status.success()
            && err.contains("no Vulkan adapter")
            && std::env::var_os("CI").is_none()
        {
            eprintln!("SKIPPED: no Vulkan adapter");
            return;
        }
        assert!(out.status.success(), "{args:?}: {err}");
        assert!(
            !err.lines().any(|l| l.starts_with("error:")),
            "{args:?}: {err}"
        );
    }
}

/// One batch of every suite mesh's candidates (what `sweep --suite` submits) gives the same
/// bits as one submission per mesh, also when the batch is split into many dispatches and
/// compacted; and it agrees with the CPU twin.
#[test]
fn suite_batch_is_bit_identical_to_per_mesh_evaluation() {
    use quadrecomb::internals::mesh::suite;
    let Some(d) = dev() else { return };
    let meshes: Vec<Mesh> = (suite::suite("default").unwrap().iter())
        .map(|m| quadrecomb::internals::mesh::load(&suite::spec(m)).unwrap())
        .collect();
    let tables: Vec<CandidateTable> = meshes.iter().map(CandidateTable::topology_only).collect();
    let mut batch = Batch::new();
    for (m, t) in meshes.iter().zip(&tables) {
        batch.push(&m.vertices, &t.quads).unwrap();
    }
    let whole = run(d, &batch);
    let mut each = Vec::new();
    for (m, t) in meshes.iter().zip(&tables) {
        let mut one = Batch::new();
        one.push(&m.vertices, &t.quads).unwrap();
        each.extend(run(d, &one));
    }
    assert_eq!(
        whole.len(),
        tables.iter().map(|t| t.quads.len()).sum::<usize>()
    );
    assert!(whole == each, "batched and per-mesh eta differ");
    // Dispatches that cut meshes in the middle, with vertex compaction.
    let split = Kernel::new(&d.device).unwrap().with_caps(7777, 5000);
    let (chunked, t) = split.run(&d.device, &d.queue, &batch).unwrap();
    assert!(t.dispatches > meshes.len(), "{} dispatches", t.dispatches);
    assert!(chunked == whole, "chunked batch differs");
    let twin = gpu::cpu::quad_quality(&batch);
    let worst = (whole.iter().zip(&twin))
        .map(|(a, b)| (a - b).abs() as f64)
        .fold(0.0, f64::max);
    assert!(worst <= TWIN_TOL, "device vs twin {worst:e}");
    // The evaluator (sweep's path): one fill of every table, and one fill per table.
    let ev = Evaluator::new(Backend::Gpu).unwrap();
    let mut all: Vec<CandidateTable> = meshes.iter().map(CandidateTable::topology_only).collect();
    let mut jobs: Vec<(&Mesh, &mut CandidateTable)> = meshes.iter().zip(all.iter_mut()).collect();
    ev.fill(&mut jobs).unwrap();
    for (m, a) in meshes.iter().zip(&all) {
        let mut t = CandidateTable::topology_only(m);
        ev.fill(&mut [(m, &mut t)]).unwrap();
        assert!(t.eta == a.eta, "evaluator: batched and per-mesh differ");
    }
}
