//! The benchmark suite (issue 24): meshes of several generators, size fields, surfaces and
//! topologies, named `suite:NAME` wherever a mesh is taken. Twelve are Gmsh 4.15.2 files made by
//! `scripts/make_suite.py` and embedded (`meshes/suite/*.msh`), two are the built-in meshes,
//! and one (`grid-1m`) is generated at first use, in memory, exactly as `quadrecomb generate`
//! would write it. [`SUITES`] names subsets (`default`, `small`, `full`).

use super::generate::{GridSpec, grid};
use super::{Recombined, builtin, msh};
use std::borrow::Cow;

/// What names a suite member on the command line: `suite:torus`.
pub const PREFIX: &str = "suite:";

/// Where a member's mesh comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Origin {
    /// A file of `meshes/suite/`, embedded in the binary.
    File(&'static [u8]),
    /// A built-in mesh ([`builtin::NAMES`]).
    Builtin(&'static str),
    /// A procedural grid, generated at first use (MSH 4.1 ASCII in memory, as
    /// `quadrecomb generate grid` writes it).
    Grid(GridSpec),
}

/// One mesh of the suite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Member {
    /// The name (`suite:` + name on the command line; the name alone in records).
    pub name: &'static str,
    /// Triangles (checked by a test).
    pub triangles: usize,
    /// Components of the dual graph with an odd number of triangles (checked by a test).
    pub odd_components: usize,
    /// The family it belongs to (one word: which axis of the suite it varies).
    pub family: &'static str,
    /// What it tests, in a line.
    pub tests: &'static str,
    /// Where the mesh comes from.
    pub origin: Origin,
}

macro_rules! file {
    ($name:literal) => {
        Origin::File(include_bytes!(concat!(
            "../../meshes/suite/",
            $name,
            ".msh"
        )))
    };
}

/// The generated member: `quadrecomb generate grid --triangles 1000000 --seed 24`.
pub const GRID_1M: GridSpec = GridSpec {
    triangles: 1_000_000,
    seed: 24,
    jitter: 0.2,
    holes: false,
    surfaces: 1,
    drop_triangles: 0,
};

/// Every member, smallest families first (the order of `suite list` and of the suites).
pub const MEMBERS: &[Member] = &[
    Member {
        name: "plate-delquad",
        triangles: 4822,
        odd_components: 0,
        family: "generator",
        tests: "the paper's domain and mesher (Frontal-Delaunay for quads), uniform size 0.02",
        origin: file!("plate-delquad"),
    },
    Member {
        name: "plate-delaunay",
        triangles: 6178,
        odd_components: 0,
        family: "generator",
        tests: "the same domain and size meshed by plain Delaunay",
        origin: file!("plate-delaunay"),
    },
    Member {
        name: "plate-frontal",
        triangles: 5538,
        odd_components: 0,
        family: "generator",
        tests: "the same domain and size meshed by Frontal-Delaunay",
        origin: file!("plate-frontal"),
    },
    Member {
        name: "plate-meshadapt",
        triangles: 5896,
        odd_components: 0,
        family: "generator",
        tests: "the same domain and size meshed by MeshAdapt",
        origin: file!("plate-meshadapt"),
    },
    Member {
        name: "graded-corner",
        triangles: 3394,
        odd_components: 0,
        family: "size-field",
        tests: "strong grading: size 0.0004 at a corner growing to 0.05 (ratio 125)",
        origin: file!("graded-corner"),
    },
    Member {
        name: "anisotropic-stretched",
        triangles: 5830,
        odd_components: 0,
        family: "size-field",
        tests: "anisotropy: every triangle stretched 25:1 along x",
        origin: file!("anisotropic-stretched"),
    },
    Member {
        name: "sphere",
        triangles: 2104,
        odd_components: 0,
        family: "curved",
        tests: "the paper's closed curved surface (built-in)",
        origin: Origin::Builtin("sphere"),
    },
    Member {
        name: "torus",
        triangles: 5878,
        odd_components: 0,
        family: "curved",
        tests: "a closed curved surface of genus 1",
        origin: file!("torus"),
    },
    Member {
        name: "capped-cylinder",
        triangles: 5308,
        odd_components: 2,
        family: "curved",
        tests: "a cylinder and its two caps: three surfaces meeting at sharp edges",
        origin: file!("capped-cylinder"),
    },
    Member {
        name: "vase-revolution",
        triangles: 7465,
        odd_components: 1,
        family: "curved",
        tests: "a surface of revolution of a B-spline: curvature of both signs, open ends",
        origin: file!("vase-revolution"),
    },
    Member {
        name: "materials",
        triangles: 7668,
        odd_components: 2,
        family: "surfaces",
        tests: "four surfaces in three named physical groups (matrix, inclusions, insert)",
        origin: file!("materials"),
    },
    Member {
        name: "many-holes",
        triangles: 8975,
        odd_components: 1,
        family: "topology",
        tests: "18 holes: many boundaries and narrow passages between them",
        origin: file!("many-holes"),
    },
    Member {
        name: "odd-pieces",
        triangles: 3791,
        odd_components: 5,
        family: "topology",
        tests: "seven disjoint pieces, five with an odd number of triangles",
        origin: file!("odd-pieces"),
    },
    Member {
        name: "borouchaki",
        triangles: 34456,
        odd_components: 0,
        family: "size",
        tests: "the paper's graded mesh (built-in), the largest Gmsh member",
        origin: Origin::Builtin("borouchaki"),
    },
    Member {
        name: "grid-1m",
        triangles: 1_000_000,
        odd_components: 0,
        family: "size",
        tests: "10^6 triangles, generated at first use (generate grid --triangles 1000000 --seed 24)",
        origin: Origin::Grid(GRID_1M),
    },
];

/// Named subsets: name, members, what it is for.
pub const SUITES: &[(&str, &[&str], &str)] = &[
    (
        "default",
        &[
            "plate-delquad",
            "plate-delaunay",
            "plate-frontal",
            "plate-meshadapt",
            "graded-corner",
            "anisotropic-stretched",
            "sphere",
            "torus",
            "capped-cylinder",
            "vase-revolution",
            "materials",
            "many-holes",
            "odd-pieces",
            "borouchaki",
        ],
        "every member but grid-1m (whose runs take about 2 s each: minutes more for the sweep)",
    ),
    (
        "small",
        &["graded-corner", "sphere", "odd-pieces"],
        "three small meshes of three families, for quick checks and tests",
    ),
    ("full", &[], "every member, grid-1m included"),
];

/// The member named `name` (without the prefix).
pub fn member(name: &str) -> Option<&'static Member> {
    MEMBERS.iter().find(|m| m.name == name)
}

/// The names of every member, comma-separated (for messages).
pub fn member_names() -> String {
    MEMBERS
        .iter()
        .map(|m| m.name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// The names of every suite, comma-separated (for messages).
pub fn suite_names() -> String {
    SUITES.iter().map(|s| s.0).collect::<Vec<_>>().join(", ")
}

/// The members of the suite `name`, in [`MEMBERS`] order; `None` for an unknown suite.
pub fn suite(name: &str) -> Option<Vec<&'static Member>> {
    let (_, names, _) = SUITES.iter().find(|s| s.0 == name)?;
    Some(if names.is_empty() {
        MEMBERS.iter().collect()
    } else {
        MEMBERS.iter().filter(|m| names.contains(&m.name)).collect()
    })
}

/// The mesh spec of a member (what `--mesh` takes): `suite:NAME`.
pub fn spec(member: &Member) -> String {
    format!("{PREFIX}{}", member.name)
}

/// The member a spec names, if it begins with [`PREFIX`]: `Some(Err(name))` for an unknown
/// name.
pub fn parse_spec(spec: &str) -> Option<Result<&'static Member, &str>> {
    let name = spec.strip_prefix(PREFIX)?;
    Some(member(name).ok_or(name))
}

impl Member {
    /// The mesh file's bytes: embedded, built-in, or generated now (MSH 4.1 ASCII, the bytes
    /// `quadrecomb generate` writes for the same grid).
    pub fn bytes(&self) -> Cow<'static, [u8]> {
        match self.origin {
            Origin::File(b) => Cow::Borrowed(b),
            Origin::Builtin(name) => {
                Cow::Borrowed(builtin::bytes(name).expect("suite builtins exist"))
            }
            Origin::Grid(spec) => {
                let mesh = grid(spec);
                let mut out = Vec::new();
                msh::write_to(&mut out, &mesh, &Recombined::unrecombined(&mesh))
                    .expect("writing to memory cannot fail");
                Cow::Owned(out)
            }
        }
    }

    /// Where it comes from, in words (for `suite list`).
    pub fn origin_text(&self) -> String {
        match self.origin {
            Origin::File(_) => format!("meshes/suite/{}.msh", self.name),
            Origin::Builtin(name) => format!("built-in {name} (meshes/{name}.msh)"),
            Origin::Grid(s) => format!(
                "generated: generate grid --triangles {} --seed {}",
                s.triangles, s.seed
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_suites_name_members() {
        for (i, m) in MEMBERS.iter().enumerate() {
            assert!(MEMBERS[..i].iter().all(|o| o.name != m.name), "{}", m.name);
            assert!(!m.name.contains(':') && !m.name.is_empty());
        }
        for (name, members, _) in SUITES {
            for m in *members {
                assert!(member(m).is_some(), "suite {name} names unknown {m}");
            }
            assert!(!suite(name).unwrap().is_empty());
        }
        assert_eq!(suite("full").unwrap().len(), MEMBERS.len());
        assert!(suite("nope").is_none());
    }

    #[test]
    fn specs_parse_back() {
        let m = member("torus").unwrap();
        assert_eq!(parse_spec(&spec(m)), Some(Ok(m)));
        assert_eq!(parse_spec("suite:nope"), Some(Err("nope")));
        assert_eq!(parse_spec("torus"), None);
    }

    #[test]
    fn embedded_files_are_msh_4_1_binary() {
        for m in MEMBERS {
            if let Origin::File(b) = m.origin {
                assert!(b.starts_with(b"$MeshFormat\n4.1 1 8\n"), "{}", m.name);
            }
        }
    }
}
