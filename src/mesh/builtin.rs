//! Built-in benchmark meshes, embedded in the binary so that they work from any directory and a
//! fresh clone: `meshes/*.msh` (MSH 4.1 binary), made by `scripts/make_meshes.py` with Gmsh
//! 4.15.2. Counts and hashes are in `meshes/README.md`.

/// Names of the built-in meshes.
pub const NAMES: &[&str] = &["borouchaki", "sphere"];

/// The paper's planar test domain: the unit square minus the disk of radius 0.15 at
/// (0.75, 0.75), 34,456 triangles.
const BOROUCHAKI: &[u8] = include_bytes!("../../meshes/borouchaki.msh");
/// The unit sphere, 2,104 triangles.
const SPHERE: &[u8] = include_bytes!("../../meshes/sphere.msh");

/// The file content of a built-in mesh, by name; `None` if `name` is not one of [`NAMES`].
pub fn bytes(name: &str) -> Option<&'static [u8]> {
    match name {
        "borouchaki" => Some(BOROUCHAKI),
        "sphere" => Some(SPHERE),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_has_msh_4_1_bytes() {
        for name in NAMES {
            let b = bytes(name).unwrap_or_else(|| panic!("no bytes for {name}"));
            assert!(
                b.starts_with(b"$MeshFormat\n4.1 1 8\n"),
                "{name} is not MSH 4.1 binary"
            );
            assert!(b.ends_with(b"$EndElements\n"), "{name} is truncated");
        }
    }

    #[test]
    fn unknown_name_has_no_bytes() {
        assert!(bytes("square").is_none());
        assert!(bytes("").is_none());
    }
}
