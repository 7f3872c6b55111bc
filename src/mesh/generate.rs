//! Procedural meshes of any size, without Gmsh, for tests and scaling benchmarks: jittered
//! right-triangle grids on the unit square ([`grid`]), icospheres ([`icosphere`]) and
//! one-cell-wide corridors: strips, spirals and mazes ([`corridor()`]), and jittered
//! equilateral lattices ([`lattice()`]).
//!
//! Both are deterministic: a grid depends only on its [`GridSpec`] (the seed drives a ChaCha8
//! stream, read as raw `u64`s so the result does not change with `rand`'s distributions), on
//! every platform.

mod corridor;
mod lattice;

pub use corridor::{Corridor, corridor, validate_corridor};
pub use lattice::{lattice, lattice_cells};

use super::{Mesh, MeshData};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::borrow::Borrow;
use std::collections::HashMap;

/// Largest icosphere subdivision level: 20 * 4^10 = 20,971,520 triangles.
pub const MAX_SUBDIVISIONS: u32 = 10;

/// Largest grid: about 2^31 triangles keeps every index well inside `u32`.
pub const MAX_GRID_TRIANGLES: usize = 1 << 31;

/// A jittered right-triangle grid on the unit square `[0, 1]^2` (z = 0): `nx` by `ny` cells,
/// each split along a random diagonal into two triangles, interior vertices moved by a random
/// offset (vertices on the outer boundary move only along it; corners stay).
///
/// Optional features for tests that need them: a square hole, several surfaces (vertical
/// strips, so the dual graph splits along each interface) and dropped triangles (each makes
/// its component odd and punches a one-triangle hole).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridSpec {
    /// Target triangle count of the full grid (before holes and drops). The grid gets
    /// `2 * nx * ny` triangles, the closest to this with cells of aspect ratio at most 4/3
    /// (see [`GridSpec::cells`]); at least 2.
    pub triangles: usize,
    /// Seed of the diagonals, the jitter and the dropped triangles.
    pub seed: u64,
    /// Largest vertex offset in each axis, as a fraction of the cell size, in `[0, 0.25)`:
    /// below 1/4 no triangle can flip or degenerate. Default 0.2.
    pub jitter: f64,
    /// Remove the cells in the middle third of the square in both directions (columns
    /// `nx/3 .. nx - nx/3`, rows likewise), leaving one hole. Needs at least 3 x 3 cells.
    pub holes: bool,
    /// Number of surface tags (1, 2, ...): vertical strips of columns, surface `k` (1-based)
    /// holding the columns `i` with `i * surfaces / nx == k - 1`; with 2 surfaces and even `nx`
    /// the interface is x = 0.5. At most `nx`.
    pub surfaces: u32,
    /// Number of triangles to remove, one in each of as many interior cells chosen at random
    /// among cells two apart (never next to each other, the border, a surface interface or the
    /// hole), so that no component splits: each drop flips the parity of its component.
    pub drop_triangles: usize,
}

impl Default for GridSpec {
    fn default() -> Self {
        GridSpec {
            triangles: 1000,
            seed: 0,
            jitter: 0.2,
            holes: false,
            surfaces: 1,
            drop_triangles: 0,
        }
    }
}

/// A generator specification that cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GenerateError {
    #[error("a grid needs at least 2 triangles (asked for {0})")]
    TooFewTriangles(usize),
    #[error("a grid of {0} triangles is too large (at most {MAX_GRID_TRIANGLES})")]
    TooManyTriangles(usize),
    #[error("jitter must be in [0, 0.25) (got {0}); from 1/4 on triangles may flip")]
    Jitter(f64),
    #[error("a hole needs at least 3 x 3 cells (the grid has {nx} x {ny})")]
    GridTooSmallForHole { nx: usize, ny: usize },
    #[error("surfaces must be between 1 and the number of cell columns, {nx} (got {surfaces})")]
    Surfaces { surfaces: u32, nx: usize },
    #[error("cannot drop {asked} triangles: only {available} cells are far enough apart")]
    TooManyDrops { asked: usize, available: usize },
    #[error("icosphere subdivisions must be at most {MAX_SUBDIVISIONS} (got {0})")]
    Subdivisions(u32),
    #[error("a {shape} needs between 2 and {MAX_GRID_TRIANGLES} triangles (asked for {triangles})")]
    CorridorSize {
        shape: &'static str,
        triangles: usize,
    },
}

impl GridSpec {
    /// Number of cells `(nx, ny)` along x and y: among `nx >= ny` with `nx / ny <= 4/3`, the
    /// pair whose `2 * nx * ny` is closest to [`GridSpec::triangles`], the squarer one on ties.
    /// For example 1,000,000 triangles gives 800 x 625 cells, exactly.
    pub fn cells(&self) -> (usize, usize) {
        cells_for(self.triangles.max(2))
    }

    /// Checks that the grid can be built; [`grid`] panics where this fails.
    pub fn validate(&self) -> Result<(), GenerateError> {
        if self.triangles < 2 {
            return Err(GenerateError::TooFewTriangles(self.triangles));
        }
        if self.triangles > MAX_GRID_TRIANGLES {
            return Err(GenerateError::TooManyTriangles(self.triangles));
        }
        if !(0.0..0.25).contains(&self.jitter) {
            return Err(GenerateError::Jitter(self.jitter));
        }
        let (nx, ny) = self.cells();
        if self.holes && (nx < 3 || ny < 3) {
            return Err(GenerateError::GridTooSmallForHole { nx, ny });
        }
        if self.surfaces == 0 || self.surfaces as usize > nx {
            return Err(GenerateError::Surfaces {
                surfaces: self.surfaces,
                nx,
            });
        }
        if self.drop_triangles > 0 {
            let available = drop_candidates(self, nx, ny).len();
            if self.drop_triangles > available {
                return Err(GenerateError::TooManyDrops {
                    asked: self.drop_triangles,
                    available,
                });
            }
        }
        Ok(())
    }

    /// The triangle count [`grid`] will give: `2 * nx * ny`, less the hole and the drops.
    pub fn triangle_count(&self) -> usize {
        let (nx, ny) = self.cells();
        let hole = if self.holes {
            let (i, j) = (hole_range(nx), hole_range(ny));
            i.len() * j.len()
        } else {
            0
        };
        2 * (nx * ny - hole) - self.drop_triangles
    }
}

/// Builds the grid of `spec` (a `GridSpec` or a reference to one).
///
/// # Panics
/// If `spec` fails [`GridSpec::validate`].
pub fn grid(spec: impl Borrow<GridSpec>) -> Mesh {
    let spec = spec.borrow();
    if let Err(e) = spec.validate() {
        panic!("invalid grid spec {spec:?}: {e}");
    }
    let (nx, ny) = spec.cells();
    let (hx, hy) = (1.0 / nx as f64, 1.0 / ny as f64);
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);

    // Vertices (i, j) for i in 0..=nx, j in 0..=ny, row-major in j; jitter drawn for all of
    // them in order (two draws each), then clamped to the boundary where needed.
    let vid = |i: usize, j: usize| j * (nx + 1) + i;
    let mut vertices = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            let dx = (2.0 * unit(&mut rng) - 1.0) * spec.jitter * hx;
            let dy = (2.0 * unit(&mut rng) - 1.0) * spec.jitter * hy;
            let x = if i == 0 || i == nx { 0.0 } else { dx };
            let y = if j == 0 || j == ny { 0.0 } else { dy };
            vertices.push([i as f64 * hx + x, j as f64 * hy + y, 0.0]);
        }
    }
    // Fix the extreme coordinates exactly (i * hx may round).
    for j in 0..=ny {
        vertices[vid(nx, j)][0] = 1.0;
    }
    for i in 0..=nx {
        vertices[vid(i, ny)][1] = 1.0;
    }

    let hole = spec.holes.then(|| (hole_range(nx), hole_range(ny)));
    let in_hole = |i: usize, j: usize| {
        hole.as_ref()
            .is_some_and(|(hi, hj)| hi.contains(&i) && hj.contains(&j))
    };
    // Diagonals: one draw per cell, in cell order, hole or not (so a hole does not change the
    // rest of the grid).
    let diagonal: Vec<bool> = (0..nx * ny).map(|_| rng.next_u64() >> 63 == 1).collect();
    // Dropped triangles: a random subset of the candidate cells, and which half of each.
    let mut dropped: HashMap<usize, usize> = HashMap::new();
    if spec.drop_triangles > 0 {
        let mut cand = drop_candidates(spec, nx, ny);
        for k in 0..spec.drop_triangles {
            let r = k + (rng.next_u64() % (cand.len() - k) as u64) as usize;
            cand.swap(k, r);
            dropped.insert(cand[k], (rng.next_u64() >> 63) as usize);
        }
    }

    let mut triangles = Vec::with_capacity(2 * nx * ny);
    let mut surface = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            if in_hole(i, j) {
                continue;
            }
            let c = j * nx + i;
            let (a, b, cc, d) = (vid(i, j), vid(i + 1, j), vid(i + 1, j + 1), vid(i, j + 1));
            // Counter-clockwise halves: along a-c or along b-d.
            let halves = if diagonal[c] {
                [[a, b, cc], [a, cc, d]]
            } else {
                [[a, b, d], [b, cc, d]]
            };
            let tag = 1 + (i * spec.surfaces as usize / nx) as i32;
            for (h, tri) in halves.iter().enumerate() {
                if dropped.get(&c) == Some(&h) {
                    continue;
                }
                triangles.push(tri.map(|v| v as u32));
                surface.push(tag);
            }
        }
    }

    // Keep only the vertices in use (a hole leaves some out), in grid order.
    let mut new_index = vec![u32::MAX; vertices.len()];
    for tri in &triangles {
        for &v in tri {
            new_index[v as usize] = 0;
        }
    }
    let mut kept = Vec::with_capacity(vertices.len());
    for (v, n) in new_index.iter_mut().enumerate() {
        if *n == 0 {
            *n = kept.len() as u32;
            kept.push(vertices[v]);
        }
    }
    for tri in &mut triangles {
        for v in tri.iter_mut() {
            *v = new_index[*v as usize];
        }
    }

    let data = MeshData {
        vertices: kept,
        triangles,
        triangle_surface: surface,
        ..MeshData::default()
    };
    Mesh::new(data).expect("a valid grid spec gives a valid mesh")
}

/// An icosphere: the regular icosahedron with each triangle split into 4, `subdivisions`
/// times, vertices projected on the unit sphere: `20 * 4^s` triangles, `10 * 4^s + 2` vertices,
/// closed, one surface, triangles oriented outward.
///
/// # Panics
/// If `subdivisions > MAX_SUBDIVISIONS`.
pub fn icosphere(subdivisions: u32) -> Mesh {
    assert!(
        subdivisions <= MAX_SUBDIVISIONS,
        "{}",
        GenerateError::Subdivisions(subdivisions)
    );
    let p = (1.0 + 5f64.sqrt()) / 2.0;
    let mut vertices: Vec<[f64; 3]> = [
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
    ]
    .into_iter()
    .map(normalized)
    .collect();
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
    for _ in 0..subdivisions {
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 2);
        let mut mid = |a: u32, b: u32, vertices: &mut Vec<[f64; 3]>| -> u32 {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (u, w) = (vertices[a as usize], vertices[b as usize]);
                vertices.push(normalized([u[0] + w[0], u[1] + w[1], u[2] + w[2]]));
                (vertices.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for &[a, b, c] in &triangles {
            let (ab, bc, ca) = (
                mid(a, b, &mut vertices),
                mid(b, c, &mut vertices),
                mid(c, a, &mut vertices),
            );
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    Mesh::new(MeshData {
        vertices,
        triangles,
        ..MeshData::default()
    })
    .expect("an icosphere is a valid mesh")
}

/// The subdivision level whose icosphere has the triangle count closest to `target`
/// (`20 * 4^s`, s at most [`MAX_SUBDIVISIONS`]).
pub fn subdivisions_for(target: usize) -> u32 {
    (0..=MAX_SUBDIVISIONS)
        .min_by_key(|&s| (20usize << (2 * s)).abs_diff(target))
        .expect("non-empty range")
}

/// The icosphere with the triangle count closest to `target` (see [`subdivisions_for`]).
pub fn icosphere_with_triangles(target: usize) -> Mesh {
    icosphere(subdivisions_for(target))
}

/// A uniform draw in `[0, 1)` from the top 53 bits of one `u64`.
fn unit(rng: &mut ChaCha8Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

fn normalized(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

/// `(nx, ny)` with `nx >= ny`, `3 * nx <= 4 * ny`, `2 * nx * ny` closest to `target`, the
/// squarer pair on ties. `O(sqrt(target))`.
fn cells_for(target: usize) -> (usize, usize) {
    let half = target as f64 / 2.0;
    let mut best = (1usize, 1usize);
    let mut best_key = (usize::MAX, usize::MAX);
    for ny in 1..=half.sqrt() as usize + 1 {
        let nx = ((half / ny as f64).round() as usize).clamp(ny, (4 * ny) / 3);
        let key = ((2 * nx * ny).abs_diff(target), nx - ny);
        if key < best_key {
            best_key = key;
            best = (nx, ny);
        }
    }
    best
}

/// Hole rows or columns of a grid with `n` cells in that direction: the middle third.
fn hole_range(n: usize) -> std::ops::Range<usize> {
    n / 3..n - n / 3
}

/// Cells where a triangle may be dropped without splitting a component: odd row and column
/// (so candidates are two apart), not on the border, not next to the hole, and not next to a
/// surface interface: the 8 cells around each dropped one are whole and in its surface, so
/// its component stays connected.
fn drop_candidates(spec: &GridSpec, nx: usize, ny: usize) -> Vec<usize> {
    let hole = spec.holes.then(|| (hole_range(nx), hole_range(ny)));
    let strip = |i: usize| i * spec.surfaces as usize / nx;
    let mut out = Vec::new();
    for j in (1..ny.saturating_sub(1)).step_by(2) {
        for i in (1..nx.saturating_sub(1)).step_by(2) {
            let near_hole = hole.as_ref().is_some_and(|(hi, hj)| {
                i + 1 >= hi.start && i < hi.end + 1 && j + 1 >= hj.start && j < hj.end + 1
            });
            let strip_edge = strip(i) != strip(i - 1) || strip(i) != strip(i + 1);
            if !near_hole && !strip_edge {
                out.push(j * nx + i);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_are_near_square_and_near_the_target() {
        assert_eq!(cells_for(1_000_000), (800, 625));
        assert_eq!(cells_for(2), (1, 1));
        assert_eq!(cells_for(3), (1, 1));
        for target in [2usize, 7, 50, 999, 1000, 12_345, 34_456, 1_000_001] {
            let (nx, ny) = cells_for(target);
            assert!(nx >= ny && 3 * nx <= 4 * ny, "{target}: {nx} x {ny}");
            // No better pair within the aspect bound.
            let err = (2 * nx * ny).abs_diff(target);
            for y in 1..=(target as f64).sqrt() as usize + 2 {
                for x in y..=(4 * y) / 3 {
                    assert!((2 * x * y).abs_diff(target) >= err, "{target}: {x} x {y}");
                }
            }
        }
    }

    #[test]
    fn subdivisions_closest() {
        assert_eq!(subdivisions_for(0), 0);
        assert_eq!(subdivisions_for(20), 0);
        assert_eq!(subdivisions_for(2104), 3);
        assert_eq!(subdivisions_for(5000), 4);
        assert_eq!(subdivisions_for(usize::MAX), MAX_SUBDIVISIONS);
    }

    #[test]
    fn unit_draws_are_in_range() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..1000 {
            let u = unit(&mut rng);
            assert!((0.0..1.0).contains(&u));
        }
    }
}
