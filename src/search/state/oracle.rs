//! What the tests judge the state by: [`State::sanity_check`] (internal invariants and
//! every verdict against a from-scratch evaluation) and [`naive_allowed`], the criterion
//! computed by a full search per candidate.

use super::{State, is_split};
use crate::mesh::{Mesh, NONE};
use crate::quality::CandidateTable;

impl State<'_> {
    /// Checks the state's internal invariants (buckets, counts, polder sizes) and the
    /// verdicts against a from-scratch evaluation of the criterion. O(n) per candidate:
    /// for tests only.
    pub fn sanity_check(&self) -> Result<(), String> {
        if let Some(c) = (0..self.cand.len()).find(|&c| self.cand[c].dirty) {
            return Err(format!("candidate {c} still marked stale"));
        }
        let nt = self.alive.len();
        for t in 0..nt {
            let k = self.count[t];
            let expect = if self.alive[t] {
                self.table.by_triangle[t]
                    .iter()
                    .filter(|&&c| c != NONE && self.cand[c as usize].verdict.allowed)
                    .count() as u8
            } else {
                0
            };
            if k != expect {
                return Err(format!("triangle {t}: count {k}, allowed actions {expect}"));
            }
        }
        for k in 1..4u32 {
            let members = self.bucket(k);
            let expect: Vec<u32> = (0..nt as u32)
                .filter(|&t| self.count[t as usize] as u32 == k)
                .collect();
            if members != expect {
                return Err(format!("P_{k} holds {members:?}, counts say {expect:?}"));
            }
        }
        let naive = naive_parts(self.mesh, self.table, &self.alive);
        for (c, &(ok, parts)) in naive.iter().enumerate() {
            let v = &self.cand[c].verdict;
            if ok != v.allowed {
                return Err(format!(
                    "candidate {c}: allowed {} but the naive criterion says {ok}",
                    v.allowed
                ));
            }
            // A verdict that found one part (an apply then relabels nothing) must still be
            // right; a split can have lost a part since (see `tree_push`).
            if self.is_live(c as u32) && !is_split(v.kind) && parts >= 2 {
                return Err(format!(
                    "candidate {c}: a verdict of kind {} (one part) but its removal leaves \
                     {parts} parts",
                    v.kind
                ));
            }
        }
        Ok(())
    }
}

/// The criterion evaluated from scratch for every candidate (a full search from each
/// neighbour of the pair, same rule: at most one odd part): the reference the fast state is
/// tested against. `alive[t]` says which triangles remain.
pub fn naive_allowed(mesh: &Mesh, table: &CandidateTable, alive: &[bool]) -> Vec<bool> {
    let parts = naive_parts(mesh, table, alive);
    parts.into_iter().map(|(ok, _)| ok).collect()
}

/// [`naive_allowed`] with, for each candidate, the number of parts its removal leaves of
/// its polder (0 for a used candidate).
fn naive_parts(mesh: &Mesh, table: &CandidateTable, alive: &[bool]) -> Vec<(bool, u32)> {
    debug_assert_eq!(mesh.num_triangles(), alive.len());
    let nb = &table.dual_graph();
    let nt = alive.len();
    let mut stack = Vec::new();
    let mut mark = vec![0u32; nt];
    let mut epoch = 0;
    (0..table.len())
        .map(|c| {
            let [t0, t1] = table.pairs[c];
            if !alive[t0 as usize] || !alive[t1 as usize] {
                return (false, 0);
            }
            epoch += 1;
            mark[t0 as usize] = epoch;
            mark[t1 as usize] = epoch;
            let (mut odd, mut parts) = (0, 0);
            for &s in nb[t0 as usize].iter().chain(&nb[t1 as usize]) {
                if s == NONE || !alive[s as usize] || mark[s as usize] == epoch {
                    continue;
                }
                mark[s as usize] = epoch;
                stack.push(s);
                let mut size = 0u32;
                while let Some(x) = stack.pop() {
                    size += 1;
                    for &u in &nb[x as usize] {
                        if u != NONE && alive[u as usize] && mark[u as usize] != epoch {
                            mark[u as usize] = epoch;
                            stack.push(u);
                        }
                    }
                }
                odd += size & 1;
                parts += 1;
            }
            (odd <= 1, parts)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MeshData;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// A jittered `n` x `n` grid of split squares with one square removed (a hole) and one
    /// extra lone triangle (an odd component).
    fn mesh(n: usize, seed: u64) -> Mesh {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut d = MeshData::default();
        for j in 0..=n {
            for i in 0..=n {
                let inner = i > 0 && j > 0 && i < n && j < n;
                let mut jit = || (rng.next_u64() as f64 / u64::MAX as f64 - 0.5) * 0.4;
                let (dx, dy) = if inner { (jit(), jit()) } else { (0.0, 0.0) };
                d.vertices.push([i as f64 + dx, j as f64 + dy, 0.0]);
            }
        }
        let v = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        for j in 0..n {
            for i in 0..n {
                if (i, j) == (n / 2, n / 2) {
                    continue;
                }
                if (i + j) % 3 == 0 {
                    d.triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
                    d.triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
                } else {
                    d.triangles.push([v(i, j), v(i + 1, j), v(i, j + 1)]);
                    d.triangles
                        .push([v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)]);
                }
            }
        }
        let b = d.vertices.len() as u32;
        d.vertices
            .extend([[-3.0, 0.0, 0.0], [-2.0, 0.0, 0.0], [-3.0, 1.0, 0.0]]);
        d.triangles.push([b, b + 1, b + 2]);
        Mesh::new(d).unwrap()
    }

    /// Lazy applies (as the trees do) with lazy queries must agree with the naive criterion
    /// once resolved, and undo must restore the exact earlier state.
    #[test]
    fn lazy_walks_resolve_to_the_naive_criterion() {
        for seed in 0..4 {
            let m = mesh(7, seed);
            let table = CandidateTable::build(&m);
            let mut st = State::new(&m, &table);
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            for _ in 0..3 {
                loop {
                    // Lazy queries agree with the naive criterion on what they read.
                    let naive = naive_allowed(&m, &table, &st.alive);
                    let c = (rng.next_u64() % table.len() as u64) as u32;
                    assert_eq!(st.is_allowed_lazy(c), naive[c as usize], "candidate {c}");
                    let t = table.pairs[c as usize][0];
                    let k = table.by_triangle[t as usize]
                        .iter()
                        .filter(|&&x| x != NONE && naive[x as usize])
                        .count() as u32;
                    let k = if st.is_remaining(t) { k } else { 0 };
                    assert_eq!(st.allowed_count_lazy(t), k);
                    let allowed: Vec<u32> = (0..table.len() as u32)
                        .filter(|&x| naive[x as usize])
                        .collect();
                    if allowed.is_empty() {
                        break;
                    }
                    if st.depth() > 0 && rng.next_u64() % 4 == 0 {
                        st.undo();
                    } else {
                        let a = allowed[(rng.next_u64() % allowed.len() as u64) as usize];
                        st.apply_lazy(a);
                    }
                    if rng.next_u64() % 3 == 0 {
                        st.resolve_all();
                        st.sanity_check().unwrap();
                    }
                }
                st.reset();
                st.sanity_check().unwrap();
            }
        }
    }
}
