//! Jittered equilateral triangle lattices: rows of near-equilateral triangles, like the
//! interior of a frontal mesh, on which the exact optimum's growth is measured (`bench
//! optimum`, `bench finish`, `generate lattice`). Deterministic: a lattice depends only on
//! its size and seed (a ChaCha8 stream).

use crate::mesh::{Mesh, MeshData};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The `(nx, ny)` cells (two triangles each) of the lattice of about `n` triangles.
pub fn lattice_cells(n: usize) -> (usize, usize) {
    let cells = (n / 2).max(1);
    let nx = ((cells as f64).sqrt().round() as usize).max(1);
    (nx, cells.div_ceil(nx))
}

/// A jittered equilateral triangle lattice of about `n` triangles (`2 * nx * ny` of
/// [`lattice_cells`]; rows offset by half a step, interior vertices moved by up to 0.15 of an
/// edge in each axis, boundary vertices fixed), seeded.
pub fn lattice(n: usize, seed: u64) -> Mesh {
    let (nx, ny) = lattice_cells(n);
    let h = 3f64.sqrt() / 2.0;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut vertices = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            let interior = i > 0 && i < nx && j > 0 && j < ny;
            let (dx, dy) = if interior {
                (rng.random_range(-0.15..0.15), rng.random_range(-0.15..0.15))
            } else {
                (0.0, 0.0)
            };
            let shift = if j % 2 == 1 { 0.5 } else { 0.0 };
            vertices.push([i as f64 + shift + dx, j as f64 * h + dy, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    let mut triangles = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            if j % 2 == 0 {
                triangles.push([id(i, j), id(i + 1, j), id(i, j + 1)]);
                triangles.push([id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
            } else {
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            }
        }
    }
    Mesh::new(MeshData {
        vertices,
        triangles,
        ..MeshData::default()
    })
    .expect("a jittered lattice is a valid mesh")
}
