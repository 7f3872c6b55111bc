//! Synthetic candidate sets of any size for the benchmark, built straight into a [`Batch`]
//! without the mesh and topology machinery: the candidates of a jittered right-triangle grid
//! (row-major vertices, candidates cell by cell, so neighbouring candidates share vertices as
//! in a real mesh's table).

use super::layout::Batch;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Vertices and candidate quads `[s0, o1, s1, o0]` of an `n` x `n` grid of unit cells,
/// each split along its (0,0)-(1,1) diagonal, with vertices jittered by up to `jitter` cell
/// sizes (below 0.25 keeps every triangle valid). About `3 n^2` candidates.
pub fn jittered_grid(n: usize, jitter: f64, seed: u64) -> (Vec<[f64; 3]>, Vec<[u32; 4]>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let w = n + 1;
    let mut vertices = Vec::with_capacity(w * w);
    for j in 0..w {
        for i in 0..w {
            let dx = jitter * (2.0 * rng.random::<f64>() - 1.0);
            let dy = jitter * (2.0 * rng.random::<f64>() - 1.0);
            vertices.push([i as f64 + dx, j as f64 + dy, 0.0]);
        }
    }
    let id = |i: usize, j: usize| (j * w + i) as u32;
    let mut quads = Vec::with_capacity(3 * n * n);
    for j in 0..n {
        for i in 0..n {
            let (p00, p10, p11, p01) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            // Lower (p00, p10, p11) and upper (p00, p11, p01) triangles across the diagonal.
            quads.push([p00, p10, p11, p01]);
            // Upper triangle with the next cell's lower one, across the edge p01-p11.
            if j + 1 < n {
                quads.push([p11, id(i + 1, j + 2), p01, p00]);
            }
            // Lower triangle with the right cell's upper one, across the edge p10-p11.
            if i + 1 < n {
                quads.push([p10, id(i + 2, j + 1), p11, p00]);
            }
        }
    }
    (vertices, quads)
}

/// A batch of about `candidates` grid candidates (one mesh), seeded.
pub fn grid_batch(candidates: usize, seed: u64) -> Batch {
    let n = ((candidates as f64 / 3.0).sqrt().ceil() as usize).max(1);
    let (vertices, quads) = jittered_grid(n, 0.2, seed);
    let mut batch = Batch::new();
    batch
        .push(&vertices, &quads)
        .expect("grid indices are in range");
    batch
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Mesh, MeshData};
    use crate::quality::CandidateTable;

    #[test]
    fn grid_candidates_are_the_mesh_candidate_table() {
        let (vertices, quads) = jittered_grid(7, 0.2, 1);
        let mut triangles = Vec::new();
        let w = 8u32;
        for j in 0..7u32 {
            for i in 0..7u32 {
                let p = |a: u32, b: u32| (j + b) * w + i + a;
                triangles.push([p(0, 0), p(1, 0), p(1, 1)]);
                triangles.push([p(0, 0), p(1, 1), p(0, 1)]);
            }
        }
        let mesh = Mesh::new(MeshData {
            vertices: vertices.clone(),
            triangles,
            ..MeshData::default()
        })
        .unwrap();
        let table = CandidateTable::build(&mesh);
        // Same set of quads up to the choice of diagonal direction and start.
        let canon = |q: [u32; 4]| {
            let mut d = [
                q[0].min(q[2]),
                q[0].max(q[2]),
                q[1].min(q[3]),
                q[1].max(q[3]),
            ];
            d[2..].sort();
            d
        };
        let mut a: Vec<_> = quads.iter().map(|&q| canon(q)).collect();
        let mut b: Vec<_> = table.quads.iter().map(|&q| canon(q)).collect();
        a.sort();
        b.sort();
        assert_eq!(a, b);
        // And the same eta: the quads are the same cycles with the same diagonal.
        let reference: std::collections::HashMap<_, _> = table
            .quads
            .iter()
            .zip(&table.eta)
            .map(|(&q, &e)| (canon(q), e))
            .collect();
        for q in &quads {
            let e = crate::quality::quad_eta(q.map(|v| vertices[v as usize]));
            assert!((e - reference[&canon(*q)]).abs() < 1e-12);
            assert!(e > 0.0, "jittered grid quads are convex");
        }
    }
}
