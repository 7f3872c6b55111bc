//! Small mesh builders for the oracle test, independent of the library's generators: strips,
//! jittered grids (diagonals, holes, dropped triangles, input quads, surface tags), icospheres
//! and random triangulations (random point insertions and edge flips).

use quadrecomb::internals::mesh::{Mesh, MeshData};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;

/// A strip of `n` triangles where triangle i neighbours exactly i - 1 and i + 1.
pub fn strip(n: usize) -> Mesh {
    strip_with_surfaces(&vec![1; n])
}

/// A strip of `surfaces.len()` triangles, triangle i on surface `surfaces[i]`.
pub fn strip_with_surfaces(surfaces: &[i32]) -> Mesh {
    let n = surfaces.len();
    let vertices = (0..n + 2)
        .map(|k| [k as f64 * 0.5, (k % 2) as f64, 0.0])
        .collect();
    let triangles = (0..n as u32).map(|i| [i, i + 1, i + 2]).collect();
    Mesh::new(MeshData {
        vertices,
        triangles,
        triangle_surface: surfaces.to_vec(),
        ..MeshData::default()
    })
    .expect("valid strip")
}

/// Direction of the diagonal splitting each grid cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Diagonals {
    /// Every cell from its lower-left to its upper-right corner.
    Rising,
    /// Rising where i + j is even, falling elsewhere.
    Alternating,
    /// Chosen at random per cell.
    Random,
}

/// How surface tags are assigned to the triangles of a grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Surfaces {
    One,
    /// Four quadrants of the grid, four surfaces.
    Quadrants,
    /// Vertical bands `width` cells wide.
    Bands(usize),
    /// A random tag in 1..=k per cell (both triangles share it).
    RandomCells(i32),
    /// A random tag in 1..=k per triangle (many tiny polders).
    RandomTriangles(i32),
}

/// A jittered grid of `nx` by `ny` unit cells, each split into two triangles (or kept as an
/// input quad), with random holes and dropped triangles. Everything random comes from `seed`.
#[derive(Debug, Clone)]
pub struct Grid {
    pub nx: usize,
    pub ny: usize,
    /// Each vertex moves by up to this much in x and y (keep below 0.25).
    pub jitter: f64,
    pub diagonals: Diagonals,
    /// Probability that a cell is removed.
    pub holes: f64,
    /// Probability that a single triangle is removed (odd components).
    pub drop: f64,
    /// Probability that a cell is an input quad (never recombined, cuts the dual graph).
    pub quads: f64,
    pub surfaces: Surfaces,
    /// Cells whose diagonal is flipped after `diagonals` is applied.
    pub flip: Vec<(usize, usize)>,
    /// Walls standing on grid lines, out of the plane (other surfaces meeting the grid's).
    pub fins: Vec<Fin>,
    pub seed: u64,
}

/// A wall of triangles standing on the grid line `y = j` (row of vertices `j`) from column
/// `i0` to `i1`, `levels` cells high (in z), on surface `surface`, its cells' diagonals drawn
/// at random; `through` also puts it below the plane (same surface), so that the wall has
/// two triangles on each of the line's edges as the grid has.
#[derive(Debug, Clone)]
pub struct Fin {
    pub j: usize,
    pub i0: usize,
    pub i1: usize,
    pub levels: usize,
    pub surface: i32,
    pub through: bool,
}

impl Grid {
    /// A plain grid: rising diagonals, no jitter, no holes, one surface.
    pub fn plain(nx: usize, ny: usize) -> Grid {
        Grid {
            nx,
            ny,
            jitter: 0.0,
            diagonals: Diagonals::Rising,
            holes: 0.0,
            drop: 0.0,
            quads: 0.0,
            surfaces: Surfaces::One,
            flip: Vec::new(),
            fins: Vec::new(),
            seed: 0,
        }
    }

    /// Builds the mesh; `None` when nothing is left (every cell removed).
    pub fn build(&self) -> Option<Mesh> {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        let (nx, ny) = (self.nx, self.ny);
        let vid = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
        let mut vertices = Vec::with_capacity((nx + 1) * (ny + 1));
        for j in 0..=ny {
            for i in 0..=nx {
                let (dx, dy) = if self.jitter > 0.0 {
                    (
                        rng.random_range(-self.jitter..self.jitter),
                        rng.random_range(-self.jitter..self.jitter),
                    )
                } else {
                    (0.0, 0.0)
                };
                vertices.push([i as f64 + dx, j as f64 + dy, 0.0]);
            }
        }
        let mut triangles = Vec::new();
        let mut triangle_surface = Vec::new();
        let mut quads = Vec::new();
        let mut quad_surface = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                let surface = match self.surfaces {
                    Surfaces::One => 1,
                    Surfaces::Quadrants => 1 + (i >= nx / 2) as i32 + 2 * (j >= ny / 2) as i32,
                    Surfaces::Bands(w) => 1 + (i / w.max(1)) as i32,
                    Surfaces::RandomCells(k) | Surfaces::RandomTriangles(k) => {
                        rng.random_range(1..=k.max(1))
                    }
                };
                let mut rising = match self.diagonals {
                    Diagonals::Rising => true,
                    Diagonals::Alternating => (i + j) % 2 == 0,
                    Diagonals::Random => rng.random_bool(0.5),
                };
                if self.flip.contains(&(i, j)) {
                    rising = !rising;
                }
                let hole = self.holes > 0.0 && rng.random_bool(self.holes);
                let quad = self.quads > 0.0 && rng.random_bool(self.quads);
                let drops = [
                    self.drop > 0.0 && rng.random_bool(self.drop),
                    self.drop > 0.0 && rng.random_bool(self.drop),
                ];
                let (v00, v10, v11, v01) =
                    (vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1));
                if hole {
                    continue;
                }
                if quad {
                    quads.push([v00, v10, v11, v01]);
                    quad_surface.push(surface);
                    continue;
                }
                let pair = if rising {
                    [[v00, v10, v11], [v00, v11, v01]]
                } else {
                    [[v00, v10, v01], [v10, v11, v01]]
                };
                for (tri, dropped) in pair.into_iter().zip(drops) {
                    if dropped {
                        continue;
                    }
                    triangles.push(tri);
                    triangle_surface.push(match self.surfaces {
                        Surfaces::RandomTriangles(k) => rng.random_range(1..=k.max(1)),
                        _ => surface,
                    });
                }
            }
        }
        for fin in &self.fins {
            assert!(
                fin.i0 < fin.i1 && fin.i1 <= nx && fin.j <= ny,
                "{fin:?} off the grid"
            );
            let mut row = |sign: f64| {
                // Vertex ids of the wall's level k (level 0 is the grid's line).
                let mut levels = vec![(fin.i0..=fin.i1).map(|i| vid(i, fin.j)).collect::<Vec<_>>()];
                for k in 1..=fin.levels {
                    levels.push(
                        (fin.i0..=fin.i1)
                            .map(|i| {
                                let [x, y, _] = vertices[vid(i, fin.j) as usize];
                                vertices.push([x, y, sign * k as f64]);
                                vertices.len() as u32 - 1
                            })
                            .collect(),
                    );
                }
                for k in 0..fin.levels {
                    for i in 0..fin.i1 - fin.i0 {
                        let (a, b) = (levels[k][i], levels[k][i + 1]);
                        let (c, d) = (levels[k + 1][i + 1], levels[k + 1][i]);
                        let pair = if rng.random_bool(0.5) {
                            [[a, b, c], [a, c, d]]
                        } else {
                            [[a, b, d], [b, c, d]]
                        };
                        for tri in pair {
                            triangles.push(tri);
                            triangle_surface.push(fin.surface);
                        }
                    }
                }
            };
            row(1.0);
            if fin.through {
                row(-1.0);
            }
        }
        if triangles.is_empty() {
            return None;
        }
        Some(
            Mesh::new(MeshData {
                vertices,
                triangles,
                triangle_surface,
                quads,
                quad_surface,
                ..MeshData::default()
            })
            .expect("valid grid"),
        )
    }
}

/// The icosahedron subdivided `subdiv` times and projected on the unit sphere: closed, every
/// triangle has three neighbours, 20 * 4^subdiv triangles.
pub fn icosphere(subdiv: u32) -> Mesh {
    let p = (1.0 + 5f64.sqrt()) / 2.0;
    let mut vertices: Vec<[f64; 3]> = vec![
        [-1.0, p, 0.0],
        [1.0, p, 0.0],
        [-1.0, -p, 0.0],
        [1.0, -p, 0.0],
        [0.0, -1.0, p],
        [0.0, 1.0, p],
        [0.0, -1.0, -p],
        [0.0, 1.0, -p],
        [p, 0.0, -1.0],
        [p, 0.0, 1.0],
        [-p, 0.0, -1.0],
        [-p, 0.0, 1.0],
    ];
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdiv {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut next = Vec::with_capacity(triangles.len() * 4);
        let mut midpoint = |a: u32, b: u32, vertices: &mut Vec<[f64; 3]>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (x, y) = (vertices[a as usize], vertices[b as usize]);
                vertices.push([
                    (x[0] + y[0]) / 2.0,
                    (x[1] + y[1]) / 2.0,
                    (x[2] + y[2]) / 2.0,
                ]);
                vertices.len() as u32 - 1
            })
        };
        for [a, b, c] in triangles {
            let ab = midpoint(a, b, &mut vertices);
            let bc = midpoint(b, c, &mut vertices);
            let ca = midpoint(c, a, &mut vertices);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    for v in &mut vertices {
        let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        *v = v.map(|x| x / n);
    }
    Mesh::new(MeshData {
        vertices,
        triangles,
        ..MeshData::default()
    })
    .expect("valid icosphere")
}

/// A grid of `nu` by `nv` cells wrapped into a closed surface (each cell two triangles, its
/// diagonal rising): a torus (genus 1, where a quad that touches one dead component twice
/// need not cut) with `Wrap::Torus`, an open cylinder (an annulus, genus 0) with
/// `Wrap::Cylinder`. (A Möbius strip is refused by `Mesh::new`: not orientable.)
pub fn wrapped(nu: usize, nv: usize, wrap: Wrap) -> Mesh {
    use std::f64::consts::TAU;
    let rows = if wrap == Wrap::Torus { nv } else { nv + 1 };
    let id = |i: usize, j: usize| -> u32 { (i % nu * rows + j % rows) as u32 };
    let mut vertices = Vec::new();
    for i in 0..nu {
        let a = TAU * i as f64 / nu as f64;
        for j in 0..rows {
            let p = match wrap {
                Wrap::Torus => {
                    let b = TAU * j as f64 / nv as f64;
                    let r = 2.0 + 0.7 * b.cos();
                    [r * a.cos(), r * a.sin(), 0.7 * b.sin()]
                }
                Wrap::Cylinder => [a.cos(), a.sin(), 0.6 * j as f64 / nv as f64],
            };
            vertices.push(p);
        }
    }
    let mut triangles = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            let (a, b) = (id(i, j), id(i + 1, j));
            let (c, d) = (id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    Mesh::new(MeshData {
        vertices,
        triangles,
        ..MeshData::default()
    })
    .expect("valid wrapped grid")
}

/// How [`wrapped`] closes its grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wrap {
    Torus,
    Cylinder,
}

/// Twice the signed area of (a, b, c) in the plane.
fn orient(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// A random planar triangulation of the unit square: `points` random insertions (each splits a
/// random triangle in three at a point well inside it), then `flips` random edge flips of
/// convex quads, then each triangle dropped with probability `drop` and tagged with a random
/// surface in 1..=`surfaces`.
pub fn random_triangulation(
    points: usize,
    flips: usize,
    drop: f64,
    surfaces: i32,
    seed: u64,
) -> Option<Mesh> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut vertices = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let mut triangles: Vec<[u32; 3]> = vec![[0, 1, 2], [0, 2, 3]];
    for _ in 0..points {
        let t = rng.random_range(0..triangles.len());
        let [a, b, c] = triangles[t];
        let mut w = [
            rng.random_range(0.2..1.0),
            rng.random_range(0.2..1.0),
            rng.random_range(0.2..1.0),
        ];
        let s: f64 = w.iter().sum();
        w = w.map(|x| x / s);
        let (pa, pb, pc) = (
            vertices[a as usize],
            vertices[b as usize],
            vertices[c as usize],
        );
        let p: [f64; 3] = std::array::from_fn(|k| w[0] * pa[k] + w[1] * pb[k] + w[2] * pc[k]);
        vertices.push(p);
        let v = vertices.len() as u32 - 1;
        triangles[t] = [a, b, v];
        triangles.push([b, c, v]);
        triangles.push([c, a, v]);
    }
    for _ in 0..flips {
        // Edge (directed, as in its triangle) -> triangle; pick a random interior edge.
        let mut side: HashMap<(u32, u32), usize> = HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            for i in 0..3 {
                side.insert((tri[i], tri[(i + 1) % 3]), t);
            }
        }
        let t = rng.random_range(0..triangles.len());
        let i = rng.random_range(0..3);
        let tri = triangles[t];
        let (a, b, c) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
        let Some(&u) = side.get(&(b, a)) else {
            continue;
        };
        let d = *triangles[u]
            .iter()
            .find(|&&x| x != a && x != b)
            .expect("opposite vertex");
        let (pa, pb, pc, pd) = (
            vertices[a as usize],
            vertices[b as usize],
            vertices[c as usize],
            vertices[d as usize],
        );
        // New diagonal c-d: triangles (a, d, c) and (d, b, c), both counter-clockwise.
        let (x, y) = (orient(pa, pd, pc), orient(pd, pb, pc));
        let scale = 1e-3 * orient(pa, pb, pc).abs().max(1e-12);
        if x > scale && y > scale {
            triangles[t] = [a, d, c];
            triangles[u] = [d, b, c];
        }
    }
    let mut kept = Vec::new();
    let mut triangle_surface = Vec::new();
    for tri in triangles {
        if drop > 0.0 && rng.random_bool(drop) {
            continue;
        }
        kept.push(tri);
        triangle_surface.push(rng.random_range(1..=surfaces.max(1)));
    }
    if kept.is_empty() {
        return None;
    }
    Some(
        Mesh::new(MeshData {
            vertices,
            triangles: kept,
            triangle_surface,
            ..MeshData::default()
        })
        .expect("valid random triangulation"),
    )
}
