//! Spatial order for loaded meshes: triangles sorted along a Morton (Z-order) curve of their
//! centroids, vertices numbered by first use. Mesh generators write elements in whatever
//! order they made them (Gmsh's `borouchaki`: neighbouring triangles are on average 5,000
//! indices apart), which scatters every per-triangle and per-candidate array the searches
//! touch around one quad over as many cache lines; in this order neighbours are mostly
//! adjacent in memory. Node and element tags are kept, so written files carry the input's
//! tags, and a file's model (node classification, point and line elements) follows the new
//! vertex order.

use super::MeshData;

/// Reorders `data` in place (see the module docs). Deterministic: ties keep the input order.
pub fn spatial(data: &mut MeshData) {
    let (nv, nt) = (data.vertices.len(), data.triangles.len());
    if nt < 2 {
        return;
    }
    // Implicit tags are positions: fix them before anything moves.
    data.materialise_defaults();
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for v in &data.vertices {
        for k in 0..3 {
            if v[k].is_finite() {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
    }
    let key = |tri: &[u32; 3]| -> u64 {
        let mut z = 0u64;
        for k in 0..3 {
            let c: f64 = tri
                .iter()
                .map(|&v| data.vertices.get(v as usize).map_or(0.0, |p| p[k]))
                .sum::<f64>()
                / 3.0;
            let span = hi[k] - lo[k];
            let q = if span > 0.0 && c.is_finite() {
                (((c - lo[k]) / span).clamp(0.0, 1.0) * ((1u64 << 21) - 1) as f64) as u64
            } else {
                0
            };
            for b in 0..21 {
                z |= ((q >> b) & 1) << (3 * b + k);
            }
        }
        z
    };
    let mut order: Vec<u32> = (0..nt as u32).collect();
    let keys: Vec<u64> = data.triangles.iter().map(key).collect();
    order.sort_by_key(|&t| keys[t as usize]);
    drop(keys);
    // A gather into a new array, the old one dropped before the next: one array's copy at a
    // time. (Permuting in place along the cycles needs no copy, but its chained random
    // reads made the spatial order three times slower on a 10^6-triangle strip, and the
    // copy is not the load's peak: the topology's build is.)
    fn permute<T: Copy>(v: &mut Vec<T>, order: &[u32]) {
        let old = std::mem::take(v);
        *v = order.iter().map(|&t| old[t as usize]).collect();
    }
    permute(&mut data.triangles, &order);
    permute(&mut data.triangle_ids, &order);
    permute(&mut data.triangle_surface, &order);
    drop(order);
    // Vertices by first use (triangles, then quads, then unused ones); out-of-range indices
    // are left for validation to report.
    let mut new_index = vec![u32::MAX; nv];
    let mut from = Vec::with_capacity(nv);
    let mut visit = |v: &mut u32| {
        if let Some(slot) = new_index.get_mut(*v as usize) {
            if *slot == u32::MAX {
                *slot = from.len() as u32;
                from.push(*v);
            }
            *v = *slot;
        }
    };
    for tri in &mut data.triangles {
        tri.iter_mut().for_each(&mut visit);
    }
    for quad in &mut data.quads {
        quad.iter_mut().for_each(&mut visit);
    }
    for v in 0..nv as u32 {
        if new_index[v as usize] == u32::MAX {
            new_index[v as usize] = from.len() as u32;
            from.push(v);
        }
    }
    data.vertices = from.iter().map(|&v| data.vertices[v as usize]).collect();
    data.vertex_ids = from.iter().map(|&v| data.vertex_ids[v as usize]).collect();
    if let Some(model) = &mut data.model {
        model.renumber(&from, &new_index);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    /// Same elements (by tags, with the same node tags and coordinates), neighbours close.
    #[test]
    fn reorders_without_changing_the_mesh() {
        let mesh = generate::grid(generate::GridSpec {
            triangles: 200,
            seed: 7,
            ..Default::default()
        });
        let mut data = MeshData {
            vertices: mesh.vertices.clone(),
            triangles: mesh.triangles.clone(),
            ..MeshData::default()
        };
        // Scramble the input so there is something to sort.
        data.triangles.reverse();
        let before = data.clone();
        spatial(&mut data);
        /// An element: its tag and its nodes' tags and coordinate bits.
        type Element = (u64, Vec<(u64, [u64; 3])>);
        let describe = |d: &MeshData, ids: bool| -> Vec<Element> {
            let mut out: Vec<_> = d
                .triangles
                .iter()
                .enumerate()
                .map(|(i, tri)| {
                    let tag = if ids { d.triangle_ids[i] } else { i as u64 + 1 };
                    let nodes = tri
                        .iter()
                        .map(|&v| {
                            let tag = if ids {
                                d.vertex_ids[v as usize]
                            } else {
                                v as u64 + 1
                            };
                            (tag, d.vertices[v as usize].map(f64::to_bits))
                        })
                        .collect();
                    (tag, nodes)
                })
                .collect();
            out.sort();
            out
        };
        assert_eq!(describe(&data, true), describe(&before, false));
        assert!(crate::mesh::Mesh::new(data.clone()).is_ok());
        // Consecutive triangles share a vertex far more often than in reverse input order.
        let shared = |d: &MeshData| {
            d.triangles
                .windows(2)
                .filter(|w| w[0].iter().any(|v| w[1].contains(v)))
                .count()
        };
        let n = data.triangles.len();
        assert!(shared(&data) * 10 >= n * 6, "{} of {n}", shared(&data));
    }
}
