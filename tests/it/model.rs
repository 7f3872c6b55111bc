//! The Gmsh model written back (issue 21, point 4): a `.msh` read from a Gmsh file is
//! written with its physical groups, entities, node classification, parametric coordinates
//! and point and line elements, so that Gmsh can go on from it. Checked through Gmsh's own
//! Python API (and meshio), not our reader.

use crate::util::{gmsh_available, python, repo_path, run_in};
use quadrecomb::internals::mesh::{self, Mesh, Recombined, msh};
use quadrecomb::internals::quality::{self, CandidateTable, Rule};
use quadrecomb::internals::search::{self, Algo};
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Python: what Gmsh reads from `argv[1]`, as one JSON object: physical groups with their
/// names and entities, element counts by type, the node tags classified on each entity
/// (boundary excluded) and their parametric coordinates. With `argv[2]` = `smooth`, also
/// the area before and after `optimize("Laplace2D")` and how many of the nodes that Gmsh
/// reads on points and curves from `argv[3]` (the input mesh) it moved; with `recombine`,
/// the area before and after `recombine()`. Areas are
/// the sum of the elements' absolute areas (a folded mesh grows) and of their signed
/// areas (which only moving boundary nodes changes), in the xy plane.
const DESCRIBE: &str = r#"
import sys, json, gmsh
import numpy as np
gmsh.initialize(["-noenv"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(sys.argv[1])
mode = sys.argv[2] if len(sys.argv) > 2 else ""

def areas():
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    order = np.argsort(tags)
    tags, xyz = tags[order], xyz.reshape(-1, 3)[order]
    total_abs, total_signed = 0.0, 0.0
    for etype, k in ((2, 3), (3, 4)):
        _, nodes = gmsh.model.mesh.getElementsByType(etype)
        if len(nodes) == 0:
            continue
        p = xyz[np.searchsorted(tags, nodes)].reshape(-1, k, 3)
        q = np.roll(p, -1, axis=1)
        a = 0.5 * (p[:, :, 0] * q[:, :, 1] - q[:, :, 0] * p[:, :, 1]).sum(axis=1)
        total_abs += float(np.abs(a).sum())
        total_signed += float(a.sum())
    return [total_abs, total_signed]

def boundary_nodes():
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    return dict(zip(tags.tolist(), xyz.reshape(-1, 3).tolist()))

out = {}
out["groups"] = sorted(
    [d, t, gmsh.model.getPhysicalName(d, t),
     sorted(int(e) for e in gmsh.model.getEntitiesForPhysicalGroup(d, t))]
    for d, t in gmsh.model.getPhysicalGroups())
out["entities"] = sorted([d, t] for d, t in gmsh.model.getEntities())
out["elements"] = {str(t): len(gmsh.model.mesh.getElementsByType(t)[0])
                   for t in (15, 1, 2, 3)}
nodes, params = {}, {}
for d, t in gmsh.model.getEntities():
    tags, _, u = gmsh.model.mesh.getNodes(d, t, includeBoundary=False,
                                          returnParametricCoord=True)
    if len(tags):
        key = f"{d} {t}"
        nodes[key] = sorted(int(x) for x in tags)
        if len(u):
            u = u.reshape(len(tags), -1).tolist()
            params[key] = sorted([int(x)] + c for x, c in zip(tags, u))
out["nodes"] = nodes
out["params"] = params
if mode == "smooth":
    before, fixed = areas(), boundary_nodes()
    gmsh.model.mesh.optimize("Laplace2D")
    after, moved = areas(), boundary_nodes()
    gmsh.model.add("input")
    gmsh.merge(sys.argv[3])
    boundary = set()
    for d in (0, 1):
        boundary.update(gmsh.model.mesh.getNodes(d, -1)[0].tolist())
    out["area"] = [before, after]
    out["boundary"] = len(boundary)
    out["boundary_moved"] = sum(1 for t in boundary if moved[t] != fixed[t])
elif mode == "recombine":
    before = areas()
    gmsh.model.mesh.recombine()
    out["area"] = [before, areas()]
gmsh.finalize()
print(json.dumps(out))
"#;

/// What Gmsh reads from `path` (see [`DESCRIBE`]), `mode` "", "smooth" (then `input` is
/// the mesh it was made from) or "recombine".
fn gmsh_reads(path: &Path, mode: &str) -> Value {
    gmsh_compares(path, mode, path)
}

fn gmsh_compares(path: &Path, mode: &str, input: &Path) -> Value {
    let out = python(DESCRIBE, &[path, Path::new(mode), input]);
    serde_json::from_str(&out).expect("JSON from the Gmsh script")
}

fn data(name: &str) -> PathBuf {
    repo_path("tests/data").join(name)
}

/// `name` (a file of tests/data, or a built-in mesh) loaded as every command loads it
/// (spatial order), and its path for Gmsh.
fn load(name: &str) -> (Mesh, PathBuf) {
    let path = if mesh::builtin::NAMES.contains(&name) {
        repo_path("meshes").join(format!("{name}.msh"))
    } else {
        data(name)
    };
    let m = mesh::load(path.to_str().unwrap()).unwrap_or_else(|e| panic!("{name}: {e}"));
    (m, path)
}

/// Writes `mesh` recombined as `recombine --algo selective --horizon 5 --seed 1` does under
/// `rule` to `dir`/`name` and returns the path and the recombination.
fn write_recombined(dir: &Path, name: &str, mesh: &Mesh, rule: Rule) -> (PathBuf, Recombined) {
    let table = CandidateTable::build(mesh).restrict(mesh, rule);
    let run = search::run(mesh, &table, Algo::selective(5), 1);
    let rec = quality::recombined(mesh, &table, &run.chosen);
    assert!(!rec.quads.is_empty(), "{name}: nothing recombined");
    let out = dir.join(name);
    msh::write(&out, mesh, &rec).unwrap();
    (out, rec)
}

fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs())
}

/// Physical groups (dimension, tag, name, entities), entities, point and line elements,
/// and the nodes on every entity are those Gmsh reads from the input, for MSH 4.1 and 2.2
/// inputs with named groups and boundary lines (the channel: groups for both surfaces and
/// for the inlet, outlet and walls) and for the built-in meshes (physical surfaces only,
/// nodes on their curves and points without line elements), and for a stiffened plate
/// (surfaces meeting three at an edge).
#[test]
fn written_msh_keeps_the_gmsh_model() {
    if !gmsh_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "channel_41_ascii.msh",
        "channel_22_ascii.msh",
        "sphere",
        "two_squares_41_bin.msh",
        // Three surfaces meeting at the edges of a line (a web on a plate, a fin on it).
        "stiffened_41_ascii.msh",
    ] {
        let (m, path) = load(name);
        let (out, rec) = write_recombined(dir.path(), "out.msh", &m, Rule::default());
        let input = gmsh_reads(&path, "");
        let ours = gmsh_reads(&out, "");
        for key in ["groups", "entities", "nodes"] {
            assert_eq!(ours[key], input[key], "{name}: {key}");
        }
        for t in ["15", "1"] {
            assert_eq!(
                ours["elements"][t], input["elements"][t],
                "{name}: type {t}"
            );
        }
        assert_eq!(ours["elements"]["2"], rec.leftover.len(), "{name}");
        assert_eq!(
            ours["elements"]["3"],
            rec.quads.len() + m.quads.len(),
            "{name}"
        );
        // Nodes on curves, not all on the surfaces.
        let on_curves = |v: &Value| -> usize {
            let nodes = v["nodes"].as_object().unwrap();
            let curves = nodes.iter().filter(|(k, _)| k.starts_with("1 "));
            curves.map(|(_, n)| n.as_array().unwrap().len()).sum()
        };
        assert!(on_curves(&ours) > 0, "{name}: no node on a curve");
        assert_eq!(on_curves(&ours), on_curves(&input), "{name}");
    }
    // The channel's groups as the script made them.
    let (m, _) = load("channel_41_ascii.msh");
    let (out, _) = write_recombined(dir.path(), "channel.msh", &m, Rule::default());
    let ours = gmsh_reads(&out, "");
    let names: Vec<(u64, &str)> = ours["groups"]
        .as_array()
        .unwrap()
        .iter()
        .map(|g| (g[0].as_u64().unwrap(), g[2].as_str().unwrap()))
        .collect();
    assert_eq!(
        names,
        [
            (1, "inlet"),
            (1, "outlet"),
            (1, "walls"),
            (2, "left"),
            (2, "right")
        ]
    );
    assert!(ours["elements"]["1"].as_u64().unwrap() > 20);
}

/// Parametric coordinates of the input's nodes on curves and surfaces come back, from
/// MSH 4.1 `$Nodes` and from MSH 2.2 `$ParametricNodes`.
#[test]
fn parametric_coordinates_are_written_back() {
    if !gmsh_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "param_41_ascii.msh",
        "param_41_bin.msh",
        "param_22_ascii.msh",
    ] {
        let (m, path) = load(name);
        let out = dir.path().join("out.msh");
        msh::write(&out, &m, &Recombined::unrecombined(&m)).unwrap();
        let input = gmsh_reads(&path, "");
        let ours = gmsh_reads(&out, "");
        assert!(
            input["params"].as_object().unwrap().len() >= 2,
            "{name}: {}",
            input["params"]
        );
        assert_eq!(ours["params"], input["params"], "{name}");
        assert_eq!(ours["nodes"], input["nodes"], "{name}");
    }
}

/// `optimize("Laplace2D")` leaves the boundary where it is: nodes on points and curves do
/// not move and the domain's area stays within 1e-6 (relative), on our recombined channel
/// as on Gmsh's own recombination of it; on borouchaki (the issue's selective h = 5, seed 1
/// run) too, and under --allow-invalid the signed area only: its quads with a corner of 180
/// degrees or more fold when smoothed (absolute area 0.929 -> 1.147). And `recombine()`
/// keeps the area: before the model was written, Gmsh's recombination of our borouchaki
/// dropped elements (6 % of the area) and smoothing moved its boundary. On a stiffened
/// plate (surfaces meeting three at an edge) the nodes of the junction lines stay too.
#[test]
fn gmsh_smooths_and_recombines_our_output() {
    if !gmsh_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // Gmsh's own recombination of the channel, for comparison.
    let gmsh_own = dir.path().join("gmsh_own.msh");
    let script = r#"
import sys, gmsh
gmsh.initialize(["-noenv"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(sys.argv[1])
gmsh.model.mesh.recombine()
gmsh.write(sys.argv[2])
gmsh.finalize()
"#;
    python(script, &[&data("channel_41_ascii.msh"), &gmsh_own]);
    let (channel, _) = load("channel_41_ascii.msh");
    let (ours, _) = write_recombined(dir.path(), "channel.msh", &channel, Rule::default());
    let (borouchaki, b_input) = load("borouchaki");
    let c_input = data("channel_41_ascii.msh");
    let (b_all, _) = write_recombined(dir.path(), "b_all.msh", &borouchaki, Rule::AllPairs);
    let (b_valid, _) = write_recombined(dir.path(), "b_valid.msh", &borouchaki, Rule::default());
    // A shell model: three surfaces meet along two lines, whose nodes must stay.
    let (stiffened, s_input) = load("stiffened_41_ascii.msh");
    let (s_ours, _) = write_recombined(dir.path(), "stiff.msh", &stiffened, Rule::default());
    for (what, path, input, absolute) in [
        ("our stiffened plate", &s_ours, &s_input, true),
        ("Gmsh's channel", &gmsh_own, &c_input, true),
        ("our channel", &ours, &c_input, true),
        ("our borouchaki, --allow-invalid", &b_all, &b_input, false),
        (
            "our borouchaki, valid quads (the default)",
            &b_valid,
            &b_input,
            true,
        ),
    ] {
        let r = gmsh_compares(path, "smooth", input);
        assert!(
            r["boundary"].as_u64().unwrap() > 60,
            "{what}: {}",
            r["boundary"]
        );
        assert_eq!(r["boundary_moved"], 0, "{what}: boundary nodes moved");
        let area = |i: usize, k: usize| r["area"][i][k].as_f64().unwrap();
        assert!(area(0, 0) > 0.5, "{what}: {}", r["area"]);
        let signed = relative(area(0, 1), area(1, 1));
        assert!(signed < 1e-6, "{what}: signed area {}", r["area"]);
        if absolute {
            let abs = relative(area(0, 0), area(1, 0));
            assert!(abs < 1e-6, "{what}: area {}", r["area"]);
        }
    }
    for (what, path) in [("our channel", &ours), ("our borouchaki", &b_valid)] {
        let r = gmsh_reads(path, "recombine");
        let area = |i: usize| r["area"][i][0].as_f64().unwrap();
        assert!(relative(area(0), area(1)) < 1e-6, "{what}: {}", r["area"]);
    }
}

/// A partitioned mesh is written on its unpartitioned model: Gmsh reads the same
/// entities, groups, points, lines and node classification (the number of nodes on each
/// entity: Gmsh numbers the nodes of a partitioned mesh differently in 2.2 and 4.1) from
/// our output of the partitioned box (4.1 ASCII and binary) as from our output of the
/// unpartitioned one, and the same from our outputs of the partitioned square in 4.1 and
/// 2.2. The finer box has interior nodes, which MSH 4.1 puts on partition volumes: they go
/// back to the box's volume (they made two more volumes before, a review's finding).
#[test]
fn partitioned_input_writes_the_unpartitioned_model() {
    if !gmsh_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    // Files that must give the same model, and its number of entities per dimension.
    let cases: [(&[&str], [usize; 4]); 3] = [
        (
            &[
                "box_41_ascii.msh",
                "box_parts_41_ascii.msh",
                "box_parts_41_bin.msh",
            ],
            [8, 12, 6, 1],
        ),
        (
            &["box_fine_41_ascii.msh", "box_fine_parts_41_ascii.msh"],
            [8, 12, 6, 1],
        ),
        (
            &[
                "parts_41_ascii.msh",
                "parts_41_bin.msh",
                "parts_22_ascii.msh",
            ],
            [4, 4, 1, 0],
        ),
    ];
    for (names, want) in cases {
        let mut seen = Vec::new();
        for &name in names {
            let (m, _) = load(name);
            let out = dir.path().join(format!("{name}.out.msh"));
            msh::write(&out, &m, &Recombined::unrecombined(&m)).unwrap();
            seen.push((name, gmsh_reads(&out, "")));
        }
        let (first, reference) = &seen[0];
        let dims: Vec<u64> = reference["entities"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e[0].as_u64().unwrap())
            .collect();
        let count = |d: u64| dims.iter().filter(|&&x| x == d).count();
        assert_eq!([0, 1, 2, 3].map(count), want, "{first}");
        if first.starts_with("box_fine") {
            let inside = reference["nodes"]["3 1"].as_array().map_or(0, Vec::len);
            assert!(inside > 0, "{first}: no interior nodes");
        }
        assert!(reference["elements"]["1"].as_u64().unwrap() > 0, "{first}");
        let per_entity = |r: &Value| -> BTreeMap<String, usize> {
            let nodes = r["nodes"].as_object().unwrap();
            let count = |n: &Value| n.as_array().unwrap().len();
            nodes.iter().map(|(k, n)| (k.clone(), count(n))).collect()
        };
        for (name, r) in &seen[1..] {
            for key in ["groups", "entities", "elements"] {
                assert_eq!(r[key], reference[key], "{name} vs {first}: {key}");
            }
            assert_eq!(per_entity(r), per_entity(reference), "{name} vs {first}");
        }
    }
}

/// Python: the nodes `argv[2]` (an all-quad output) adds to `argv[1]` (its input), read by
/// Gmsh: how many lie at the midpoint of a side where a curve must lie in the input (used by
/// one triangle, or by triangles of two surfaces) and how many elsewhere; those classified on
/// the wrong dimension (a curve for the first, a surface for the others) or on another curve
/// than their side's ends; and, where the curve's block has parametric coordinates, how many
/// new nodes' parameter is the mean of their side's ends' and which are not.
const NEW_NODES: &str = r#"
import sys, json, gmsh
import numpy as np
gmsh.initialize(["-noenv"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(sys.argv[1])
tags, xyz, _ = gmsh.model.mesh.getNodes()
at = dict(zip(tags.tolist(), xyz.reshape(-1, 3)))
sides = {}
for _, s in gmsh.model.getEntities(2):
    _, nodes = gmsh.model.mesh.getElementsByType(2, s)
    for t in nodes.reshape(-1, 3).tolist():
        for i in range(3):
            sides.setdefault(tuple(sorted((t[i], t[(i + 1) % 3]))), []).append(s)
mid = {}
for (a, b), on in sides.items():
    if len(on) == 1 or len(set(on)) > 1:
        mid[tuple((0.5 * (at[a] + at[b])).tolist())] = (a, b)
curve = {}
for _, c in gmsh.model.getEntities(1):
    t, _, u = gmsh.model.mesh.getNodes(1, c, includeBoundary=False, returnParametricCoord=True)
    for i, x in enumerate(t.tolist()):
        curve[x] = (c, float(u[i]) if len(u) else None)
old = set(at)
gmsh.clear()
gmsh.open(sys.argv[2])
out = {"on_curve_sides": 0, "elsewhere": 0, "wrong": [], "params": 0, "wrong_params": []}
for d, e in gmsh.model.getEntities():
    t, xyz, u = gmsh.model.mesh.getNodes(d, e, includeBoundary=False, returnParametricCoord=True)
    for i, x in enumerate(t.tolist()):
        if x in old:
            continue
        side = mid.get(tuple(xyz[3 * i:3 * i + 3].tolist()))
        if side is None:
            out["elsewhere"] += 1
            if d != 2:
                out["wrong"].append([x, d, e])
            continue
        out["on_curve_sides"] += 1
        ends = [curve.get(v) for v in side]
        if d != 1 or any(c is not None and c[0] != e for c in ends):
            out["wrong"].append([x, d, e, list(side)])
        if d == 1 and len(u) and all(c is not None and c[1] is not None for c in ends):
            out["params"] += 1
            if float(u[i]) != 0.5 * (ends[0][1] + ends[1][1]):
                out["wrong_params"].append([x, float(u[i])])
gmsh.finalize()
print(json.dumps(out))
"#;

/// all-quad on models whose curves have no line elements (Gmsh saves none for a curve in no
/// physical group, but classifies its nodes): a node added on a boundary side (a split) or on
/// a side between two surfaces (sheets across the disk's circle) is classified on the curve of
/// the side's ends, with the mean of their parameters, as Gmsh reads the file; every other new
/// node on its surface. Put on the surface before (a review's finding), a split node made
/// Gmsh's `recombine()` drop it and open a hole; the area is kept now. A disk of six nodes,
/// all on its circle, with a triangle inside (its sides are chords): the sheets' midpoints of
/// the chords stay on the surface, with or without the circle's line elements (a second
/// review's finding: they went on the circle).
#[test]
fn all_quad_puts_new_nodes_on_curve_sides_on_their_curves() {
    if !gmsh_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for lines in [false, true] {
        std::fs::write(dir.path().join(format!("hex{lines}.msh")), hexagon(lines)).unwrap();
    }
    for (name, params) in [
        ("square_nolines_41_ascii.msh", Some(true)),
        ("disk_nolines_41_ascii.msh", Some(false)),
        ("hexfalse.msh", None),
        ("hextrue.msh", None),
    ] {
        let input = if name.starts_with("hex") {
            dir.path().join(name)
        } else {
            data(name)
        };
        let out = dir.path().join(format!("{name}.aq.msh"));
        crate::util::run_ok(
            dir.path(),
            &[
                "recombine",
                input.to_str().unwrap(),
                "--algo",
                "greedy",
                "--finish",
                "--all-quad",
                "--no-optimum",
                "-o",
                out.to_str().unwrap(),
            ],
        );
        let text = python(NEW_NODES, &[&input, &out]);
        let v: Value = serde_json::from_str(text.trim()).unwrap();
        assert!(v["on_curve_sides"].as_u64().unwrap() >= 1, "{name}: {v}");
        assert_eq!(v["wrong"], serde_json::json!([]), "{name}: {v}");
        assert_eq!(v["wrong_params"], serde_json::json!([]), "{name}: {v}");
        if let Some(params) = params {
            assert_eq!(v["params"].as_u64().unwrap() >= 1, params, "{name}: {v}");
        }
        let r = gmsh_reads(&out, "recombine");
        let area = |i: usize| r["area"][i][0].as_f64().unwrap();
        assert!(relative(area(0), area(1)) < 1e-9, "{name}: {}", r["area"]);
    }
}

/// A MSH 4.1 disk: six nodes on its circle (curve 1, from and to point 1, with parameters),
/// three ears and a triangle inside, and the circle's six line elements when `lines`; only
/// the surface is in a physical group.
fn hexagon(lines: bool) -> String {
    let mut s = String::from(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 1 \"disk\"\n\
         $EndPhysicalNames\n$Entities\n1 1 1 0\n1 1 0 0 0\n1 -1 -1 0 1 1 0 0 2 1 -1\n\
         1 -1 -1 0 1 1 0 1 1 1 1\n$EndEntities\n$Nodes\n2 6 1 6\n0 1 0 1\n1\n1 0 0\n\
         1 1 1 5\n2\n3\n4\n5\n6\n",
    );
    for k in 1..6 {
        let a = k as f64 * std::f64::consts::PI / 3.0;
        s += &format!("{} {} 0 {a}\n", a.cos(), a.sin());
    }
    s += "$EndNodes\n$Elements\n";
    if lines {
        s += "2 10 1 10\n1 1 1 6\n";
        for k in 1..=6 {
            s += &format!("{} {k} {}\n", k + 4, k % 6 + 1);
        }
    } else {
        s += "1 4 1 4\n";
    }
    s += "2 1 2 4\n1 1 2 3\n2 3 4 5\n3 5 6 1\n4 1 3 5\n$EndElements\n";
    s
}

/// meshio reads our file with its physical groups: cells by type and the group names.
#[test]
fn meshio_reads_the_model() {
    if !gmsh_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (m, _) = load("channel_41_ascii.msh");
    let (out, rec) = write_recombined(dir.path(), "channel.msh", &m, Rule::default());
    let script = r#"
import sys, json, meshio
m = meshio.read(sys.argv[1])
cells = {}
for c in m.cells:
    cells[c.type] = cells.get(c.type, 0) + len(c.data)
print(json.dumps({"cells": cells, "names": sorted(m.field_data)}))
"#;
    let r: Value = serde_json::from_str(&python(script, &[&out])).unwrap();
    assert_eq!(r["cells"]["quad"], rec.quads.len());
    assert_eq!(r["cells"]["triangle"], rec.leftover.len());
    let input = gmsh_reads(&data("channel_41_ascii.msh"), "");
    assert_eq!(r["cells"]["line"], input["elements"]["1"]);
    assert_eq!(
        r["names"],
        serde_json::json!(["inlet", "left", "outlet", "right", "walls"])
    );
}

/// The model follows the spatial order: every node keeps its entity and parametric
/// coordinates, every line its nodes (by tag), whether the mesh is read in file order or
/// loaded in spatial order.
#[test]
fn model_follows_the_spatial_order() {
    for name in [
        "param_41_ascii.msh",
        "channel_22_ascii.msh",
        "box_parts_41_bin.msh",
    ] {
        let path = data(name);
        let read = msh::read(&path).unwrap();
        let loaded = mesh::load(path.to_str().unwrap()).unwrap();
        assert_ne!(read.vertex_ids, loaded.vertex_ids, "{name}: nothing moved");
        type Classification = BTreeMap<u64, (Option<(u8, i32)>, Option<[u64; 3]>)>;
        let by_tag = |m: &Mesh| -> (Classification, Vec<(i64, i32, Vec<u64>)>) {
            let model = m.model.as_ref().expect("a model");
            let nodes = m
                .vertex_ids
                .iter()
                .enumerate()
                .map(|(v, &t)| {
                    let u = model.node_param.get(v).copied().flatten();
                    let u = u.map(|u| u.map(f64::to_bits));
                    (t, (model.node_entity[v], u))
                })
                .collect();
            let mut lines: Vec<_> = model
                .elements
                .iter()
                .map(|e| {
                    let tags = e.nodes.iter().map(|&v| m.vertex_ids[v as usize]).collect();
                    (e.gmsh_type, e.entity, tags)
                })
                .collect();
            lines.sort();
            (nodes, lines)
        };
        let (a, b) = (by_tag(&read), by_tag(&loaded));
        assert_eq!(a, b, "{name}");
        assert!(a.0.values().all(|(on, _)| on.is_some()), "{name}");
        assert!(!a.1.is_empty(), "{name}");
    }
}

/// Generated meshes have no model and are written as before: one surface entity, nodes on
/// it, no physical names, points or lines.
#[test]
fn generated_meshes_are_written_without_a_model() {
    let m = mesh::generate::grid(mesh::generate::GridSpec {
        triangles: 50,
        seed: 3,
        ..Default::default()
    });
    assert!(m.model.is_none());
    let mut out = Vec::new();
    msh::write_to(&mut out, &m, &Recombined::unrecombined(&m)).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.starts_with("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 1 0\n"),
        "{}",
        &text[..200]
    );
    assert!(!text.contains("$PhysicalNames"));
}

/// A point or line element on a node that does not exist is refused like a triangle
/// (it is written back, so it must be read).
#[test]
fn lines_on_missing_nodes_are_refused() {
    let text = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n$Elements\n2\n1 1 2 1 1 1 9\n2 2 2 1 1 1 2 3\n$EndElements\n";
    let err = msh::read_bytes("l.msh", text.as_bytes()).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("l.msh:12") && msg.contains("element 1 refers to node 9"),
        "{msg}"
    );
}

/// A volume element (skipped: neither kept nor written) naming a node the file lacks is
/// refused too, as Gmsh refuses such a file, in each of the four element readers: MSH 2.2
/// and 4.1, ASCII (the element's line) and binary (its byte offset). The same files with
/// the tetrahedron on an existing node are read, its element counted as skipped.
#[test]
fn skipped_elements_on_missing_nodes_are_refused() {
    let cases = |node: u64| -> Vec<(&'static str, Vec<u8>, String)> {
        let v22 = format!(
            "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n\
             $EndNodes\n$Elements\n2\n1 2 2 1 1 1 2 3\n2 4 2 1 1 1 2 3 {node}\n$EndElements\n"
        );
        let v41 = format!(
            "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n\
             1 0 0\n0 1 0\n$EndNodes\n$Elements\n2 2 1 2\n2 1 2 1\n1 1 2 3\n3 1 4 1\n\
             2 1 2 3 {node}\n$EndElements\n"
        );
        vec![
            ("a22.msh", v22.into_bytes(), ":13:".to_string()),
            ("a41.msh", v41.into_bytes(), ":19:".to_string()),
            (
                "b22.msh",
                msh22_binary_tet(node),
                "byte offset ".to_string(),
            ),
            (
                "b41.msh",
                msh41_binary_tet(node),
                "byte offset ".to_string(),
            ),
        ]
    };
    for (name, bytes, at) in cases(9) {
        let err = msh::read_bytes(name, &bytes).unwrap_err();
        let msg = err.to_string();
        assert!(
            msg.contains(name)
                && msg.contains(&at)
                && msg.contains("element 2 refers to node 9, which does not exist"),
            "{name}: {msg}"
        );
    }
    for (name, bytes, _) in cases(3) {
        let m = msh::read_bytes(name, &bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m.num_triangles(), 1, "{name}");
    }
    // MSH 2.2 binary writes tags as signed integers: a negative one is named as written.
    for (tet, node, want) in [
        (2, -5, "element 2 refers to node -5, which does not exist"),
        (-2, 3, "bad element tag -2 (tags are positive)"),
        (0, 3, "bad element tag 0 (tags are positive)"),
    ] {
        let err = msh::read_bytes("n.msh", &msh22_binary_tet_tagged(tet, node)).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("n.msh") && msg.contains(want), "{msg}");
    }
}

/// One surface in two physical groups: MSH 2.2 writes each triangle once per group (it was
/// refused as a duplicate triangle). The copies are merged and counted as skipped, so the 2.2
/// files read as the 4.1 file, and Gmsh reads both groups on the surface from our output.
#[test]
fn a_surface_in_two_physical_groups_reads_as_in_msh_41() {
    let (m41, _) = load("two_groups_41_ascii.msh");
    for name in ["two_groups_22_ascii.msh", "two_groups_22_bin.msh"] {
        let file = msh::parse(&data(name), &std::fs::read(data(name)).unwrap()).unwrap();
        let copies: Vec<String> = (file.skipped.iter())
            .filter(|k| k.why == msh::SkipReason::GroupCopy)
            .map(ToString::to_string)
            .collect();
        assert_eq!(
            copies,
            [format!(
                "{} Triangle 3 (type 2) (copies for another physical group, merged)",
                m41.num_triangles()
            )],
            "{name}"
        );
        let (m, _) = load(name);
        assert_eq!(m.num_triangles(), m41.num_triangles(), "{name}");
        assert_eq!(m.surfaces(), vec![1], "{name}");
        let model = m.model.as_ref().expect("a model");
        let surface = model.entities.iter().find(|e| (e.dim, e.tag) == (2, 1));
        assert_eq!(surface.unwrap().physicals, vec![1, 2], "{name}");
        if gmsh_available() {
            let dir = tempfile::tempdir().unwrap();
            let (out, rec) = write_recombined(dir.path(), "out.msh", &m, Rule::default());
            let v = gmsh_reads(&out, "");
            assert_eq!(
                v["groups"],
                serde_json::json!([[2, 1, "fluid", [1]], [2, 2, "all", [1]]]),
                "{name}"
            );
            assert_eq!(v["elements"]["3"], rec.quads.len(), "{name}");
        }
    }
}

/// A volume mesh in MSH 2.2 (no `$Entities`): the volume and its group are known from the
/// tetrahedra, and the nodes inside it are on it, as Gmsh reads the file (they were written
/// on surface 1, the volume and its group lost). Gmsh reads from our output the input's
/// groups, entities and every entity's nodes.
#[test]
fn msh22_volume_meshes_keep_their_volume_and_its_nodes() {
    if !gmsh_available() {
        return;
    }
    // With them: nodes held by quads of surface 1 and triangles of surface 2 only, and by
    // prisms of volume 1 and tetrahedra of volume 2 only (2.2 writes the later type first):
    // on the lower tag, as Gmsh reads them (they went to the first element in the file).
    for name in [
        "box_groups_22_ascii.msh",
        "box_groups_22_bin.msh",
        "order_surfaces_22_ascii.msh",
        "order_volumes_22_ascii.msh",
    ] {
        let (m, input) = load(name);
        let dir = tempfile::tempdir().unwrap();
        let (out, _) = write_recombined(dir.path(), "out.msh", &m, Rule::default());
        let (got, want) = (gmsh_reads(&out, ""), gmsh_reads(&input, ""));
        assert_eq!(got["groups"], want["groups"], "{name}");
        assert_eq!(got["entities"], want["entities"], "{name}");
        let inside = if name.starts_with("order_surfaces") {
            "2 1"
        } else {
            "3 1"
        };
        assert!(
            want["nodes"][inside].as_array().unwrap().len() > 1,
            "{name}"
        );
        assert_eq!(got["nodes"], want["nodes"], "{name}");
    }
}

/// A node tag 0 is refused in every node reader, named where it is (tags are positive; Gmsh
/// reads such a file but gives node 0 the tag of another node, so our output of it would not
/// be what Gmsh then reads).
#[test]
fn node_tag_zero_is_refused() {
    let v22 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n0 1 0 0\n3 0 1 0\n\
               $EndNodes\n$Elements\n1\n1 2 2 1 1 1 0 3\n$EndElements\n";
    let v41 = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 3 0 3\n2 1 0 3\n1\n0\n3\n0 0 0\n\
               1 0 0\n0 1 0\n$EndNodes\n$Elements\n1 1 1 1\n2 1 2 1\n1 1 0 3\n$EndElements\n";
    let mut b41 = msh41_binary_tet(3);
    // The binary file's node tags 1, 2, 3 (one block) become 1, 0, 3.
    let tags: Vec<u8> = [1u64, 2, 3].iter().flat_map(|t| t.to_le_bytes()).collect();
    let at = b41.windows(24).position(|w| w == tags).unwrap();
    b41[at + 8..at + 16].copy_from_slice(&0u64.to_le_bytes());
    for (name, bytes, at) in [
        ("a22.msh", v22.as_bytes().to_vec(), "a22.msh:7:"),
        ("a41.msh", v41.as_bytes().to_vec(), "a41.msh:8:"),
        ("b41.msh", b41, "byte offset "),
    ] {
        let msg = msh::read_bytes(name, &bytes).unwrap_err().to_string();
        assert!(
            msg.contains(at) && msg.contains("bad node tag 0 (tags are positive)"),
            "{name}: {msg}"
        );
    }
}

/// MSH 2.2 binary: nodes 1..3 and one triangle (element 1), then a tetrahedron (element 2)
/// on nodes 1, 2, 3 and `node`.
fn msh22_binary_tet(node: u64) -> Vec<u8> {
    msh22_binary_tet_tagged(2, node as i32)
}

/// [`msh22_binary_tet`] with the tetrahedron's tag and last node tag as written (`i32`).
fn msh22_binary_tet_tagged(tet: i32, node: i32) -> Vec<u8> {
    let mut b = b"$MeshFormat\n2.2 1 8\n".to_vec();
    b.extend(1i32.to_le_bytes());
    b.extend(b"\n$EndMeshFormat\n$Nodes\n3\n");
    for (tag, x, y) in [(1i32, 0.0f64, 0.0f64), (2, 1.0, 0.0), (3, 0.0, 1.0)] {
        b.extend(tag.to_le_bytes());
        for c in [x, y, 0.0] {
            b.extend(c.to_le_bytes());
        }
    }
    b.extend(b"\n$EndNodes\n$Elements\n2\n");
    // Group header (type, count, number of tags), then tag, tags, nodes.
    for (etype, tag, nodes) in [
        (2i32, 1i32, vec![1i32, 2, 3]),
        (4, tet, vec![1, 2, 3, node]),
    ] {
        for x in [etype, 1, 2, tag, 1, 1] {
            b.extend(x.to_le_bytes());
        }
        for n in nodes {
            b.extend(n.to_le_bytes());
        }
    }
    b.extend(b"\n$EndElements\n");
    b
}

/// MSH 4.1 binary (no `$Entities`): the same nodes and elements as [`msh22_binary_tet`],
/// the triangle on surface 1, the tetrahedron on volume 1.
fn msh41_binary_tet(node: u64) -> Vec<u8> {
    let mut b = b"$MeshFormat\n4.1 1 8\n".to_vec();
    b.extend(1i32.to_le_bytes());
    b.extend(b"\n$EndMeshFormat\n$Nodes\n");
    for x in [1u64, 3, 1, 3] {
        b.extend(x.to_le_bytes());
    }
    for x in [2i32, 1, 0] {
        b.extend(x.to_le_bytes());
    }
    b.extend(3u64.to_le_bytes());
    for tag in [1u64, 2, 3] {
        b.extend(tag.to_le_bytes());
    }
    for c in [0.0f64, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        b.extend(c.to_le_bytes());
    }
    b.extend(b"\n$EndNodes\n$Elements\n");
    for x in [2u64, 2, 1, 2] {
        b.extend(x.to_le_bytes());
    }
    for (dim, etype, tag, nodes) in [
        (2i32, 2i32, 1u64, vec![1u64, 2, 3]),
        (3, 4, 2, vec![1, 2, 3, node]),
    ] {
        for x in [dim, 1, etype] {
            b.extend(x.to_le_bytes());
        }
        b.extend(1u64.to_le_bytes());
        b.extend(tag.to_le_bytes());
        for n in nodes {
            b.extend(n.to_le_bytes());
        }
    }
    b.extend(b"\n$EndElements\n");
    b
}

/// Python: Gmsh's reading of `argv[1]`: how many line elements it holds, how many of them
/// are the side of no triangle or quad (a quad made across the curve), how many element
/// sides belong to one element only (a hanging node makes more) and how many lines lie on
/// the curves of the physical group "boundary".
const CURVE_SIDES: &str = r#"
import sys, json, gmsh
gmsh.initialize(["-noenv"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(sys.argv[1])
sides = {}
for etype, k in ((2, 3), (3, 4)):
    _, nodes = gmsh.model.mesh.getElementsByType(etype)
    for i in range(0, len(nodes), k):
        e = [int(x) for x in nodes[i:i + k]]
        for j in range(k):
            key = tuple(sorted((e[j], e[(j + 1) % k])))
            sides[key] = sides.get(key, 0) + 1
boundary = set()
for dim, tag in gmsh.model.getPhysicalGroups(1):
    if gmsh.model.getPhysicalName(dim, tag) == "boundary":
        boundary |= set(int(c) for c in gmsh.model.getEntitiesForPhysicalGroup(dim, tag))
lines, broken, on_boundary = 0, 0, 0
for _, c in gmsh.model.getEntities(1):
    for n in gmsh.model.mesh.getElements(1, c)[2]:
        for i in range(0, len(n), 2):
            lines += 1
            on_boundary += c in boundary
            broken += tuple(sorted((int(n[i]), int(n[i + 1])))) not in sides
once = sum(1 for v in sides.values() if v == 1)
print(json.dumps({"lines": lines, "broken": broken, "once": once, "boundary_lines": on_boundary}))
gmsh.finalize()
"#;

/// No quad straddles a model curve inside a surface: on a square with an embedded crack,
/// circle and point (MSH 4.1 and 2.2) and on a cylinder's shell with its seam, every line
/// element of the written file is still the side of an element, read back by Gmsh, for
/// greedy, selective (under the rule and `--allow-invalid`), the finish, all-quad and the
/// optimum; and the result conforms (element sides used once are exactly the boundary's
/// lines: no hanging node where all-quad split a side on the circle). Before, selective
/// h = 3 made 10 of the 23 crack and circle segments quad diagonals, greedy 6, the optimum 10. The MSH
/// 2.2 file holds the crack's and the circle's lines twice (two physical groups): all-quad
/// split only the first copy of a line on a side it split (3 or 4 lines across a node).
#[test]
fn no_quad_straddles_an_embedded_curve_or_a_seam() {
    if !gmsh_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let runs: [&[&str]; 6] = [
        &["recombine", "--algo", "greedy"],
        &["recombine", "--algo", "selective", "--horizon", "3"],
        &[
            "recombine",
            "--algo",
            "selective",
            "--horizon",
            "3",
            "--allow-invalid",
        ],
        &[
            "recombine",
            "--algo",
            "selective",
            "--horizon",
            "3",
            "--finish",
        ],
        &["recombine", "--algo", "greedy", "--finish", "--all-quad"],
        &["optimum"],
    ];
    for name in [
        "crack_41_ascii.msh",
        "crack_22_ascii.msh",
        "cylinder_41_ascii.msh",
    ] {
        let input = data(name);
        let info = crate::util::run_ok(dir.path(), &["info", "--json", input.to_str().unwrap()]);
        let info: Value = serde_json::from_slice(&info.stdout).unwrap();
        let curve_edges = info["curve_edges"].as_u64().unwrap();
        // The crack's 7 segments and the circle's 16; the seam's 7.
        let want = if name.starts_with("crack") { 23 } else { 7 };
        assert_eq!(curve_edges, want, "{name}: {info}");
        // The 2.2 file writes the lines of the curves in two groups once per group (Gmsh
        // reads each copy); they are merged, so the output holds the 4.1 file's lines.
        let same_41 = data(&name.replace("_22_", "_41_"));
        let original: Value = serde_json::from_str(&python(CURVE_SIDES, &[&same_41])).unwrap();
        if name.contains("_22_") {
            let copies: Value = serde_json::from_str(&python(CURVE_SIDES, &[&input])).unwrap();
            assert!(
                copies["lines"].as_u64() > original["lines"].as_u64(),
                "{copies}"
            );
        }
        for run in runs {
            let out = dir.path().join("out.msh");
            let mut args = vec![run[0], input.to_str().unwrap()];
            args.extend(&run[1..]);
            args.extend(["-o", out.to_str().unwrap()]);
            crate::util::run_ok(dir.path(), &args);
            let got: Value = serde_json::from_str(&python(CURVE_SIDES, &[&out])).unwrap();
            assert_eq!(got["broken"], 0, "{name} {run:?}: {got}");
            assert_eq!(got["once"], got["boundary_lines"], "{name} {run:?}: {got}");
            if !run.contains(&"--all-quad") {
                assert_eq!(got["lines"], original["lines"], "{name} {run:?}: {got}");
            }
        }
    }
}

/// Elements the output cannot hold (a volume's tetrahedra, second-order triangles on one
/// surface of a first-order mesh) are said when `-o` leaves them out, with the physical
/// groups left empty: a solver reading our file would otherwise meet an empty group.
#[test]
fn elements_left_out_of_the_output_are_warned_about() {
    let tmp = tempfile::tempdir().unwrap();
    // A unit square of two triangles (surface 1, group "skin") and a tetrahedron on it
    // (volume 1, group "vol"), and a 6-node triangle on surface 2 (group "curved").
    let msh = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n3\n2 1 \"skin\"\n\
               3 2 \"vol\"\n2 3 \"curved\"\n$EndPhysicalNames\n$Entities\n0 0 2 1\n\
               1 0 0 0 1 1 0 1 1 0\n2 0 0 0 1 1 0 1 3 0\n1 0 0 0 1 1 1 1 2 1 1\n$EndEntities\n\
               $Nodes\n2 8 1 8\n2 1 0 7\n1\n2\n3\n4\n6\n7\n8\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n\
               0.5 0 0\n0.5 0.5 0\n0 0.5 0\n3 1 0 1\n5\n0.5 0.5 1\n$EndNodes\n\
               $Elements\n3 4 1 4\n2 1 2 2\n1 1 2 3\n2 1 3 4\n3 1 4 1\n3 1 2 3 5\n\
               2 2 9 1\n4 1 2 4 6 7 8\n$EndElements\n";
    std::fs::write(tmp.path().join("in.msh"), msh).unwrap();
    let out = run_in(
        tmp.path(),
        &["recombine", "in.msh", "--algo", "greedy", "-o", "out.msh"],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains(
            "warning: out.msh: the input's 1 Tetrahedron 4 (type 4), 1 Triangle 6 (type 9) are \
             not written"
        ) && err.contains(
            "physical groups left with no element: \"curved\" (dimension 2, tag 3), \"vol\" \
             (dimension 3, tag 2)"
        ) && !err.contains("\"skin\""),
        "{err}"
    );
    // Nothing left out (a mesh with groups, points and lines), nothing said.
    let out = run_in(
        tmp.path(),
        &[
            "recombine",
            repo_path("tests/data/crack_41_ascii.msh").to_str().unwrap(),
            "--algo",
            "greedy",
            "-o",
            "again.msh",
        ],
    );
    assert!(out.status.success());
    assert!(
        !String::from_utf8_lossy(&out.stderr).contains("not written"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A binary file whose data size is not 8 is refused, naming what the size is of in each
/// version (a double's in MSH 2.2, a size_t's in MSH 4.1; the message said size_t alone).
#[test]
fn a_binary_data_size_other_than_8_is_refused() {
    for version in ["2.2", "4.1"] {
        let mut b = format!("$MeshFormat\n{version} 1 4\n").into_bytes();
        b.extend(1i32.to_le_bytes());
        b.extend(b"\n$EndMeshFormat\n");
        let err = quadrecomb::internals::mesh::msh::read_bytes("f.msh", &b)
            .unwrap_err()
            .to_string();
        assert!(err.contains("f.msh"), "{err}");
        assert!(
            err.contains(
                "unsupported data size `4` in a binary file (only 8 is read: the size \
                 of a double in MSH 2.2, of a size_t in MSH 4.1)"
            ),
            "{err}"
        );
    }
}
