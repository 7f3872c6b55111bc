//! Mesh input and output: the four MSH variants, round trips through the writers (and Gmsh),
//! every bad input through the CLI, and a seeded mutation fuzzer over the MSH reader.

use crate::util::{
    SEED, gmsh_available, python, python_module_available, repo_path, run_in, run_ok,
};
use quadrecomb::internals::mesh::{self, Mesh, MeshError, ReadError, Recombined, msh, vtu};
use quadrecomb::internals::quality::{self, CandidateTable};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

fn data(name: &str) -> PathBuf {
    repo_path("tests/data").join(name)
}

/// Coordinates equal up to the 16 significant digits Gmsh writes in ASCII files.
fn assert_close(a: &[[f64; 3]], b: &[[f64; 3]], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}");
    for (p, q) in a.iter().zip(b) {
        for k in 0..3 {
            assert!(
                (p[k] - q[k]).abs() <= 1e-15 * p[k].abs().max(1.0),
                "{what}: {p:?} vs {q:?}"
            );
        }
    }
}

fn read(name: &str) -> Mesh {
    let m = msh::read(&data(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
    m.sanity_check().unwrap_or_else(|e| panic!("{name}: {e}"));
    m
}

/// The triangles as sets of corner coordinates (to 12 digits), for meshes whose node tags
/// differ.
fn triangle_points_set(m: &Mesh) -> BTreeSet<Vec<String>> {
    (0..m.num_triangles() as u32)
        .map(|t| {
            let mut c: Vec<String> = m
                .triangle_points(t)
                .iter()
                .map(|p| format!("{:.12} {:.12} {:.12}", p[0], p[1], p[2]))
                .collect();
            c.sort();
            c
        })
        .collect()
}

/// Triangles as sets of node tags, with their element tag and surface.
fn triangle_set(m: &Mesh) -> BTreeSet<([u64; 3], i32)> {
    m.triangles
        .iter()
        .zip(&m.triangle_surface)
        .map(|(t, &s)| {
            let mut k = t.map(|v| m.vertex_ids[v as usize]);
            k.sort_unstable();
            (k, s)
        })
        .collect()
}

fn quad_set(m: &Mesh) -> BTreeSet<([u64; 4], i32)> {
    m.quads
        .iter()
        .zip(&m.quad_surface)
        .map(|(q, &s)| {
            let mut k = q.map(|v| m.vertex_ids[v as usize]);
            k.sort_unstable();
            (k, s)
        })
        .collect()
}

/// Element counts (triangles, quads) and node count of `path` as Gmsh reads them.
fn gmsh_counts(path: &Path) -> (usize, usize, usize) {
    let script = r#"
import sys, gmsh
gmsh.initialize(["-noenv"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(sys.argv[1])
def count(t):
    return sum(len(tags) for tags in [gmsh.model.mesh.getElementsByType(t)[0]])
print(count(2), count(3), len(gmsh.model.mesh.getNodes()[0]))
gmsh.finalize()
"#;
    let s = python(script, &[path]);
    let v: Vec<usize> = s.split_whitespace().map(|x| x.parse().unwrap()).collect();
    (v[0], v[1], v[2])
}

/// A matching of candidates: take each candidate whose triangles are both still free.
fn greedy(mesh: &Mesh, table: &CandidateTable) -> Vec<u32> {
    let mut used = vec![false; mesh.num_triangles()];
    let mut chosen = Vec::new();
    for (c, &[a, b]) in table.pairs.iter().enumerate() {
        if !used[a as usize] && !used[b as usize] {
            used[a as usize] = true;
            used[b as usize] = true;
            chosen.push(c as u32);
        }
    }
    chosen
}

#[test]
fn four_variants_read_identically() {
    let names = [
        ("two_squares_22_ascii.msh", "2.2", false),
        ("two_squares_22_bin.msh", "2.2", true),
        ("two_squares_41_ascii.msh", "4.1", false),
        ("two_squares_41_bin.msh", "4.1", true),
    ];
    let first = read(names[0].0);
    assert_eq!(first.num_triangles(), 44);
    assert_eq!(first.vertices.len(), 31);
    assert_eq!(first.surfaces(), vec![1, 2]);
    for (name, version, binary) in names {
        let bytes = std::fs::read(data(name)).unwrap();
        let file = msh::parse(Path::new(name), &bytes).unwrap();
        assert_eq!(file.version.to_string(), version, "{name}");
        assert_eq!(file.binary, binary, "{name}");
        assert!(
            file.ignored_elements > 0,
            "{name}: points and lines are skipped"
        );
        let m = read(name);
        assert_close(&m.vertices, &first.vertices, name);
        assert_eq!(m.vertex_ids, first.vertex_ids, "{name}");
        assert_eq!(m.triangles, first.triangles, "{name}");
        assert_eq!(m.triangle_ids, first.triangle_ids, "{name}");
        assert_eq!(m.triangle_surface, first.triangle_surface, "{name}");
        // read_bytes gives the same mesh and names the file it was given.
        let mb = msh::read_bytes(name, &bytes).unwrap();
        assert_eq!(mb.triangles, m.triangles);
    }
}

#[test]
fn crlf_and_byte_order_mark_are_accepted() {
    let text = std::fs::read_to_string(data("two_squares_41_ascii.msh")).unwrap();
    let dos = format!("\u{feff}{}", text.replace('\n', "\r\n"));
    let a = msh::read_bytes("dos.msh", dos.as_bytes()).unwrap();
    let b = read("two_squares_41_ascii.msh");
    assert_eq!(a.triangles, b.triangles);
    assert_eq!(a.vertices, b.vertices);
}

#[test]
fn triangle_counts_match_gmsh() {
    if !gmsh_available() {
        return;
    }
    for name in [
        "two_squares_22_bin.msh",
        "two_squares_41_ascii.msh",
        "mixed_41_ascii.msh",
        "param_41_bin.msh",
    ] {
        let m = read(name);
        let (t, q, _) = gmsh_counts(&data(name));
        assert_eq!((m.num_triangles(), m.quads.len()), (t, q), "{name}");
    }
}

#[test]
fn parametric_coordinates_are_skipped() {
    let a = read("param_41_ascii.msh");
    let b = read("param_41_bin.msh");
    assert_eq!(a.num_triangles(), 26);
    assert_close(&a.vertices, &b.vertices, "param");
    assert_eq!(a.triangles, b.triangles);
    for p in &a.vertices {
        assert!((0.0..=1.0).contains(&p[0]) && (0.0..=1.0).contains(&p[1]) && p[2] == 0.0);
    }
}

#[test]
fn input_quads_are_kept() {
    let a = read("mixed_41_ascii.msh");
    let b = read("mixed_22_ascii.msh");
    assert_eq!((a.num_triangles(), a.quads.len()), (22, 11));
    assert_eq!(triangle_set(&a), triangle_set(&b));
    assert_eq!(quad_set(&a), quad_set(&b));
    // Quads are on their own surface and never part of a candidate.
    assert!(a.quad_surface.iter().all(|&s| s == 2));
    assert!(a.triangle_surface.iter().all(|&s| s == 1));
}

#[test]
fn sparse_tags_are_mapped_and_reported() {
    let text = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n\
                1000000000000 0 0 0\n7 1 0 0\n123456789 1 1 0\n3 0 1 0\n$EndNodes\n\
                $Elements\n2\n101 2 2 5 5 1000000000000 7 123456789\n\
                205 2 2 5 5 1000000000000 123456789 3\n$EndElements\n";
    let m = msh::read_bytes("sparse.msh", text.as_bytes()).unwrap();
    m.sanity_check().unwrap();
    assert_eq!(m.vertex_ids, vec![1_000_000_000_000, 7, 123_456_789, 3]);
    assert_eq!(m.triangle_ids, vec![101, 205]);
    assert_eq!(m.triangle_surface, vec![5, 5]);
    // Content errors carry the file's tags, not indices.
    let dup = text.replace("123456789 3\n", "7 123456789\n");
    match msh::read_bytes("sparse.msh", dup.as_bytes()) {
        Err(ReadError::Mesh {
            source: MeshError::DuplicateTriangle { element, first },
            ..
        }) => assert_eq!((element, first), (205, 101)),
        other => panic!("expected a duplicate triangle, got {other:?}"),
    }
}

#[test]
fn load_detects_format_by_content() {
    let dir = tempfile::tempdir().unwrap();
    // A MSH file with another extension loads; a non-MSH file with .msh does not.
    let odd = dir.path().join("mesh.dat");
    std::fs::copy(data("two_squares_41_bin.msh"), &odd).unwrap();
    assert_eq!(
        mesh::load(odd.to_str().unwrap()).unwrap().num_triangles(),
        44
    );
    let bad = data("bad/unknown_format.msh");
    assert!(matches!(
        mesh::load(bad.to_str().unwrap()),
        Err(ReadError::UnknownFormat { .. })
    ));
    let missing = dir.path().join("missing.msh");
    match mesh::load(missing.to_str().unwrap()) {
        Err(e @ ReadError::Io { .. }) => assert!(e.to_string().contains("missing.msh"), "{e}"),
        other => panic!("expected an I/O error, got {other:?}"),
    }
    for &name in mesh::builtin::NAMES {
        let m = mesh::load(name).unwrap_or_else(|e| panic!("built-in {name}: {e}"));
        m.sanity_check().unwrap();
        if name == "borouchaki" {
            assert_eq!(m.num_triangles(), 34_456);
        }
    }
}

#[test]
fn msh_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    for name in [
        "two_squares_41_ascii.msh",
        "mixed_22_ascii.msh",
        "param_41_bin.msh",
    ] {
        let m = read(name);
        // Unrecombined: the same triangles and quads come back.
        let out = dir.path().join("plain.msh");
        msh::write(&out, &m, &Recombined::unrecombined(&m)).unwrap();
        let back = msh::read(&out).unwrap();
        back.sanity_check().unwrap();
        assert_eq!(back.vertices.len(), m.vertices.len(), "{name}");
        assert_eq!(triangle_set(&back), triangle_set(&m), "{name}");
        assert_eq!(quad_set(&back), quad_set(&m), "{name}");
        // Recombined: quads plus leftover triangles, on the right surfaces.
        let table = CandidateTable::build(&m);
        let chosen = greedy(&m, &table);
        assert!(!chosen.is_empty());
        let rec = quality::recombined(&m, &table, &chosen);
        let out = dir.path().join("rec.msh");
        msh::write(&out, &m, &rec).unwrap();
        let back = msh::read(&out).unwrap();
        back.sanity_check().unwrap();
        assert_eq!(back.num_triangles(), rec.leftover.len(), "{name}");
        assert_eq!(back.quads.len(), rec.quads.len() + m.quads.len(), "{name}");
        assert_eq!(back.surfaces(), m.surfaces(), "{name}");
        let mut want: Vec<i32> = rec.quad_surface.clone();
        want.extend(&m.quad_surface);
        want.sort_unstable();
        let mut got = back.quad_surface.clone();
        got.sort_unstable();
        assert_eq!(got, want, "{name}");
        // The same mesh through every reader variant: the written 4.1 file re-parses exactly.
        let again = msh::read_bytes("rec.msh", &std::fs::read(&out).unwrap()).unwrap();
        assert_eq!(again.vertices, back.vertices);
    }
}

#[test]
fn written_msh_opens_in_gmsh() {
    if !gmsh_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for name in ["two_squares_41_ascii.msh", "mixed_41_ascii.msh"] {
        let m = read(name);
        let table = CandidateTable::build(&m);
        let rec = quality::recombined(&m, &table, &greedy(&m, &table));
        let out = dir.path().join("rec.msh");
        msh::write(&out, &m, &rec).unwrap();
        let (t, q, n) = gmsh_counts(&out);
        assert_eq!(t, rec.leftover.len(), "{name}: triangles");
        assert_eq!(q, rec.quads.len() + m.quads.len(), "{name}: quads");
        assert_eq!(n, m.vertices.len(), "{name}: nodes");
    }
}

/// The whitespace-separated values of the `<DataArray ... Name="name" ...>` element.
fn data_array<'a>(xml: &'a str, name: &str) -> Vec<&'a str> {
    let key = format!("Name=\"{name}\"");
    let start = xml.find(&key).unwrap_or_else(|| panic!("no array {name}"));
    let body = &xml[start..];
    let open = body.find('>').unwrap() + 1;
    let close = body.find("</DataArray>").unwrap();
    body[open..close].split_whitespace().collect()
}

#[test]
fn vtu_ascii_is_well_formed_with_cell_data() {
    let m = read("mixed_41_ascii.msh");
    let table = CandidateTable::build(&m);
    let rec = quality::recombined(&m, &table, &greedy(&m, &table));
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("rec.vtu");
    let mut bytes = Vec::new();
    vtu::write_to(&mut bytes, &m, &rec, vtu::Encoding::Ascii).unwrap();
    std::fs::write(&out, &bytes).unwrap();
    let xml = String::from_utf8(bytes).unwrap();
    let cells = rec.quads.len() + m.quads.len() + rec.leftover.len();
    assert!(xml.contains(&format!(
        "NumberOfPoints=\"{}\" NumberOfCells=\"{cells}\"",
        m.vertices.len()
    )));
    let types = data_array(&xml, "types");
    assert_eq!(types.len(), cells);
    assert_eq!(
        types.iter().filter(|&&t| t == "9").count(),
        rec.quads.len() + m.quads.len()
    );
    assert_eq!(
        types.iter().filter(|&&t| t == "5").count(),
        rec.leftover.len()
    );
    let offsets = data_array(&xml, "offsets");
    let conn = data_array(&xml, "connectivity");
    assert_eq!(
        offsets.last().unwrap().parse::<usize>().unwrap(),
        conn.len()
    );
    assert!(
        conn.iter()
            .all(|v| v.parse::<usize>().unwrap() < m.vertices.len())
    );
    let quality: Vec<f64> = data_array(&xml, "quality")
        .iter()
        .map(|v| v.parse().unwrap())
        .collect();
    let kind = data_array(&xml, "kind");
    assert_eq!(quality.len(), cells);
    assert_eq!(data_array(&xml, "surface").len(), cells);
    let node: Vec<u64> = (data_array(&xml, "node").iter())
        .map(|v| v.parse().unwrap())
        .collect();
    assert_eq!(node, m.vertex_ids);
    for (q, k) in quality.iter().zip(&kind) {
        match *k {
            "0" => assert!((0.0..=1.0).contains(q)),
            "1" | "2" => assert_eq!(*q, -1.0),
            other => panic!("unknown kind {other}"),
        }
    }
    let etas: Vec<f64> = quality.iter().copied().filter(|&q| q >= 0.0).collect();
    assert_eq!(etas, rec.quad_eta);
    // Well-formed XML, checked by Python's parser where Python is present.
    if let Ok(o) = Command::new("python3")
        .args([
            "-c",
            "import sys, xml.etree.ElementTree as E; E.parse(sys.argv[1])",
        ])
        .arg(&out)
        .output()
    {
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
}

/// The binary `.vtu` (the default) as VTK's own XML reader and meshio read it: the same
/// points, cells and cell data as the ASCII file and as the recombination written, to the bit,
/// in less than a third of the bytes.
#[test]
fn vtu_binary_reads_in_vtk_and_meshio() {
    if !["vtk", "meshio", "gmsh"]
        .iter()
        .all(|m| python_module_available(m))
    {
        return;
    }
    let m = mesh::load("borouchaki").unwrap();
    let table = CandidateTable::build(&m);
    let rec = quality::recombined(&m, &table, &greedy(&m, &table));
    let dir = tempfile::tempdir().unwrap();
    let (bin, ascii) = (dir.path().join("bin.vtu"), dir.path().join("ascii.vtu"));
    vtu::write(&bin, &m, &rec).unwrap();
    let mut text = Vec::new();
    vtu::write_to(&mut text, &m, &rec, vtu::Encoding::Ascii).unwrap();
    std::fs::write(&ascii, &text).unwrap();
    let (bin_len, ascii_len) = (std::fs::metadata(&bin).unwrap().len(), text.len() as u64);
    assert!(
        3 * bin_len < ascii_len,
        "binary {bin_len} B vs ASCII {ascii_len} B"
    );
    let script = r#"
import sys, json
import numpy as np
import meshio
from vtk import vtkXMLUnstructuredGridReader
from vtk.util.numpy_support import vtk_to_numpy
def by_vtk(path):
    r = vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    assert r.GetErrorCode() == 0, r.GetErrorCode()
    g = r.GetOutput()
    cd = g.GetCellData()
    return {
        "points": vtk_to_numpy(g.GetPoints().GetData()),
        "types": vtk_to_numpy(g.GetCellTypesArray()),
        "conn": vtk_to_numpy(g.GetCells().GetConnectivityArray()),
        "quality": vtk_to_numpy(cd.GetArray("quality")),
        "surface": vtk_to_numpy(cd.GetArray("surface")),
        "kind": vtk_to_numpy(cd.GetArray("kind")),
        "node": vtk_to_numpy(g.GetPointData().GetArray("node")),
    }
b, a = by_vtk(sys.argv[1]), by_vtk(sys.argv[2])
for k in b:
    assert np.array_equal(b[k], a[k]), k
mb, ma = meshio.read(sys.argv[1]), meshio.read(sys.argv[2])
assert np.array_equal(mb.points, ma.points)
assert np.array_equal(mb.points, b["points"])
for cb, ca in zip(mb.cells, ma.cells):
    assert cb.type == ca.type and np.array_equal(cb.data, ca.data)
for name in ("quality", "surface", "kind"):
    for x, y in zip(mb.cell_data[name], ma.cell_data[name]):
        assert np.array_equal(x, y), name
assert np.array_equal(mb.point_data["node"], b["node"])
# Each point is the input's node that `node` names, as Gmsh reads the input.
import gmsh
gmsh.initialize(["-noenv"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(sys.argv[3])
tags, xyz, _ = gmsh.model.mesh.getNodes()
gmsh.finalize()
at = dict(zip(tags.tolist(), xyz.reshape(-1, 3).tolist()))
assert b["node"].dtype == np.uint64, b["node"].dtype
assert sorted(b["node"].tolist()) == sorted(at), "node tags"
assert all(at[int(t)] == p.tolist() for t, p in zip(b["node"], b["points"])), "node coordinates"
print(json.dumps({
    "points": int(b["points"].shape[0]),
    "quads": int((b["types"] == 9).sum()),
    "triangles": int((b["types"] == 5).sum()),
    "quality": [float(q) for q in b["quality"] if q >= 0],
    "kind0": int((b["kind"] == 0).sum()),
    "meshio": {c.type: int(len(c.data)) for c in mb.cells},
}))
"#;
    let input = crate::util::repo_path("meshes/borouchaki.msh");
    let r: serde_json::Value =
        serde_json::from_str(&python(script, &[&bin, &ascii, &input])).unwrap();
    assert_eq!(r["points"], m.vertices.len());
    assert_eq!(r["quads"], rec.quads.len() + m.quads.len());
    assert_eq!(r["triangles"], rec.leftover.len());
    assert_eq!(r["kind0"], rec.quads.len());
    assert_eq!(r["meshio"]["quad"], rec.quads.len() + m.quads.len());
    let etas: Vec<f64> = (r["quality"].as_array().unwrap().iter())
        .map(|q| q.as_f64().unwrap())
        .collect();
    assert_eq!(
        etas, rec.quad_eta,
        "eta read back by VTK differs from the one written"
    );
}

/// `-o x.vtu` writes compressed binary arrays; `--vtu-ascii` writes them as text, the same
/// values; `--vtu-ascii` without `-o` is a usage error.
#[test]
fn vtu_output_is_binary_unless_asked_for_text() {
    let dir = tempfile::tempdir().unwrap();
    let run = |extra: &[&str]| {
        let mut args = vec!["recombine", "sphere", "--algo", "greedy"];
        args.extend_from_slice(extra);
        run_in(dir.path(), &args)
    };
    assert!(run(&["-o", "b.vtu"]).status.success());
    assert!(run(&["-o", "a.vtu", "--vtu-ascii"]).status.success());
    let b = std::fs::read(dir.path().join("b.vtu")).unwrap();
    let a = std::fs::read_to_string(dir.path().join("a.vtu")).unwrap();
    let b_head = String::from_utf8_lossy(&b[..b.len().min(2000)]).to_string();
    assert!(
        b_head.contains(r#"compressor="vtkZLibDataCompressor""#),
        "{b_head}"
    );
    assert!(b_head.contains(r#"format="appended""#));
    assert!(a.contains(r#"format="ascii""#) && !a.contains("AppendedData"));
    assert!(
        b.len() * 2 < a.len(),
        "binary {} B, text {} B",
        b.len(),
        a.len()
    );
    assert_eq!(run(&["--vtu-ascii"]).status.code(), Some(2));
}

/// A mesh in another format gets an error that says how to convert it, and the commands it
/// names (Gmsh's and meshio's, run where their command-line tools are installed) make a `.msh`
/// that quadrecomb reads.
#[test]
fn other_formats_get_a_conversion_command_that_works() {
    let dir = tempfile::tempdir().unwrap();
    let files = [
        (
            "tri.stl",
            "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n",
        ),
        ("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
    ];
    for (name, text) in files {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let out = run_in(dir.path(), &["info", name]);
        assert_eq!(out.status.code(), Some(3));
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(err.contains("unknown mesh format"), "{err}");
        // Each suggested command, between backticks, run as written.
        let commands: Vec<&str> = err.split('`').skip(1).step_by(2).collect();
        assert_eq!(commands.len(), 2, "{err}");
        assert!(commands[0].starts_with("gmsh ") && commands[1].contains("meshio convert"));
        for command in commands {
            let command = command.trim_start_matches("pip install meshio; ");
            let words: Vec<&str> = command.split_whitespace().collect();
            let msh = dir.path().join("tri.msh");
            let _ = std::fs::remove_file(&msh);
            match Command::new(words[0])
                .args(&words[1..])
                .current_dir(dir.path())
                .output()
            {
                Ok(o) if o.status.success() => {
                    let info = run_in(dir.path(), &["info", "tri.msh", "--json"]);
                    assert!(
                        info.status.success(),
                        "{command}: {}",
                        String::from_utf8_lossy(&info.stderr)
                    );
                    let v: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
                    assert_eq!(v["triangles"], 1, "{command}");
                }
                Ok(o) => panic!("{command} failed: {}", String::from_utf8_lossy(&o.stderr)),
                Err(_) => eprintln!("skipping `{command}`: {} is not installed", words[0]),
            }
        }
    }
}

/// Runs `quadrecomb info path` and checks exit code 3 (bad input), no panic, and that the message names
/// the file and says each of `expect`.
fn assert_bad(path: &Path, expect: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), &["info", path.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(3), "{}: {err}", path.display());
    assert!(!err.contains("panicked"), "{err}");
    let file = path.file_name().unwrap().to_str().unwrap();
    assert!(err.contains(file), "message does not name {file}: {err}");
    for e in expect {
        assert!(err.contains(e), "message lacks `{e}`: {err}");
    }
    err
}

fn bad(name: &str) -> PathBuf {
    data("bad").join(name)
}

#[test]
fn bad_input_missing_file() {
    let err = assert_bad(
        Path::new("/nonexistent/dir/no_such_mesh.msh"),
        &["No such file"],
    );
    assert_eq!(
        err.matches("No such file").count(),
        1,
        "cause repeated: {err}"
    );
    // A bare word is taken for a mistyped name: the message lists the names.
    let err = assert_bad(
        Path::new("spheres"),
        &["spheres: no such file, nor a built-in mesh"],
    );
    assert!(
        err.contains("(borouchaki, sphere)") && err.contains("quadrecomb suite list"),
        "{err}"
    );
}

#[test]
fn bad_input_unknown_format_and_version() {
    assert_bad(&bad("unknown_format.msh"), &["unknown mesh format"]);
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("zero_bytes.msh");
    std::fs::write(&empty, "").unwrap();
    assert_bad(&empty, &[":1:", "the file is empty"]);
    assert_bad(
        &bad("unsupported_version.msh"),
        &[
            ":2:",
            "unsupported MSH version `3.0`",
            "re-save it with Gmsh as version 4.1: `gmsh ",
            "unsupported_version.msh -0 -format msh41 -o ",
            "unsupported_version.41.msh`",
        ],
    );
    // Gmsh's legacy MSH 1.0 (no $MeshFormat; Gmsh still reads it, meshio does not): named,
    // with Gmsh's command that re-saves it, not taken for another tool's .msh.
    let legacy = dir.path().join("legacy.msh");
    std::fs::write(
        &legacy,
        "\n$NOD\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$ENDNOD\n$ELM\n1\n1 2 1 1 3 1 2 3\n$ENDELM\n",
    )
    .unwrap();
    let err = assert_bad(
        &legacy,
        &[
            "legacy.msh:2: this is Gmsh's legacy MSH 1.0 format (`$NOD`)",
            "-format msh41 -o ",
        ],
    );
    assert!(!err.contains("Fluent"), "{err}");
}

#[test]
fn bad_input_truncated_and_missing_sections() {
    assert_bad(
        &bad("truncated.msh"),
        &[":15:", "truncated", "$EndElements"],
    );
    assert_bad(
        &bad("missing_end_nodes.msh"),
        &[":10:", "expected $EndNodes"],
    );
}

#[test]
fn bad_input_wrong_counts() {
    assert_bad(
        &bad("wrong_node_count.msh"),
        &[
            ":10:",
            "node 5 of 5",
            "fewer entries than its header announces",
        ],
    );
    assert_bad(
        &bad("wrong_element_count.msh"),
        &[":15:", "element 3 of 3", "fewer entries"],
    );
    // More elements than announced.
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(bad("odd_triangles.msh")).unwrap();
    let p = dir.path().join("too_many.msh");
    std::fs::write(&p, text.replace("$Elements\n3\n", "$Elements\n2\n")).unwrap();
    assert_bad(&p, &[":16:", "expected $EndElements after 2 elements"]);
}

#[test]
fn bad_input_unknown_node() {
    assert_bad(
        &bad("unknown_node.msh"),
        &[":14:", "element 2 refers to node 9, which does not exist"],
    );
}

#[test]
fn bad_input_non_finite_coordinates() {
    assert_bad(&bad("nan_coordinate.msh"), &[":8:", "node 3", "non-finite"]);
    assert_bad(&bad("inf_coordinate.msh"), &[":8:", "node 3", "inf"]);
}

#[test]
fn bad_input_degenerate_duplicate_non_manifold() {
    assert_bad(&bad("degenerate.msh"), &["triangle 3 is degenerate"]);
    assert_bad(&bad("duplicate.msh"), &["triangle 3 duplicates triangle 2"]);
    assert_bad(
        &bad("non_manifold.msh"),
        &["non-manifold edge between nodes 1 and 3", "shared by 3"],
    );
}

/// A compressed mesh is told by its first bytes, and the command the message gives makes a
/// file that reads.
#[test]
fn compressed_input_names_the_command_that_decompresses_it() {
    let dir = tempfile::tempdir().unwrap();
    let zipped = Command::new("gzip")
        .arg("-c")
        .arg(data("two_squares_41_ascii.msh"))
        .output()
        .expect("gzip")
        .stdout;
    // Gzipped meshes named `name`, given to `info` as relative names: the command the
    // message gives, run by sh, leaves the input as it was and writes `want`, which reads.
    for (name, want) in [
        ("two.msh.gz", "two.msh"),
        // Named as its output would be: another name, or the shell empties the input.
        ("m.msh", "m.decompressed.msh"),
        // Spaces, a quote and a leading dash: quoted, and not read as an option.
        ("-it's a mesh.MSH.GZ", "-it's a mesh.MSH"),
        // two.msh exists now (the first case wrote it): not written over.
        ("two.msh.gz", "two.decompressed.msh"),
    ] {
        let p = dir.path().join(name);
        std::fs::write(&p, &zipped).unwrap();
        let out = run_in(dir.path(), &["info", "--", name]);
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert_eq!(out.status.code(), Some(3), "{err}");
        assert!(
            err.contains("gzip-compressed") && err.contains("`gzip -dc "),
            "{err}"
        );
        assert!(!err.contains("convert it"), "{err}");
        let command = err.split('`').nth(1).unwrap();
        let done = Command::new("sh")
            .args(["-c", command])
            .current_dir(dir.path())
            .status()
            .unwrap();
        assert!(done.success(), "{command}");
        assert_eq!(
            std::fs::read(&p).unwrap(),
            zipped,
            "{command} changed {name}"
        );
        assert_eq!(
            msh::read(&dir.path().join(want)).unwrap().num_triangles(),
            read("two_squares_41_ascii.msh").num_triangles(),
            "{command}"
        );
    }
    // Other compressors by their magic bytes.
    for (magic, what) in [
        (&b"BZh91AY&SY"[..], "bzip2-compressed"),
        (b"\xfd7zXZ\x00\x00", "xz-compressed"),
        (b"\x28\xb5\x2f\xfd\x00", "zstd-compressed"),
        (b"PK\x03\x04\x14\x00", "a zip archive"),
    ] {
        let p = dir.path().join("mesh.bin");
        std::fs::write(&p, magic).unwrap();
        assert_bad(&p, &[what, "mesh.bin > "]);
    }
}

/// `info` counts the edges where surfaces meet (three or more elements), on a triangle mesh
/// and on a mesh of quads only (the box and wall finished to all quads), as counted here
/// from the file's elements.
#[test]
fn info_counts_the_edges_where_surfaces_meet() {
    let dir = tempfile::tempdir().unwrap();
    let box_wall = data("box_wall_41_ascii.msh");
    let args = [
        "--algo",
        "selective",
        "--finish",
        "--all-quad",
        "-o",
        "aq.msh",
    ];
    let mut all = vec!["recombine", box_wall.to_str().unwrap()];
    all.extend(args);
    run_ok(dir.path(), &all);
    for path in [
        data("stiffened_41_ascii.msh"),
        box_wall.clone(),
        dir.path().join("aq.msh"),
    ] {
        let file = msh::parse(&path, &std::fs::read(&path).unwrap()).unwrap();
        let mut uses: std::collections::HashMap<(u32, u32), usize> = Default::default();
        let sides = |e: &[u32]| -> Vec<(u32, u32)> {
            (0..e.len())
                .map(|i| {
                    (
                        e[i].min(e[(i + 1) % e.len()]),
                        e[i].max(e[(i + 1) % e.len()]),
                    )
                })
                .collect()
        };
        let elements = (file.data.triangles.iter().map(|t| sides(t)))
            .chain(file.data.quads.iter().map(|q| sides(q)));
        for side in elements.flatten() {
            *uses.entry(side).or_default() += 1;
        }
        let want = uses.values().filter(|&&n| n > 2).count();
        assert!(want > 10, "{}", path.display());
        let out = run_ok(dir.path(), &["info", "--json", path.to_str().unwrap()]);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["junction_edges"], want, "{}", path.display());
        let text = run_ok(dir.path(), &["info", path.to_str().unwrap()]);
        let text = String::from_utf8_lossy(&text.stdout).to_string();
        assert!(
            text.contains(&format!("junction edges:       {want} ")),
            "{text}"
        );
    }
}

/// `info` counts element nodes lying exactly where another element node lies (a crack:
/// the elements on either side are not joined), on triangles and on quad-only files; an
/// unused node does not count, -0 is 0, and Gmsh's conforming two squares have none.
#[test]
fn info_counts_coincident_nodes() {
    let dir = tempfile::tempdir().unwrap();
    // A unit square split along its diagonal, the second triangle on copies of the
    // diagonal's nodes (5 and 6, one written with -0), and node 7 unused on node 2.
    let nodes =
        "$Nodes\n7\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n5 -0 0 0\n6 1 1 0\n7 1 0 0\n$EndNodes\n";
    let header = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
    let tri =
        format!("{header}{nodes}$Elements\n2\n1 2 2 1 1 1 2 3\n2 2 2 1 1 5 6 4\n$EndElements\n");
    // Two quads side by side, the second on copies of the shared side's nodes.
    let quad = format!(
        "{header}$Nodes\n8\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n5 1 0 0\n6 2 0 0\n7 2 1 0\n\
         8 1 1 0\n$EndNodes\n$Elements\n2\n1 3 2 1 1 1 2 3 4\n2 3 2 1 1 5 6 7 8\n$EndElements\n"
    );
    let joined = data("two_squares_41_ascii.msh");
    for (name, text, want) in [
        ("tri.msh", Some(tri), 2),
        ("quad.msh", Some(quad), 2),
        ("", None, 0),
    ] {
        let path = match text {
            Some(t) => {
                let p = dir.path().join(name);
                std::fs::write(&p, t).unwrap();
                p
            }
            None => joined.clone(),
        };
        let out = run_ok(dir.path(), &["info", "--json", path.to_str().unwrap()]);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["coincident_nodes"], want, "{}", path.display());
        let text = run_ok(dir.path(), &["info", path.to_str().unwrap()]);
        let text = String::from_utf8_lossy(&text.stdout).to_string();
        let line = format!("coincident nodes:     {want} (");
        assert_eq!(text.contains(&line), want > 0, "{text}");
    }
}

/// `info` counts neighbouring triangles folded over each other (normals more than 150 degrees
/// apart once oriented consistently): in a plane, a triangle lying back over its neighbour;
/// on a hinge, a bend past 150 degrees and not one short of it, nor a right angle. The expected counts come
/// from the coordinates written here (signed areas, the hinge's angle), not from our code.
#[test]
fn info_counts_folded_pairs() {
    let dir = tempfile::tempdir().unwrap();
    let header = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
    let write = |name: &str, nodes: &[[f64; 3]], tris: &[[usize; 3]]| {
        let mut t = format!("{header}$Nodes\n{}\n", nodes.len());
        for (i, p) in nodes.iter().enumerate() {
            t += &format!("{} {} {} {}\n", i + 1, p[0], p[1], p[2]);
        }
        t += &format!("$EndNodes\n$Elements\n{}\n", tris.len());
        for (i, v) in tris.iter().enumerate() {
            t += &format!("{} 2 2 1 1 {} {} {}\n", i + 1, v[0] + 1, v[1] + 1, v[2] + 1);
        }
        t += "$EndElements\n";
        let p = dir.path().join(name);
        std::fs::write(&p, t).unwrap();
        p
    };
    // A unit square of two triangles; across its right side a triangle whose third node lies
    // inside the square (folded back over it), across its top one that lies outside. Every
    // shared side is written in opposite directions by its two triangles (one orientation).
    let nodes = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.5, 0.4, 0.0],
        [0.5, 2.0, 0.0],
    ];
    let tris = [[0, 1, 2], [0, 2, 3], [2, 1, 4], [3, 2, 5]];
    let signed = |t: [usize; 3]| {
        let [a, b, c] = t.map(|v| nodes[v]);
        (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    };
    let shares_side =
        |s: [usize; 3], t: [usize; 3]| s.iter().filter(|v| t.contains(v)).count() == 2;
    let mut want_plane = 0;
    for i in 0..tris.len() {
        for j in i + 1..tris.len() {
            if shares_side(tris[i], tris[j]) && signed(tris[i]) * signed(tris[j]) < 0.0 {
                want_plane += 1;
            }
        }
    }
    assert_eq!(want_plane, 1);
    let mut cases = vec![(write("plane.msh", &nodes, &tris), want_plane)];
    // A hinge along the x axis: (0, 0, 0), (1, 0, 0), (0.5, 1, 0) and, across the axis, a
    // triangle bent up by `bend` degrees (its normal `bend` degrees from the first's).
    for bend in [90.0f64, 140.0, 160.0] {
        let r = bend.to_radians();
        let hinge = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 1.0, 0.0],
            [0.5, -r.cos(), r.sin()],
        ];
        let p = write(&format!("hinge{bend}.msh"), &hinge, &[[0, 1, 2], [1, 0, 3]]);
        cases.push((p, usize::from(bend > 150.0)));
    }
    for (path, want) in cases {
        let out = run_ok(dir.path(), &["info", "--json", path.to_str().unwrap()]);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["folded_pairs"], want, "{}", path.display());
        let text = run_ok(dir.path(), &["info", path.to_str().unwrap()]);
        let text = String::from_utf8_lossy(&text.stdout).to_string();
        let line = format!("folded pairs:         {want} (");
        assert_eq!(text.contains(&line), want > 0, "{text}");
    }
    // Gmsh's and the built-in meshes have none.
    for mesh in [
        "borouchaki",
        "sphere",
        data("two_squares_41_ascii.msh").to_str().unwrap(),
    ] {
        let out = run_ok(dir.path(), &["info", "--json", mesh]);
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["folded_pairs"], 0, "{mesh}");
    }
}

/// `two_squares_41_ascii.msh` with the header of its second surface's triangle block
/// (`2 2 2 22`: dimension, entity, type, count) replaced, written to `dir`; and the line.
fn two_squares_with_block_header(dir: &Path, header: &str) -> (PathBuf, usize) {
    let text = std::fs::read_to_string(data("two_squares_41_ascii.msh")).unwrap();
    let line = 1 + text.lines().position(|l| l == "2 2 2 22").unwrap();
    let p = dir.join("edited.msh");
    std::fs::write(
        &p,
        text.replacen("\n2 2 2 22\n", &format!("\n{header}\n"), 1),
    )
    .unwrap();
    (p, line)
}

/// Triangles in a block on a curve: Gmsh refuses the file ("Trying to add unsupported
/// element in curve 2"), and which surface they were meant for is unknown.
#[test]
fn bad_input_element_block_on_an_entity_of_another_dimension() {
    let dir = tempfile::tempdir().unwrap();
    let (p, line) = two_squares_with_block_header(dir.path(), "1 2 2 22");
    assert_bad(
        &p,
        &[
            &format!(":{line}:"),
            "element block 15",
            "Triangle 3 elements (type 2, dimension 2)",
            "entity of dimension 1 (tag 2)",
        ],
    );
    // A node block's dimension out of range names its header's line too.
    let text = std::fs::read_to_string(data("two_squares_41_ascii.msh")).unwrap();
    let line = 1 + text.lines().position(|l| l == "2 2 0 6").unwrap();
    let p = dir.path().join("nodes.msh");
    std::fs::write(&p, text.replacen("\n2 2 0 6\n", "\n5 2 0 6\n", 1)).unwrap();
    assert_bad(
        &p,
        &[
            &format!(":{line}:"),
            "node block",
            "dimension 5 (expected 0 to 3)",
        ],
    );
}

/// Triangles on a surface that neither `$Entities` nor a `$Nodes` block declares: refused as
/// Gmsh refuses them ("Unknown entity 7 of dimension 2"), naming the block's line; declared
/// by a node block, they are read, as Gmsh reads them. Without `$Entities` (meshio writes
/// such files for `gmsh:geometrical` tags; Gmsh refuses them) they are read on that surface,
/// and the output declares it, so Gmsh reads our file.
#[test]
fn element_block_on_an_undeclared_surface() {
    let dir = tempfile::tempdir().unwrap();
    let (p, line) = two_squares_with_block_header(dir.path(), "2 7 2 22");
    assert_bad(
        &p,
        &[
            &format!(":{line}:"),
            "element block 15 is on surface 7, which neither $Entities nor a $Nodes block declares",
        ],
    );
    let (negative, _) = two_squares_with_block_header(dir.path(), "2 -3 2 22");
    let bad = dir.path().join("negative.msh");
    std::fs::rename(&negative, &bad).unwrap();
    assert_bad(&bad, &["element block 15 is on surface -3, which neither"]);
    let (p, _) = two_squares_with_block_header(dir.path(), "2 7 2 22");
    let text = std::fs::read_to_string(&p).unwrap();
    // The same with the surface's node block on surface 7: Gmsh makes the entity.
    std::fs::write(&p, text.replacen("\n2 2 0 6\n", "\n2 7 0 6\n", 1)).unwrap();
    assert_eq!(msh::read(&p).unwrap().surfaces(), [1, 7]);
    // Without $Entities.
    let (a, b) = (
        text.find("$Entities").unwrap(),
        text.find("$EndEntities\n").unwrap(),
    );
    let text = format!("{}{}", &text[..a], &text[b + "$EndEntities\n".len()..]);
    std::fs::write(&p, text).unwrap();
    let m = msh::read(&p).unwrap();
    m.sanity_check().unwrap();
    assert_eq!(read("two_squares_41_ascii.msh").surfaces(), [1, 2]);
    assert_eq!(m.surfaces(), [1, 7]);
    let args = [
        "recombine",
        "edited.msh",
        "--algo",
        "greedy",
        "-o",
        "out.msh",
    ];
    run_ok(dir.path(), &args);
    if gmsh_available() {
        let script = r#"
import sys, gmsh
gmsh.initialize(["-noenv"])
gmsh.option.setNumber("General.Terminal", 0)
gmsh.open(sys.argv[1])
print(sorted(t for _, t in gmsh.model.getEntities(2)))
gmsh.finalize()
"#;
        assert_eq!(
            python(script, &[&dir.path().join("out.msh")]).trim(),
            "[1, 2, 7]"
        );
    }
}

#[test]
fn bad_input_non_orientable() {
    assert_bad(&bad("moebius.msh"), &["not orientable"]);
}

#[test]
fn bad_input_empty_and_no_triangles() {
    assert_bad(&bad("empty.msh"), &["empty"]);
    assert_bad(&bad("no_triangles.msh"), &["no triangles"]);
}

#[test]
fn inconsistent_orientation_is_fixed() {
    let m = msh::read(&bad("inconsistent_orientation.msh")).unwrap();
    assert_eq!(m.reoriented, 1);
    m.sanity_check().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let p = bad("inconsistent_orientation.msh");
    let out = run_in(dir.path(), &["info", "--json", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["reoriented_triangles"], 1);
}

#[test]
fn odd_triangle_count_is_valid() {
    let m = msh::read(&bad("odd_triangles.msh")).unwrap();
    m.sanity_check().unwrap();
    assert_eq!(m.num_triangles(), 3);
    let dir = tempfile::tempdir().unwrap();
    let p = bad("odd_triangles.msh");
    let out = run_in(dir.path(), &["info", "--json", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["triangles"], 3);
    assert_eq!(v["odd_components"], 1);
}

#[test]
fn bad_binary_input_names_the_byte_offset() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["two_squares_41_bin.msh", "two_squares_22_bin.msh"] {
        let bytes = std::fs::read(data(name)).unwrap();
        // Cut inside the binary node data.
        let nodes = bytes.windows(7).position(|w| w == b"$Nodes\n").unwrap();
        let p = dir.path().join(format!("cut_{name}"));
        std::fs::write(&p, &bytes[..nodes + 60]).unwrap();
        assert_bad(&p, &["byte offset", "truncated inside $Nodes"]);
        // A byte-swapped endianness marker.
        let marker = bytes
            .windows(4)
            .position(|w| w == 1i32.to_le_bytes())
            .unwrap();
        let mut swapped = bytes.clone();
        swapped[marker..marker + 4].copy_from_slice(&1i32.to_be_bytes());
        let p = dir.path().join(format!("be_{name}"));
        std::fs::write(&p, &swapped).unwrap();
        assert_bad(&p, &["byte offset", "big-endian"]);
    }
}

#[test]
fn info_reports_counts_and_eta_statistics() {
    let m = read("two_squares_41_ascii.msh");
    let table = CandidateTable::build(&m);
    let dir = tempfile::tempdir().unwrap();
    let p = data("two_squares_41_ascii.msh");
    let out = run_in(dir.path(), &["info", "--json", p.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["triangles"], 44);
    assert_eq!(v["vertices"], 31);
    assert_eq!(v["surfaces"], 2);
    assert_eq!(v["components"], 2);
    assert_eq!(v["format"], "msh 4.1 ascii");
    assert_eq!(v["boundary_edges"], m.topology.num_boundary_edges);
    assert_eq!(v["candidate_pairs"], table.len());
    let hist: u64 = v["eta"]["histogram"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_u64().unwrap())
        .sum();
    assert_eq!(hist as usize, table.len());
    let min = table.eta.iter().copied().fold(f64::INFINITY, f64::min);
    assert_eq!(v["eta"]["min"].as_f64().unwrap(), min);
    assert!(v["time_ms"]["parse"].as_f64().unwrap() >= 0.0);
    let text = run_in(dir.path(), &["info", p.to_str().unwrap()]);
    let s = String::from_utf8_lossy(&text.stdout);
    assert!(s.contains("triangles:            44"), "{s}");
    assert!(
        s.contains(&format!("candidate pairs:      {}", table.len())),
        "{s}"
    );
}

// ---------------------------------------------------------------------------------------------
// Fuzzing: seeded random mutations of valid (and bad) MSH files; the reader must never panic,
// and every mesh it accepts must pass `sanity_check` and give a candidate table.

/// Replacement numbers that stress counts, tags and coordinates.
const NUMBERS: &[&str] = &[
    "0",
    "-1",
    "1",
    "2",
    "3",
    "4",
    "7",
    "65535",
    "2147483647",
    "2147483648",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "18446744073709551616",
    "9223372036854775808",
    "-9223372036854775808",
    "1e308",
    "-1e308",
    "1e-320",
    "nan",
    "inf",
    "-0",
    "0.5",
    "$EndNodes",
    "$Elements",
];

fn token_spans(b: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < b.len() {
        while i < b.len() && b[i].is_ascii_whitespace() {
            i += 1;
        }
        let s = i;
        while i < b.len() && !b[i].is_ascii_whitespace() {
            i += 1;
        }
        if i > s {
            spans.push((s, i));
        }
    }
    spans
}

fn mutate(rng: &mut ChaCha8Rng, input: &[u8]) -> Vec<u8> {
    let mut b = input.to_vec();
    let ops = rng.random_range(1..=4);
    for _ in 0..ops {
        if b.is_empty() {
            b.push(b'$');
        }
        match rng.random_range(0..8) {
            0 => {
                // Flip a byte (or a bit).
                let i = rng.random_range(0..b.len());
                b[i] = if rng.random_bool(0.5) {
                    rng.random()
                } else {
                    b[i] ^ (1 << rng.random_range(0..8))
                };
            }
            1 => {
                let n = rng.random_range(0..b.len());
                b.truncate(n);
            }
            2 | 3 => {
                // Replace a token by a stress number.
                let spans = token_spans(&b);
                if let Some(&(s, e)) = spans.get(rng.random_range(0..spans.len().max(1))) {
                    let r = NUMBERS[rng.random_range(0..NUMBERS.len())].as_bytes();
                    b.splice(s..e, r.iter().copied());
                }
            }
            4 => {
                // Swap two tokens.
                let spans = token_spans(&b);
                if spans.len() >= 2 {
                    let (i, j) = (
                        rng.random_range(0..spans.len()),
                        rng.random_range(0..spans.len()),
                    );
                    let (lo, hi) = (spans[i.min(j)], spans[i.max(j)]);
                    if lo != hi {
                        let a = b[lo.0..lo.1].to_vec();
                        let c = b[hi.0..hi.1].to_vec();
                        b.splice(hi.0..hi.1, a);
                        b.splice(lo.0..lo.1, c);
                    }
                }
            }
            5 => {
                // Delete or duplicate a range of bytes.
                let s = rng.random_range(0..b.len());
                let e = (s + rng.random_range(1..64)).min(b.len());
                if rng.random_bool(0.5) {
                    b.drain(s..e);
                } else {
                    let piece = b[s..e].to_vec();
                    b.splice(e..e, piece);
                }
            }
            6 => {
                // Overwrite 8 bytes with an extreme binary value (counts, tags in binary files).
                let s = rng.random_range(0..b.len());
                let v: [u8; 8] = match rng.random_range(0..4) {
                    0 => u64::MAX.to_le_bytes(),
                    1 => (1u64 << 40).to_le_bytes(),
                    2 => f64::NAN.to_le_bytes(),
                    _ => rng.random(),
                };
                for (k, x) in v.iter().enumerate() {
                    if let Some(y) = b.get_mut(s + k) {
                        *y = *x;
                    }
                }
            }
            _ => {
                // Insert random bytes.
                let s = rng.random_range(0..=b.len());
                let n = rng.random_range(1..16);
                let ins: Vec<u8> = (0..n).map(|_| rng.random()).collect();
                b.splice(s..s, ins);
            }
        }
    }
    b
}

/// Reads `bytes`; accepted meshes must be sane and give a candidate table. True if accepted.
fn check_no_panic(bytes: &[u8]) -> bool {
    let read = msh::read_bytes("fuzz.msh", bytes);
    if let Ok(m) = &read {
        m.sanity_check().expect("an accepted mesh is sane");
        let table = CandidateTable::build(m);
        assert!(table.eta.iter().all(|e| (0.0..=1.0).contains(e)));
        let mut out = Vec::new();
        msh::write_to(&mut out, m, &Recombined::unrecombined(m)).unwrap();
        let back = msh::read_bytes("fuzz-written.msh", &out).expect("written mesh reads back");
        assert_eq!(back.num_triangles(), m.num_triangles());
    }
    read.is_ok()
}

fn corpus() -> Vec<(String, Vec<u8>)> {
    let mut files = Vec::new();
    for dir in ["tests/data", "tests/data/bad"] {
        let mut names: Vec<_> = std::fs::read_dir(repo_path(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "msh"))
            .collect();
        names.sort();
        for p in names {
            files.push((p.display().to_string(), std::fs::read(&p).unwrap()));
        }
    }
    files
}

/// Runs `iters` mutations; returns the inputs that panicked (saved under `save` if given) and
/// the number of mutants the reader accepted.
fn fuzz(iters: u64, seed: u64, save: Option<&Path>) -> (Vec<Vec<u8>>, u64) {
    let mut accepted = 0;
    let corpus = corpus();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut crashes = Vec::new();
    for i in 0..iters {
        let (_, input) = &corpus[rng.random_range(0..corpus.len())];
        let m = mutate(&mut rng, input);
        let r = std::panic::catch_unwind(|| check_no_panic(&m));
        accepted += u64::from(matches!(r, Ok(true)));
        if r.is_err() {
            if let Some(dir) = save {
                std::fs::create_dir_all(dir).unwrap();
                std::fs::write(dir.join(format!("crash-{seed:x}-{i}.msh")), &m).unwrap();
            }
            crashes.push(m);
        }
    }
    (crashes, accepted)
}

#[test]
fn fuzz_msh_reader_never_panics() {
    let (crashes, accepted) = fuzz(3000, SEED, None);
    assert!(
        crashes.is_empty(),
        "{} inputs panicked (seed {SEED:#x})",
        crashes.len()
    );
    assert!(
        accepted > 0,
        "no mutant was a valid mesh: the fuzzer only tests errors"
    );
}

/// The longer campaign: `QUADRECOMB_FUZZ_ITERS=2000000 cargo test --release --test it
/// fuzz_campaign -- --ignored --nocapture`; panicking inputs go to `target/fuzz-crashes/`.
#[test]
#[ignore]
fn fuzz_campaign() {
    let iters = std::env::var("QUADRECOMB_FUZZ_ITERS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(200_000);
    let seed = std::env::var("QUADRECOMB_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(SEED);
    let save = repo_path("target/fuzz-crashes");
    let t = std::time::Instant::now();
    let (crashes, accepted) = fuzz(iters, seed, Some(&save));
    eprintln!(
        "fuzz campaign: {iters} inputs, seed {seed:#x}, {:.1} s, {accepted} accepted, {} panicked",
        t.elapsed().as_secs_f64(),
        crashes.len()
    );
    assert!(
        crashes.is_empty(),
        "panicking inputs saved in {}",
        save.display()
    );
}

/// Inputs frozen from fuzzing (tests/data/fuzz/): each must be read without a panic.
#[test]
fn fuzz_regressions() {
    let dir = repo_path("tests/data/fuzz");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|e| e == "msh") {
            check_no_panic(&std::fs::read(&p).unwrap());
            n += 1;
        }
    }
    assert!(n > 0, "no regression inputs in {}", dir.display());
}

#[test]
fn bench_io_reports_each_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let a = data("two_squares_41_bin.msh");
    let b = data("mixed_22_ascii.msh");
    let out = run_in(
        dir.path(),
        &[
            "bench",
            "io",
            "--reps",
            "3",
            a.to_str().unwrap(),
            b.to_str().unwrap(),
        ],
    );
    let s = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{s}");
    let rows: Vec<&str> = s.lines().filter(|l| l.contains(".msh")).collect();
    assert_eq!(rows.len(), 2, "{s}");
    assert!(
        rows[0].contains("msh 4.1 binary") && rows[0].contains(" 44 "),
        "{s}"
    );
    assert!(
        rows[1].contains("msh 2.2 ascii") && rows[1].contains(" 22 "),
        "{s}"
    );
    let bad = run_in(
        dir.path(),
        &["bench", "io", "--reps", "0", a.to_str().unwrap()],
    );
    assert_eq!(bad.status.code(), Some(2));
    let missing = run_in(dir.path(), &["bench", "io", "no_such.msh"]);
    assert_eq!(missing.status.code(), Some(3));
}

/// A mesh of quads only (a fully recombined one, say) is not an error for `info`: it reports
/// its size and its quads' eta (`recombine` still refuses it: nothing to recombine).
#[test]
fn info_reports_a_quad_only_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("quads.msh");
    // Two unit squares side by side (eta 1) and a trapezoid above them, on another surface.
    std::fs::write(
        &p,
        "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n8\n1 0 0 0\n2 1 0 0\n3 2 0 0\n\
         4 0 1 0\n5 1 1 0\n6 2 1 0\n7 0 3 0\n8 3 3 0\n$EndNodes\n$Elements\n3\n\
         1 3 2 0 1 1 2 5 4\n2 3 2 0 1 2 3 6 5\n3 3 2 0 2 4 6 8 7\n$EndElements\n",
    )
    .unwrap();
    let out = run_in(dir.path(), &["info", "--json", p.to_str().unwrap()]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["triangles"], 0);
    assert_eq!(v["quads"], 3);
    assert_eq!(v["vertices"], 8);
    assert_eq!(v["surfaces"], 2);
    assert!(v["eta"].is_null());
    let trapezoid = quality::quad_eta([[0., 1., 0.], [2., 1., 0.], [3., 3., 0.], [0., 3., 0.]]);
    assert!(trapezoid < 0.9);
    assert_eq!(v["quad_eta"]["max"].as_f64().unwrap(), 1.0);
    assert_eq!(v["quad_eta"]["min"].as_f64().unwrap(), trapezoid);
    let text = run_in(dir.path(), &["info", p.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&text.stdout).contains("quad eta (input):"));
    let rec = run_in(
        dir.path(),
        &["recombine", p.to_str().unwrap(), "--algo", "greedy"],
    );
    assert_eq!(rec.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&rec.stderr).contains("no triangles"));
    // Its elements are checked as any mesh's: a quad on a node that does not exist is an
    // error naming the file and the element, not a quad left out.
    let text = std::fs::read_to_string(&p)
        .unwrap()
        .replace("3 3 2 0 2 4 6 8 7", "3 3 2 0 2 4 6 8 9");
    let bad = dir.path().join("bad_quads.msh");
    std::fs::write(&bad, text).unwrap();
    let out = run_in(dir.path(), &["info", bad.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(3));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bad_quads.msh") && err.contains("element 3"),
        "{err}"
    );
}

/// Meshes in any unit: a 2 x 1 grid of unit squares (four triangles) scaled by 1e-150 to
/// 1e150 loads (no false "degenerate"), and both eta backends recombine it into two perfect
/// quads (quality 2).
#[test]
fn coordinates_far_from_one_keep_their_geometry() {
    let dir = tempfile::tempdir().unwrap();
    for s in [1e-150, 1e-100, 1e-80, 1.0, 1e80, 1e100, 1e150] {
        let mut text = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n6\n");
        for (i, (x, y)) in [(0., 0.), (1., 0.), (2., 0.), (0., 1.), (1., 1.), (2., 1.)]
            .iter()
            .enumerate()
        {
            text += &format!("{} {:e} {:e} 0\n", i + 1, x * s, y * s);
        }
        text += "$EndNodes\n$Elements\n4\n1 2 2 0 1 1 2 5\n2 2 2 0 1 1 5 4\n";
        text += "3 2 2 0 1 2 3 6\n4 2 2 0 1 2 6 5\n$EndElements\n";
        let path = dir.path().join("scaled.msh");
        std::fs::write(&path, text).unwrap();
        for backend in ["exact", "cpu"] {
            let out = run_in(
                dir.path(),
                &[
                    "recombine",
                    "scaled.msh",
                    "--algo",
                    "greedy",
                    "--backend",
                    backend,
                    "--json",
                ],
            );
            let err = String::from_utf8_lossy(&out.stderr);
            assert!(out.status.success(), "scale {s:e}, {backend}: {err}");
            let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
            assert_eq!(v["quads"], 2, "scale {s:e}, {backend}");
            let q = v["quality"].as_f64().unwrap();
            assert!(
                (q - 2.0).abs() < 1e-5,
                "scale {s:e}, {backend}: quality {q}"
            );
        }
    }
}

/// `info` on a mesh of quads only (a fully recombined grid) counts its boundary edges: the
/// same as the triangle grid it came from.
#[test]
fn info_counts_the_boundary_of_a_quad_only_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let ok = |out: std::process::Output| {
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        out
    };
    ok(run_in(
        dir.path(),
        &["generate", "grid", "--triangles", "200", "-o", "g.msh"],
    ));
    ok(run_in(dir.path(), &["optimum", "g.msh", "-o", "q.msh"]));
    let json = |f: &str| -> serde_json::Value {
        serde_json::from_slice(&ok(run_in(dir.path(), &["info", f, "--json"])).stdout).unwrap()
    };
    let (tri, quad) = (json("g.msh"), json("q.msh"));
    assert_eq!(quad["triangles"], 0, "{quad}");
    assert!(tri["boundary_edges"].as_u64().unwrap() > 0);
    assert_eq!(quad["boundary_edges"], tri["boundary_edges"]);
}

/// A lone triangle (nothing to pair) gives quality 0, not the empty f64 sum's -0.
#[test]
fn nothing_recombined_prints_quality_zero() {
    let dir = tempfile::tempdir().unwrap();
    let text = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n\
                $EndNodes\n$Elements\n1\n1 2 2 0 1 1 2 3\n$EndElements\n";
    std::fs::write(dir.path().join("one.msh"), text).unwrap();
    for args in [
        &["recombine", "one.msh", "--algo", "greedy", "--json"][..],
        &["recombine", "one.msh", "--algo", "greedy"][..],
        &["optimum", "one.msh", "--json"][..],
    ] {
        let out = run_in(dir.path(), args);
        let s = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{args:?}");
        assert!(!s.contains("-0.0"), "{args:?}: {s}");
        assert!(
            s.contains("\"quality\":0.0") || s.contains("0.0000"),
            "{args:?}: {s}"
        );
    }
}

/// `info` gives a self-intersecting input quad (a bowtie: nodes of a square in the order
/// 1, 3, 2, 4) eta 0, and the square itself eta 1.
#[test]
fn info_gives_a_bowtie_quad_eta_zero() {
    let dir = tempfile::tempdir().unwrap();
    for (order, eta) in [("1 2 3 4", 1.0), ("1 3 2 4", 0.0)] {
        let text = format!(
            "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 1 1 0\n\
             4 0 1 0\n$EndNodes\n$Elements\n1\n1 3 2 0 1 {order}\n$EndElements\n"
        );
        std::fs::write(dir.path().join("q.msh"), text).unwrap();
        let out = run_in(dir.path(), &["info", "q.msh", "--json"]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["quad_eta"]["max"].as_f64(), Some(eta), "{order}: {v}");
    }
}

/// The reader's element types are Gmsh's: every number 1..300 has the same node count,
/// dimension and name as `gmsh.model.mesh.getElementProperties` gives, or is unknown to both
/// ("Unknown type of element"). For a few types Gmsh's reader knows, the function raises
/// another error (it cannot build their basis): those must be known to us too.
#[test]
fn element_types_are_gmsh_s() {
    if !gmsh_available() {
        return;
    }
    let script = r#"
import gmsh
gmsh.initialize(["-noenv"])
gmsh.option.setNumber("General.Terminal", 0)
for t in range(1, 301):
    try:
        name, dim, order, n, _, _ = gmsh.model.mesh.getElementProperties(t)
        print(f"{t}|{n}|{dim}|{name}")
    except Exception as e:
        unknown = str(e).startswith("Unknown type of element")
        print(f"{t}|{'none' if unknown else 'noprops'}")
gmsh.finalize()
"#;
    let text = python(script, &[]);
    let (mut known, mut no_props) = (0, Vec::new());
    for line in text.lines() {
        let f: Vec<&str> = line.split('|').collect();
        let t: i64 = f[0].parse().unwrap();
        let ours = msh::element_type(t);
        match f[1] {
            "none" => assert_eq!(ours, None, "type {t}: unknown to Gmsh"),
            "noprops" => {
                assert!(ours.is_some(), "type {t}: known to Gmsh's reader");
                no_props.push(t);
            }
            _ => {
                let gmsh = (f[1].parse().unwrap(), f[2].parse().unwrap(), f[3]);
                assert_eq!(ours, Some(gmsh), "type {t}");
                known += 1;
            }
        }
    }
    assert!(known > 100, "Gmsh listed {known} types");
    let mut expected = vec![67, 68, 70, 90, 91];
    expected.extend(106..=117);
    expected.push(140);
    assert_eq!(no_props, expected);
    assert_eq!(msh::element_type(140), Some((4, 3, "Trihedron 4")));
    assert_eq!(msh::element_type(68), Some((3, 2, "Triangle Border")));
}

/// The error (its text) that reading `text` as MSH gives.
fn msh_error(text: &str) -> String {
    match msh::read_bytes("t.msh", text.as_bytes()) {
        Ok(_) => panic!("read without error"),
        Err(e) => e.to_string(),
    }
}

/// `text` with line `n` (1-based) replaced by `f(line)`.
fn edit_line(text: &str, n: usize, f: impl Fn(&str) -> String) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    lines[n - 1] = f(&lines[n - 1]);
    lines.join("\n") + "\n"
}

/// Each node and element is on a line of its own (as Gmsh writes them): a value too many or
/// too few on a line is an error at that line, not a shift of every later read (a stray
/// value once made the next element's tag and dropped a triangle without a word).
#[test]
fn ascii_entries_are_read_line_by_line() {
    let v22 = std::fs::read_to_string(data("two_squares_22_ascii.msh")).unwrap();
    let v41 = std::fs::read_to_string(data("two_squares_41_ascii.msh")).unwrap();
    // Line 80 of the 2.2 file is triangle 41 ("41 2 2 0 2 ..."); line 6 is node 1.
    assert!(v22.lines().nth(79).unwrap().starts_with("41 2 "));
    let e = msh_error(&edit_line(&v22, 80, |l| format!("{l} 999")));
    assert!(
        e.contains("t.msh:80: unexpected `999` after the 3 nodes of element 41"),
        "{e}"
    );
    let e = msh_error(&edit_line(&v22, 80, |l| {
        l.rsplit_once(' ').unwrap().0.into()
    }));
    assert!(
        e.contains("t.msh:80: the line ends where node 3 of element 41 was expected"),
        "{e}"
    );
    let e = msh_error(&edit_line(&v22, 6, |l| format!("{l} 7")));
    assert!(
        e.contains("t.msh:6: unexpected `7` after the coordinates of node 1"),
        "{e}"
    );
    // A type Gmsh does not know cannot be skipped safely.
    let e = msh_error(&edit_line(&v22, 80, |l| l.replacen("41 2 ", "41 9999 ", 1)));
    assert!(
        e.contains("t.msh:80: element 41 has type 9999, which is not a Gmsh element type"),
        "{e}"
    );
    // MSH 4.1: an element line and a block header.
    let (n, line) = v41
        .lines()
        .enumerate()
        .skip_while(|(_, l)| *l != "$Elements")
        .find(|(_, l)| l.split_whitespace().count() == 4 && l.starts_with("2 "))
        .map(|(i, l)| (i + 1, l.to_string()))
        .unwrap();
    let first = v41
        .lines()
        .nth(n)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .to_string();
    let e = msh_error(&edit_line(&v41, n + 1, |l| format!("{l} 999")));
    assert!(
        e.contains(&format!(
            "t.msh:{}: unexpected `999` after the 3 nodes of element {first}",
            n + 1
        )),
        "{e}"
    );
    let e = msh_error(&edit_line(&v41, n, |_| line.replacen(" 2 ", " 9999 ", 1)));
    assert!(e.contains(&format!("t.msh:{n}: element block")), "{e}");
    assert!(
        e.contains("type 9999, which is not a Gmsh element type"),
        "{e}"
    );
}

/// An MSH 2.2 element without an elementary tag is on entity 0, as Gmsh reads it, not on
/// surface 1 (where it would join another surface's triangles).
#[test]
fn elements_without_elementary_tag_are_on_entity_0() {
    let v22 = std::fs::read_to_string(data("two_squares_22_ascii.msh")).unwrap();
    let line = v22.lines().nth(79).unwrap();
    let f: Vec<&str> = line.split(' ').collect();
    assert_eq!(f[2], "2", "{line}");
    let no_tags = format!("{} {} 0 {}", f[0], f[1], f[5..].join(" "));
    let one_tag = format!("{} {} 1 {} {}", f[0], f[1], f[3], f[5..].join(" "));
    for edited in [no_tags, one_tag] {
        let m =
            msh::read_bytes("t.msh", edit_line(&v22, 80, |_| edited.clone()).as_bytes()).unwrap();
        assert_eq!(m.surfaces(), vec![0, 1, 2], "{edited}");
        let t = m.triangle_ids.iter().position(|&id| id == 41).unwrap();
        assert_eq!(m.triangle_surface[t], 0);
    }
}

/// Two elements with one tag: an error naming the tag (Gmsh would keep the last one, and
/// every message names elements by tag), in both versions.
#[test]
fn duplicate_element_tags_are_refused() {
    let v22 = std::fs::read_to_string(data("two_squares_22_ascii.msh")).unwrap();
    let e = msh_error(&edit_line(&v22, 80, |l| l.replacen("41 ", "40 ", 1)));
    assert!(
        e.contains("t.msh: element tag 40 is given to two elements"),
        "{e}"
    );
    let v41 = std::fs::read_to_string(data("two_squares_41_ascii.msh")).unwrap();
    let last = v41.lines().position(|l| l == "$EndElements").unwrap();
    let prev = v41
        .lines()
        .nth(last - 2)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .to_string();
    let e = msh_error(&edit_line(&v41, last, |l| {
        let rest = l.split_once(' ').unwrap().1;
        format!("{prev} {rest}")
    }));
    assert!(
        e.contains(&format!("element tag {prev} is given to two elements")),
        "{e}"
    );
    // In memory too.
    let mut data = mesh::MeshData {
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ],
        triangles: vec![[0, 1, 2], [1, 3, 2]],
        ..Default::default()
    };
    data.triangle_ids = vec![7, 7];
    assert_eq!(
        Mesh::new(data).unwrap_err(),
        MeshError::DuplicateElementTag { tag: 7 }
    );
}

/// A partitioned mesh (Gmsh's `partition`): MSH 4.1 puts each partition's triangles on an
/// entity of its own; they are read back on their parent surface, so the mesh is the one
/// surface the 2.2 file (which keeps elementary tags) gives, in both encodings.
#[test]
fn partitioned_meshes_keep_their_model_surfaces() {
    let a22 = read("parts_22_ascii.msh");
    assert_eq!(a22.surfaces(), vec![1]);
    // Gmsh numbers the nodes differently in the two versions: compare triangles by their
    // corners' coordinates.
    for name in ["parts_41_ascii.msh", "parts_41_bin.msh"] {
        let m = read(name);
        assert_eq!(m.surfaces(), vec![1], "{name}");
        assert_eq!(m.topology.component_sizes.len(), 1, "{name}");
        assert_eq!(m.num_triangles(), a22.num_triangles(), "{name}");
        assert_eq!(triangle_points_set(&m), triangle_points_set(&a22), "{name}");
    }
}

/// A mesh written one file per partition with ghost cells: each file's ghost surface (in the
/// header of `$PartitionedEntities`) holds copies of the other partition's triangles. They
/// are skipped and counted as ghost cells (they were recombined onto a surface of their own),
/// so the two files' triangles are the whole mesh's, each once.
#[test]
fn ghost_cells_of_split_partition_files_are_skipped() {
    let whole = read("split_whole_41_ascii.msh");
    let mut union = BTreeSet::new();
    for name in ["split_41_ascii_1.msh", "split_41_ascii_2.msh"] {
        let file = msh::parse(&data(name), &std::fs::read(data(name)).unwrap()).unwrap();
        let ghosts: Vec<&msh::SkippedElements> = file
            .skipped
            .iter()
            .filter(|k| k.why == msh::SkipReason::GhostCell)
            .collect();
        assert!(
            ghosts.len() == 1 && ghosts[0].gmsh_type == 2 && ghosts[0].count > 0,
            "{name}: {ghosts:?}"
        );
        assert!(ghosts[0].to_string().ends_with("(ghost cells)"), "{name}");
        let m = file.into_mesh(&data(name)).unwrap();
        assert_eq!(m.surfaces(), vec![1], "{name}");
        let own = triangle_points_set(&m);
        assert!(
            own.is_disjoint(&union),
            "{name}: a triangle is in both files"
        );
        union.extend(own);
    }
    assert_eq!(union, triangle_points_set(&whole));
}

/// A partitioned 3D mesh in MSH 4.1 has, besides the partitions of the box's faces, partition
/// surfaces cut from the volume: the interface between the two partitions, with triangles
/// inside the box (they made a non-manifold error). They are skipped and counted apart; the
/// faces read as the unpartitioned mesh's.
#[test]
fn partition_interfaces_of_3d_meshes_are_skipped() {
    let whole = read("box_41_ascii.msh");
    assert_eq!(whole.num_triangles(), 84);
    for name in ["box_parts_41_ascii.msh", "box_parts_41_bin.msh"] {
        let file = msh::parse(&data(name), &std::fs::read(data(name)).unwrap()).unwrap();
        let interface: Vec<String> = file
            .skipped
            .iter()
            .filter(|k| k.why == msh::SkipReason::PartitionInterface)
            .map(ToString::to_string)
            .collect();
        assert_eq!(
            interface,
            ["12 Triangle 3 (type 2) on partition interfaces"],
            "{name}"
        );
        let m = file.into_mesh(&data(name)).unwrap();
        assert_eq!(m.surfaces(), whole.surfaces(), "{name}");
        assert_eq!(
            triangle_points_set(&m),
            triangle_points_set(&whole),
            "{name}"
        );
    }
}

/// MSH 2.2 with parametric coordinates has `$ParametricNodes` instead of `$Nodes` (it was
/// refused as "$Elements comes before any $Nodes section"): read as the 4.1 twin.
#[test]
fn msh2_parametric_nodes_are_read() {
    let b = read("param_41_ascii.msh");
    for name in ["param_22_ascii.msh", "param_22_bin.msh"] {
        let a = read(name);
        assert_eq!(a.num_triangles(), 26, "{name}");
        assert_close(&a.vertices, &b.vertices, name);
        assert_eq!(a.triangles, b.triangles, "{name}");
    }
    // A bad entity dimension is named at its node.
    let text = std::fs::read_to_string(data("param_22_ascii.msh")).unwrap();
    let n = text.lines().position(|l| l == "$ParametricNodes").unwrap() + 3;
    let bad = edit_line(&text, n, |l| {
        let mut f: Vec<&str> = l.split(' ').collect();
        f[4] = "7";
        f.join(" ")
    });
    let e = msh_error(&bad);
    assert!(
        e.contains(&format!("t.msh:{n}: node 1 is on an entity of dimension 7")),
        "{e}"
    );
    // In a 4.1 file the section is out of place.
    let e = msh_error(&text.replace("$MeshFormat\n2.2", "$MeshFormat\n4.1"));
    assert!(
        e.contains("a $ParametricNodes section in an MSH 4.1 file"),
        "{e}"
    );
}

/// Lone carriage returns as line ends (classic Mac OS) are refused with that reason, not a
/// misleading "the line holds more values"; CRLF is read (crlf_and_byte_order_mark_are_accepted).
#[test]
fn lone_carriage_returns_are_named() {
    let text = std::fs::read_to_string(data("two_squares_41_ascii.msh")).unwrap();
    let e = msh_error(&text.replace('\n', "\r"));
    assert!(
        e.contains("t.msh:1: the lines end with a lone carriage return"),
        "{e}"
    );
}

/// Second-order elements are skipped; a mesh of nothing else says what it holds and how to
/// make it first order, and `info` lists skipped elements by type.
#[test]
fn second_order_meshes_say_what_was_skipped() {
    let e = msh::read(&data("order2_41_ascii.msh"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the mesh has no 3-node triangles to recombine"),
        "{e}"
    );
    assert!(e.contains("Triangle 6 (type 9)"), "{e}");
    assert!(e.contains("setOrder(1)"), "{e}");
    // Surface elements that are not of higher order get no such advice.
    let polygons = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n$EndNodes\n$Elements\n2\n1 34 2 0 1 1 2 3 4\n2 86 2 0 1 1\n$EndElements\n";
    let e = msh_error(polygons);
    assert!(
        e.contains("its surface elements are 1 Quadrilateral 1 (type 86), 1 Polygon (type 34)")
            || e.contains(
                "its surface elements are 1 Polygon (type 34), 1 Quadrilateral 1 (type 86)"
            ),
        "{e}"
    );
    assert!(!e.contains("setOrder"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(
        dir.path(),
        &["info", data("two_squares_41_ascii.msh").to_str().unwrap()],
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("(") && text.contains("Line 2 (type 1)") && text.contains("Point (type 15)"),
        "{text}"
    );
}

/// The library's writers keep an existing file when they fail (a quad naming a vertex past
/// the end): they truncated it to 0 bytes first (a library user's review; the CLI wrote
/// through a temporary of its own).
#[test]
fn a_failed_library_write_leaves_the_existing_file() {
    let tmp = tempfile::tempdir().unwrap();
    let mesh = mesh::load("sphere").unwrap();
    let good = Recombined::unrecombined(&mesh);
    let bad = Recombined {
        quads: vec![[0, 1, 2, u32::MAX - 1]],
        quad_surface: vec![mesh.triangle_surface[0]],
        quad_eta: vec![0.5],
        leftover: Vec::new(),
    };
    for name in ["keep.msh", "keep.vtu"] {
        let path = tmp.path().join(name);
        let write = |rec: &Recombined| {
            if name.ends_with(".msh") {
                msh::write(&path, &mesh, rec)
            } else {
                vtu::write(&path, &mesh, rec)
            }
        };
        write(&good).unwrap();
        let before = std::fs::read(&path).unwrap();
        assert!(!before.is_empty());
        let err = write(&bad).expect_err("a quad past the vertices is an error");
        assert!(err.to_string().contains(name), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), before, "{name} changed");
        let left: Vec<_> = std::fs::read_dir(tmp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .filter(|n| n.to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(left.is_empty(), "temporaries left: {left:?}");
    }
}

/// `info` on a file of quads only checks them as `Mesh::new` does: a quad of four collinear
/// nodes is refused naming it (it was read and counted as a quad of eta 0; a second reading
/// of the check, which first ran only where triangles were recombined).
#[test]
fn info_refuses_a_flat_quad_in_a_file_of_quads_only() {
    let tmp = tempfile::tempdir().unwrap();
    let file = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 2 0 0\n\
                4 3 0 0\n$EndNodes\n$Elements\n1\n7 3 2 1 1 1 2 3 4\n$EndElements\n";
    std::fs::write(tmp.path().join("flat.msh"), file).unwrap();
    let o = run_in(tmp.path(), &["info", "flat.msh"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(3), "{err}");
    assert!(err.contains("flat.msh: quad 7 is degenerate"), "{err}");
}

/// `recombine` and `optimum` on a mesh with input quads say how many they keep: their figures
/// are of the triangles alone, and read as the whole mesh's without the line.
#[test]
fn input_quads_are_counted_in_the_text_output() {
    let tmp = tempfile::tempdir().unwrap();
    let input = repo_path("tests/data/mixed_41_ascii.msh");
    let input = input.to_str().unwrap();
    let line = "input quads     11 (kept as they are; the figures below are of the triangles)";
    for args in [
        &["recombine", input, "--algo", "greedy", "--no-optimum"][..],
        &["optimum", input],
    ] {
        let out = String::from_utf8_lossy(&run_ok(tmp.path(), args).stdout).into_owned();
        assert!(out.contains(line), "{args:?}: {out}");
    }
    let out = run_ok(tmp.path(), &["optimum", "sphere"]).stdout;
    assert!(!String::from_utf8_lossy(&out).contains("input quads"));
}
