//! Built-in benchmark meshes, embedded in the binary so that they work from any directory.
//! (Filled in by the benchmark-meshes work: `meshes/*.msh`, made by `scripts/make_meshes.py`.)

/// Names of the built-in meshes.
pub const NAMES: &[&str] = &[];

/// The file content of a built-in mesh, by name.
pub fn bytes(_name: &str) -> Option<&'static [u8]> {
    None
}
