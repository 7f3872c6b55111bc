//! One-cell-wide corridors of unit squares, each split along a random diagonal: a straight
//! strip, a square spiral and a maze (long branching corridors). Their dual graphs are
//! a path and trees, the long thin polders on which the criterion's searches are longest
//! (docs/search.md, "Memory"). Deterministic: a corridor depends only on its shape, size and
//! seed (raw `u64`s of a ChaCha8 stream).

use super::{GenerateError, MAX_GRID_TRIANGLES};
use crate::mesh::{Mesh, MeshData};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashMap;

/// The shape of a corridor mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Corridor {
    /// A straight strip, one cell high.
    Strip,
    /// A square spiral around the origin, its turns one empty cell apart.
    Spiral,
    /// A perfect maze (a random spanning tree of rooms, by depth-first search): rooms and
    /// the passages between them, each one cell.
    Maze,
}

impl Corridor {
    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Corridor::Strip => "strip",
            Corridor::Spiral => "spiral",
            Corridor::Maze => "maze",
        }
    }

    /// The number of cells for a target triangle count (two triangles per cell; a maze of
    /// `r` rooms has `2r - 1` cells).
    fn cells_for(self, triangles: usize) -> usize {
        let cells = (triangles / 2).max(1);
        match self {
            Corridor::Strip | Corridor::Spiral => cells,
            Corridor::Maze => 2 * cells.div_ceil(2) - 1,
        }
    }

    /// The triangle count [`corridor`] gives for `triangles`: `2 * cells`, the nearest
    /// below or at the target (a maze's cell count is odd).
    pub fn triangle_count(self, triangles: usize) -> usize {
        2 * self.cells_for(triangles)
    }
}

/// Checks a corridor's size: at least 2 triangles, at most [`MAX_GRID_TRIANGLES`].
pub fn validate_corridor(shape: Corridor, triangles: usize) -> Result<(), GenerateError> {
    if !(2..=MAX_GRID_TRIANGLES).contains(&triangles) {
        return Err(GenerateError::CorridorSize {
            shape: shape.name(),
            triangles,
        });
    }
    Ok(())
}

/// A corridor of `shape` with [`Corridor::triangle_count`]`(triangles)` triangles, one
/// surface, in the plane z = 0.
///
/// # Panics
/// If [`validate_corridor`] fails.
pub fn corridor(shape: Corridor, triangles: usize, seed: u64) -> Mesh {
    if let Err(e) = validate_corridor(shape, triangles) {
        panic!("{e}");
    }
    let n = shape.cells_for(triangles);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let cells = match shape {
        Corridor::Strip => (0..n as i64).map(|i| (i, 0)).collect(),
        Corridor::Spiral => spiral_cells(n),
        Corridor::Maze => maze_cells(n.div_ceil(2), &mut rng),
    };
    cells_mesh(&cells, &mut rng)
}

/// `n` cells along a square spiral: arms of 2, 2, 4, 4, 6, 6, ... cells turning left, so
/// that consecutive turns are two cells apart (an empty cell between them).
fn spiral_cells(n: usize) -> Vec<(i64, i64)> {
    let mut out = Vec::with_capacity(n);
    let (mut x, mut y) = (0i64, 0i64);
    let dirs = [(1, 0), (0, 1), (-1, 0), (0, -1)];
    let mut arm = 0usize;
    out.push((x, y));
    while out.len() < n {
        let (dx, dy) = dirs[arm % 4];
        let len = 2 * (arm / 2 + 1);
        for _ in 0..len {
            if out.len() == n {
                break;
            }
            x += dx;
            y += dy;
            out.push((x, y));
        }
        arm += 1;
    }
    out
}

/// A perfect maze of `rooms` rooms: rooms at even coordinates on a near-square grid filled
/// row by row, joined by a random spanning tree (iterative depth-first search, neighbours
/// in random order); each tree edge opens the passage cell between its two rooms. `2 *
/// rooms - 1` cells.
fn maze_cells(rooms: usize, rng: &mut ChaCha8Rng) -> Vec<(i64, i64)> {
    let w = (rooms as f64).sqrt().ceil().max(1.0) as usize;
    let pos = |r: usize| ((r % w) as i64, (r / w) as i64);
    let id = |x: i64, y: i64| -> Option<usize> {
        if x < 0 || y < 0 || x >= w as i64 {
            return None;
        }
        let r = y as usize * w + x as usize;
        (r < rooms).then_some(r)
    };
    let mut out = Vec::with_capacity(2 * rooms);
    let mut seen = vec![false; rooms];
    let mut stack = vec![0usize];
    seen[0] = true;
    out.push((0, 0));
    while let Some(&r) = stack.last() {
        let (x, y) = pos(r);
        let mut next = [usize::MAX; 4];
        let mut k = 0;
        for (dx, dy) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
            if let Some(s) = id(x + dx, y + dy).filter(|&s| !seen[s]) {
                next[k] = s;
                k += 1;
            }
        }
        if k == 0 {
            stack.pop();
            continue;
        }
        let s = next[(rng.next_u64() % k as u64) as usize];
        seen[s] = true;
        let (sx, sy) = pos(s);
        out.push((x + sx, y + sy)); // the passage, between 2x and 2sx
        out.push((2 * sx, 2 * sy));
        stack.push(s);
    }
    out
}

/// The mesh of unit cells at `cells` (integer lower-left corners), each split along a
/// random diagonal, triangles counter-clockwise.
fn cells_mesh(cells: &[(i64, i64)], rng: &mut ChaCha8Rng) -> Mesh {
    let mut index: HashMap<(i64, i64), u32> = HashMap::with_capacity(cells.len() + 2);
    let mut vertices = Vec::with_capacity(cells.len() + 2);
    let mut vertex = |x: i64, y: i64| {
        *index.entry((x, y)).or_insert_with(|| {
            vertices.push([x as f64, y as f64, 0.0]);
            (vertices.len() - 1) as u32
        })
    };
    let mut triangles = Vec::with_capacity(2 * cells.len());
    for &(x, y) in cells {
        let (a, b, c, d) = (
            vertex(x, y),
            vertex(x + 1, y),
            vertex(x + 1, y + 1),
            vertex(x, y + 1),
        );
        if rng.next_u64() >> 63 == 1 {
            triangles.extend([[a, b, c], [a, c, d]]);
        } else {
            triangles.extend([[a, b, d], [b, c, d]]);
        }
    }
    Mesh::new(MeshData {
        vertices,
        triangles,
        ..MeshData::default()
    })
    .expect("a corridor is a valid mesh")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::NONE;

    /// Edges of the dual graph (each once).
    fn dual_edges(m: &Mesh) -> usize {
        let nb = &m.topology.neighbours;
        nb.iter().flatten().filter(|&&u| u != NONE).count() / 2
    }

    #[test]
    fn corridors_are_trees_of_the_asked_size() {
        for shape in [Corridor::Strip, Corridor::Spiral, Corridor::Maze] {
            for target in [2usize, 3, 10, 101, 1000, 4321] {
                let m = corridor(shape, target, 7);
                let n = m.num_triangles();
                assert_eq!(n, shape.triangle_count(target), "{shape:?} {target}");
                assert!(
                    n <= target.max(2) && n + 4 > target,
                    "{shape:?} {target}: {n}"
                );
                // One connected component whose dual graph is a tree (a path for a strip;
                // a spiral's turns may leave a one-triangle spur): corridors one cell wide,
                // no turn touching another.
                assert_eq!(m.topology.component_sizes, vec![n as u32], "{shape:?}");
                assert_eq!(dual_edges(&m), n - 1, "{shape:?} {target}");
                if shape == Corridor::Strip {
                    let nb = &m.topology.neighbours;
                    let deg = |t: usize| nb[t].iter().filter(|&&u| u != NONE).count();
                    assert!((0..n).all(|t| deg(t) <= 2), "{shape:?} is a path");
                }
            }
        }
    }

    #[test]
    fn sizes_out_of_range_are_refused_with_the_shape() {
        let e = validate_corridor(Corridor::Strip, 1).unwrap_err();
        assert_eq!(
            e.to_string(),
            format!("a strip needs between 2 and {MAX_GRID_TRIANGLES} triangles (asked for 1)")
        );
        assert!(validate_corridor(Corridor::Maze, MAX_GRID_TRIANGLES + 1).is_err());
        assert!(validate_corridor(Corridor::Maze, 2).is_ok());
        assert_eq!(corridor(Corridor::Maze, 2, 0).num_triangles(), 2);
    }

    #[test]
    fn mazes_branch_and_depend_on_the_seed() {
        let m = corridor(Corridor::Maze, 2000, 1);
        let nb = &m.topology.neighbours;
        let branches = (0..m.num_triangles())
            .filter(|&t| nb[t].iter().all(|&u| u != NONE))
            .count();
        assert!(
            branches > 10,
            "a maze branches ({branches} triangles of degree 3)"
        );
        let other = corridor(Corridor::Maze, 2000, 2);
        assert_ne!(m.triangles, other.triangles);
        assert_eq!(m.triangles, corridor(Corridor::Maze, 2000, 1).triangles);
    }
}
