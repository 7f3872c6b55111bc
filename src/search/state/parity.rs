//! A part's parity without enumerating it. On a surface of genus 0, every edge gets a weight
//! `w` in {0, 1} such that the weights of each triangle's three sides sum to `c(t)` (mod 2):
//! 1 for a triangle of an even initial polder ("active"), 0 for the others, and the weight
//! of every boundary edge is 0. Then for any set `R` of triangles, `|R ∩ active|` has the
//! parity of the weights summed over the edges with exactly one side in `R` (interior edges
//! count twice), and a closed path of edges `C` on the surface sums to the parity of the
//! active triangles on either side of it (genus 0: `C` bounds; the weights around each hole
//! sum to 0). The dead-component union–find keeps, per vertex, the parity of the weights
//! along a path of dead edges to its root ([`State::find_par`]); a quad that touches one
//! dead component at `k >= 2` arcs closes such a path, between two consecutive arcs, into a
//! curve around the part on that run of its sides, whose parity is then two lookups and the
//! weights of the quad's sides (`check_slow`, `run_parities`). See docs/search.md "Parity by
//! the boundary".
//!
//! [`State::find_par`]: super::State::find_par

use crate::mesh::{Mesh, NONE};

/// The weights of every triangle's sides (bit `i`: side `i`, the edge from corner `i` to
/// corner `i + 1`; both triangles of an edge agree), or `None` when the mesh is not one the
/// argument covers: input quads, a surface boundary or a non-manifold edge inside it (a
/// triangle side without a neighbour that is no boundary edge), a vertex whose triangles are
/// not one fan, or a component of genus above 0 (Euler's formula with its boundary loops).
/// `active(t)`: whether `t` counts (its initial polder is even); `count[v]` and `first[v]`:
/// the number of triangles at vertex `v` and one of them.
pub(super) fn edge_weights(
    mesh: &Mesh,
    count: &[u32],
    first: &[u32],
    active: impl Fn(u32) -> bool,
) -> Option<Vec<u8>> {
    let tris = &mesh.triangles;
    let nb = &mesh.topology.neighbours;
    let nt = tris.len();
    if !mesh.quads.is_empty() || nt == 0 {
        return None;
    }
    let open = nb.iter().flatten().filter(|&&u| u == NONE).count();
    if open != mesh.topology.num_boundary_edges {
        return None;
    }
    if !fans_are_disks(mesh, count, first) || !genus_zero(mesh, count) {
        return None;
    }
    // A spanning forest of the dual graph, breadth first; the boundary edges and the edges
    // off the forest weigh 0, and each forest edge is set from the leaves up so that the
    // triangle below it sums to its `c`. A component's root then sums right by itself: the
    // sum over its triangles counts every interior edge twice, so it is the parity of the
    // active triangles (even: a sum of even polders), which the others already have.
    const UNSEEN: u8 = 4;
    const ROOT: u8 = 3;
    let mut up = vec![UNSEEN; nt];
    let mut order: Vec<u32> = Vec::with_capacity(nt);
    for s in 0..nt {
        if up[s] != UNSEEN {
            continue;
        }
        up[s] = ROOT;
        let mut head = order.len();
        order.push(s as u32);
        while head < order.len() {
            let t = order[head] as usize;
            head += 1;
            for i in 0..3 {
                let u = nb[t][i];
                if u != NONE && up[u as usize] == UNSEEN {
                    up[u as usize] = side_of(tris[u as usize], tris[t][i], tris[t][(i + 1) % 3])?;
                    order.push(u);
                }
            }
        }
    }
    let mut w = vec![0u8; nt];
    for &t in order.iter().rev() {
        let t = t as usize;
        let want = active(t as u32) as u8;
        if up[t] == ROOT {
            if (w[t].count_ones() as u8 & 1) != want {
                return None;
            }
            continue;
        }
        let s = up[t] as usize;
        let have = (w[t] & !(1 << s)).count_ones() as u8 & 1;
        if have != want {
            w[t] |= 1 << s;
            let u = nb[t][s] as usize;
            let j = side_of(tris[u], tris[t][s], tris[t][(s + 1) % 3])?;
            w[u] |= 1 << j;
        }
    }
    Some(w)
}

/// The side of triangle `tri` joining vertices `a` and `b`.
fn side_of(tri: [u32; 3], a: u32, b: u32) -> Option<u8> {
    (0..3u8).find(|&i| {
        let (x, y) = (tri[i as usize], tri[(i as usize + 1) % 3]);
        (x == a && y == b) || (x == b && y == a)
    })
}

/// The weight of the edge `a`–`b` of triangle `tri` with side weights `bits`.
pub(super) fn weight_of(tri: [u32; 3], bits: u8, a: u32, b: u32) -> u8 {
    side_of(tri, a, b).map_or(0, |i| (bits >> i) & 1)
}

/// Every vertex's triangles form one fan (a disk or a half-disk) in the dual graph: a walk
/// around it from one triangle, both ways where it is open, reaches all of them.
/// `count[v]`: the triangles at `v`; `first[v]`: one of them.
fn fans_are_disks(mesh: &Mesh, count: &[u32], first: &[u32]) -> bool {
    let tris = &mesh.triangles;
    let nb = &mesh.topology.neighbours;
    // Walks around `v` from `start`, leaving it across its side `side` (one of the two at
    // `v`), until the fan closes or opens: the triangles reached (start excluded) and
    // whether it closed; `None` past `limit`.
    let walk = |v: u32, start: u32, mut side: usize, limit: u32| -> Option<(u32, bool)> {
        let (mut t, mut seen) = (start, 0u32);
        loop {
            let u = nb[t as usize][side];
            if u == NONE {
                return Some((seen, false));
            }
            if u == start {
                return Some((seen, true));
            }
            seen += 1;
            if seen > limit {
                return None;
            }
            // In `u`, the sides at `v` are k and k - 1: leave by the one not towards `t`.
            let k = tris[u as usize].iter().position(|&x| x == v)?;
            side = if nb[u as usize][k] != t {
                k
            } else {
                (k + 2) % 3
            };
            t = u;
        }
    };
    (0..count.len()).all(|v| {
        let n = count[v];
        if n == 0 {
            return true;
        }
        let (start, v) = (first[v], v as u32);
        let k = (tris[start as usize].iter())
            .position(|&y| y == v)
            .expect("incident");
        match walk(v, start, k, n) {
            Some((seen, true)) => seen + 1 == n,
            Some((seen, false)) => match walk(v, start, (k + 2) % 3, n) {
                Some((back, false)) => seen + back + 1 == n,
                _ => false,
            },
            None => false,
        }
    })
}

/// Every component is a sphere with holes: `V - E + F = 2 - L` per component, checked as
/// the sum over components (each side is at most the other's per component, so the sums
/// agree only when every component's do). `L` counts boundary loops, the components of
/// the boundary edges (one cycle each: the fans are disks).
fn genus_zero(mesh: &Mesh, count: &[u32]) -> bool {
    let tris = &mesh.triangles;
    let nb = &mesh.topology.neighbours;
    let nv = mesh.vertices.len();
    let mut parent: Vec<u32> = (0..nv as u32).collect();
    fn root(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            let p = parent[v as usize];
            parent[v as usize] = parent[p as usize];
            v = p;
        }
        v
    }
    let mut on_boundary = vec![false; nv];
    for (t, tri) in tris.iter().enumerate() {
        for i in 0..3 {
            if nb[t][i] == NONE {
                let (a, b) = (tri[i], tri[(i + 1) % 3]);
                on_boundary[a as usize] = true;
                on_boundary[b as usize] = true;
                let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                if ra != rb {
                    parent[ra as usize] = rb;
                }
            }
        }
    }
    let loops = (0..nv as u32)
        .filter(|&v| on_boundary[v as usize] && root(&mut parent, v) == v)
        .count() as i64;
    let v = count.iter().filter(|&&n| n > 0).count() as i64;
    let e = mesh.topology.num_edges as i64;
    let f = tris.len() as i64;
    let components = mesh.topology.component_sizes.len() as i64;
    v - e + f == 2 * components - loops
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::{self, GridSpec};
    use crate::mesh::{MeshData, load};

    /// Every triangle's sides sum to whether it counts, both triangles of an edge agree on
    /// its weight, and every boundary edge weighs 0: what the parity argument rests on.
    /// The triangles at each vertex and one of them, as the state's build counts them.
    fn fans(mesh: &Mesh) -> (Vec<u32>, Vec<u32>) {
        let mut count = vec![0; mesh.vertices.len()];
        let mut first = vec![NONE; mesh.vertices.len()];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for &v in tri {
                count[v as usize] += 1;
                first[v as usize] = t as u32;
            }
        }
        (count, first)
    }

    fn weights(mesh: &Mesh, active: impl Fn(u32) -> bool) -> Option<Vec<u8>> {
        let (count, first) = fans(mesh);
        edge_weights(mesh, &count, &first, active)
    }

    fn check_weights(name: &str, mesh: &Mesh, active: impl Fn(u32) -> bool) {
        let w = weights(mesh, &active).unwrap_or_else(|| panic!("{name}: not covered"));
        let (tris, nb) = (&mesh.triangles, &mesh.topology.neighbours);
        for t in 0..tris.len() {
            assert_eq!(w[t] & !7, 0, "{name}: triangle {t} has a fourth side");
            let sum = w[t].count_ones() & 1;
            assert_eq!(
                sum == 1,
                active(t as u32),
                "{name}: triangle {t} sums to {sum}"
            );
            for i in 0..3 {
                let (a, b, u) = (tris[t][i], tris[t][(i + 1) % 3], nb[t][i]);
                let mine = (w[t] >> i) & 1;
                if u == NONE {
                    assert_eq!(mine, 0, "{name}: boundary side {i} of {t}");
                } else {
                    let theirs = weight_of(tris[u as usize], w[u as usize], a, b);
                    assert_eq!(mine, theirs, "{name}: edge {a}-{b} of {t} and {u}");
                }
            }
        }
    }

    #[test]
    fn weights_sum_to_each_triangles_count() {
        let grid = |holes, seed| {
            generate::grid(GridSpec {
                triangles: 2000,
                seed,
                holes,
                ..GridSpec::default()
            })
        };
        for (name, mesh) in [
            ("borouchaki", load("borouchaki").unwrap()),
            ("sphere", load("sphere").unwrap()),
            ("icosphere", generate::icosphere(2)),
            ("grid", grid(false, 1)),
            ("grid with a hole", grid(true, 2)),
        ] {
            check_weights(name, &mesh, |_| true);
            // Some triangles not counted (those of odd initial polders), an even number of
            // them (the counted ones are even polders).
            check_weights(name, &mesh, |t| (t / 2) % 5 != 0);
        }
    }

    /// A grid of `nu` x `nv` cells on a torus (`rows == nv`) or a cylinder (`rows == nv + 1`).
    fn wrapped(nu: usize, nv: usize, rows: usize) -> Mesh {
        let id = |i: usize, j: usize| (i % nu * rows + j % rows) as u32;
        let mut vertices = Vec::new();
        for i in 0..nu {
            let a = std::f64::consts::TAU * i as f64 / nu as f64;
            for j in 0..rows {
                let b = std::f64::consts::TAU * j as f64 / nv as f64;
                let r = 2.0 + 0.7 * b.cos();
                vertices.push([r * a.cos(), r * a.sin(), 0.7 * b.sin() + j as f64]);
            }
        }
        let mut triangles = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                triangles.extend([[a, b, c], [a, c, d]]);
            }
        }
        Mesh::new(MeshData {
            vertices,
            triangles,
            ..MeshData::default()
        })
        .unwrap()
    }

    #[test]
    fn only_spheres_with_holes_are_covered() {
        assert!(
            genus_zero(&wrapped(6, 3, 4), &fans(&wrapped(6, 3, 4)).0),
            "a cylinder"
        );
        assert!(weights(&wrapped(6, 3, 4), |_| true).is_some());
        assert!(
            !genus_zero(&wrapped(6, 4, 4), &fans(&wrapped(6, 4, 4)).0),
            "a torus"
        );
        assert!(weights(&wrapped(6, 4, 4), |_| true).is_none());
        // Two fans at one vertex (a bow tie): not a disk around it.
        let bowtie = Mesh::new(MeshData {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [-1.0, 0.0, 0.0],
                [-1.0, -1.0, 0.0],
            ],
            triangles: vec![[0, 1, 2], [0, 3, 4]],
            ..MeshData::default()
        })
        .unwrap();
        let (count, first) = fans(&bowtie);
        assert!(!fans_are_disks(&bowtie, &count, &first));
        assert!(weights(&bowtie, |_| true).is_none());
        // Input quads, and a surface boundary inside the mesh: not covered.
        let with_quad = MeshData {
            vertices: vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0, 1.0, 0.0],
                [2.0, 1.0, 0.0],
            ],
            triangles: vec![[1, 2, 5], [1, 5, 4]],
            ..MeshData::default()
        };
        let triangles_only = Mesh::new(with_quad.clone()).unwrap();
        assert!(weights(&triangles_only, |_| true).is_some());
        let quad = Mesh::new(MeshData {
            quads: vec![[0, 1, 4, 3]],
            ..with_quad
        })
        .unwrap();
        assert!(weights(&quad, |_| true).is_none());
        let surfaces = generate::grid(GridSpec {
            triangles: 200,
            surfaces: 2,
            ..GridSpec::default()
        });
        assert!(weights(&surfaces, |_| true).is_none());
    }
}
