//! The selective look-ahead tree replayed naively: the same tree (section 5 of the paper, as
//! `docs/search.md` states it) built on the naive oracle, with the same random draws (one
//! ChaCha8 stream for the root triangles and one key per tree; below the root, each node's
//! draw is its path's key, `key(child) = splitmix64_finaliser(key(parent) ^ (c + 1) *
//! 0x9E3779B97F4A7C15)`; `pick(x, n)` = top 64 bits of `x * n`; `P_min` and `P_k` in
//! increasing triangle id, `N` in path then side order), must choose exactly the same
//! actions as `Searcher` for every seed and horizon. The replay visits every node, in
//! `by_triangle` order; `Searcher` visits children by decreasing reward and cuts subtrees by
//! branch and bound, which must change nothing.

use super::meshes::{self, Diagonals, Grid};
use super::naive::Naive;
use super::sample_meshes;
use crate::util::SEED;
use quadrecomb::internals::mesh::{Mesh, NONE};
use quadrecomb::internals::quality::CandidateTable;
use quadrecomb::internals::search::{Algo, Searcher};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

struct Replay<'a> {
    mesh: &'a Mesh,
    table: &'a CandidateTable,
    oracle: Naive,
    rng: ChaCha8Rng,
    /// Actions applied inside the current tree.
    path: Vec<u32>,
    /// Keys of the nodes of the path (the tree's key first).
    keys: Vec<u64>,
    h: u32,
}

fn pick(x: u64, n: usize) -> usize {
    ((x as u128 * n as u128) >> 64) as usize
}

fn child_key(parent: u64, c: u32) -> u64 {
    let mut z = parent ^ (c as u64 + 1).wrapping_mul(0x9E3779B97F4A7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
    z ^ (z >> 31)
}

impl Replay<'_> {
    /// The draw of the current node: the run's stream at the root, the node's key below.
    fn pick(&mut self, n: usize) -> usize {
        match self.keys.last() {
            Some(&key) => pick(key, n),
            None => pick(self.rng.next_u64(), n),
        }
    }

    fn count(&self, t: u32) -> u32 {
        if !self.oracle.is_remaining(t) {
            return 0;
        }
        self.table.by_triangle[t as usize]
            .iter()
            .filter(|&&c| c != NONE && self.oracle.is_allowed(c))
            .count() as u32
    }

    fn pmin(&mut self) -> Option<u32> {
        let nt = self.mesh.num_triangles() as u32;
        let counts: Vec<u32> = (0..nt).map(|t| self.count(t)).collect();
        let k = counts.iter().copied().filter(|&k| k > 0).min()?;
        let set: Vec<u32> = (0..nt).filter(|&t| counts[t as usize] == k).collect();
        let i = self.pick(set.len());
        Some(set[i])
    }

    /// The triangles across the quad's sides `[s0-o1, o1-s1, s1-o0, o0-s0]`, NONE where
    /// there is none (computed here from the mesh, not asked of the library).
    fn quad_neighbours(&self, c: u32) -> [u32; 4] {
        let [t0, t1] = self.table.pairs[c as usize];
        let [s0, o1, s1, o0] = self.table.quads[c as usize];
        let across = |t: u32, a: u32, b: u32| {
            let tri = self.mesh.triangles[t as usize];
            (0..3)
                .find(|&i| {
                    let (x, y) = (tri[i], tri[(i + 1) % 3]);
                    (x == a && y == b) || (x == b && y == a)
                })
                .map_or(NONE, |i| self.mesh.topology.neighbours[t as usize][i])
        };
        [
            across(t1, s0, o1),
            across(t1, o1, s1),
            across(t0, s1, o0),
            across(t0, o0, s0),
        ]
    }

    fn choose(&mut self) -> Option<u32> {
        let mut near: Vec<u32> = Vec::new();
        let mut kmin = u32::MAX;
        for i in 0..self.path.len() {
            for n in self.quad_neighbours(self.path[i]) {
                if n == NONE {
                    continue;
                }
                let k = self.count(n);
                if k == 0 || k > kmin {
                    continue;
                }
                if k < kmin {
                    kmin = k;
                    near.clear();
                }
                if !near.contains(&n) {
                    near.push(n);
                }
            }
        }
        if near.is_empty() {
            return self.pmin();
        }
        let i = self.pick(near.len());
        Some(near[i])
    }

    fn child(&mut self, c: u32, d: u32) -> f64 {
        if d == self.h {
            return 0.0;
        }
        self.oracle.apply(c);
        self.path.push(c);
        let key = child_key(*self.keys.last().expect("inside a tree"), c);
        self.keys.push(key);
        let v = self.node(d);
        self.keys.pop();
        self.path.pop();
        self.oracle.undo();
        v
    }

    fn node(&mut self, d: u32) -> f64 {
        let Some(t) = self.choose() else {
            return 0.0;
        };
        let mut best = f64::NEG_INFINITY;
        for c in self.table.by_triangle[t as usize] {
            if c != NONE && self.oracle.is_allowed(c) {
                let v = self.table.eta[c as usize] + self.child(c, d + 1);
                if v > best {
                    best = v;
                }
            }
        }
        best
    }

    fn run(mut self) -> Vec<u32> {
        let mut chosen = Vec::new();
        while let Some(t) = self.pmin() {
            let allowed: Vec<u32> = self.table.by_triangle[t as usize]
                .into_iter()
                .filter(|&c| c != NONE && self.oracle.is_allowed(c))
                .collect();
            if let [only] = allowed[..] {
                // A single allowed action is applied without a tree (no draws below it).
                self.oracle.apply(only);
                chosen.push(only);
                continue;
            }
            let mut best = f64::NEG_INFINITY;
            let mut first = NONE;
            self.keys = vec![self.rng.next_u64()];
            for c in self.table.by_triangle[t as usize] {
                if c != NONE && self.oracle.is_allowed(c) {
                    let v = self.table.eta[c as usize] + self.child(c, 1);
                    if v > best {
                        best = v;
                        first = c;
                    }
                }
            }
            self.keys.clear();
            self.oracle.apply(first);
            chosen.push(first);
        }
        chosen
    }
}

fn naive_selective(mesh: &Mesh, table: &CandidateTable, h: u32, seed: u64) -> Vec<u32> {
    Replay {
        mesh,
        table,
        oracle: Naive::new(mesh, table),
        rng: ChaCha8Rng::seed_from_u64(seed),
        path: Vec::new(),
        keys: Vec::new(),
        h,
    }
    .run()
}

#[test]
fn selective_tree_equals_naive_replay() {
    let mut meshes: Vec<(String, Mesh)> = sample_meshes(SEED ^ 0x5E1);
    meshes.push(("strip(7)".into(), meshes::strip(7)));
    let mut spec = Grid::plain(9, 8);
    spec.jitter = 0.25;
    spec.diagonals = Diagonals::Random;
    spec.holes = 0.08;
    spec.seed = SEED ^ 0x5E2;
    meshes.push((format!("{spec:?}"), spec.build().unwrap()));
    let mut runs = 0;
    for (name, mesh) in &meshes {
        let table = CandidateTable::build(mesh);
        let mut searcher = Searcher::new(mesh, &table);
        for (h, seeds) in [(1, 3u64), (2, 3), (3, 2), (5, 1)] {
            for s in 0..seeds {
                let seed = SEED ^ (s * 31 + h as u64);
                let got = searcher.run(Algo::selective(h), seed).chosen;
                let expected = naive_selective(mesh, &table, h, seed);
                assert_eq!(
                    got, expected,
                    "mesh {name}, selective h={h}, seed {seed:#x}: actions differ"
                );
                runs += 1;
            }
        }
    }
    assert!(runs >= 100, "{runs} runs");
}
