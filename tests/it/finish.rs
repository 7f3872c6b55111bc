//! Finishing (`src/finish/`, `recombine --finish`, `sweep --finish`) and `generate lattice`.

use crate::util::{gmsh_available, python, run_in};
use quadrecomb::internals::mesh::Mesh;
use quadrecomb::internals::mesh::generate::lattice;

/// `generate lattice` writes the lattice `bench optimum` times: same nodes, same triangles,
/// read back by the library and by Gmsh with the same counts; bad sizes are usage errors.
#[test]
fn cli_generate_lattice_writes_the_benchmark_lattice() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(
        dir.path(),
        &[
            "generate",
            "lattice",
            "--triangles",
            "1000",
            "--seed",
            "3",
            "-o",
            "l.msh",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let want = lattice(1000, 3);
    assert_eq!(want.num_triangles(), 2 * 22 * 23);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(&format!("{} triangles", want.num_triangles())),
        "{stdout}"
    );
    let back: Mesh = quadrecomb::internals::mesh::msh::read(&dir.path().join("l.msh")).unwrap();
    assert_eq!(
        back.vertices, want.vertices,
        "coordinates round-trip exactly"
    );
    assert_eq!(back.triangles.len(), want.triangles.len());
    let key = |m: &Mesh| {
        let mut v: Vec<[u32; 3]> = m
            .triangles
            .iter()
            .map(|t| {
                let mut k = *t;
                k.sort_unstable();
                k
            })
            .collect();
        v.sort_unstable();
        v
    };
    assert_eq!(key(&back), key(&want));
    // A different seed moves the interior vertices only.
    let other = lattice(1000, 4);
    assert_ne!(other.vertices, want.vertices);
    assert_eq!(key(&other), key(&want));
    for bad in ["0", "1"] {
        let out = run_in(
            dir.path(),
            &["generate", "lattice", "--triangles", bad, "-o", "x.msh"],
        );
        assert_eq!(out.status.code(), Some(2), "--triangles {bad}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("--triangles"));
    }
    if gmsh_available() {
        let script = "import gmsh, sys\n\
            gmsh.initialize(readConfigFiles=False)\n\
            gmsh.option.setNumber('General.Terminal', 0)\n\
            gmsh.open(sys.argv[1])\n\
            types, tags, _ = gmsh.model.mesh.getElements(2)\n\
            print(len(gmsh.model.mesh.getNodes()[0]), sum(len(t) for t in tags))\n";
        let line = python(script, &[&dir.path().join("l.msh")]);
        assert_eq!(
            line.trim(),
            format!("{} {}", want.vertices.len(), want.num_triangles())
        );
    }
}
