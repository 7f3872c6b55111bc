//! Quad shape quality eta (eq. 1 of the paper) and the candidate table: one entry per
//! dual-graph edge, i.e. per pair of neighbouring triangles that may be merged into a quad.
//!
//! The candidate table is what the searches, the optimum and the GPU kernel share. Its
//! `eta` column is filled either here in f64 ([`CandidateTable::build`]) or on a device
//! (`gpu`), and the searches never know which.

use crate::mesh::{Mesh, NONE, Recombined};
use std::f64::consts::{FRAC_PI_2, PI};

/// Angle at `p` between the rays to `a` and `b`, in `[0, pi]` (atan2 of |cross| and dot).
/// Degenerate rays give 0. Rays whose length is far from 1 are first rescaled (the angle
/// does not depend on their lengths), so that the products neither overflow nor underflow:
/// the same angle for coordinates scaled by 1e-150 or 1e150.
pub fn angle(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let u = unit_range([a[0] - p[0], a[1] - p[1], a[2] - p[2]]);
    let v = unit_range([b[0] - p[0], b[1] - p[1], b[2] - p[2]]);
    let c = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let cn = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    let d = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    cn.atan2(d)
}

/// `u` as it is when its largest component lies in `[1e-60, 1e60]` (products of two such
/// vectors stay far from f64's limits), else divided by that component. Leaving the usual
/// range alone keeps eta bit for bit what it was for every mesh of ordinary size.
#[inline]
fn unit_range(u: [f64; 3]) -> [f64; 3] {
    let m = u[0].abs().max(u[1].abs()).max(u[2].abs());
    if (1e-60..=1e60).contains(&m) || m == 0.0 || !m.is_finite() {
        u
    } else {
        u.map(|x| x / m)
    }
}

/// eta from the four interior angles of a quad: `max(0, 1 - 2/pi * max_k |pi/2 - alpha_k|)`,
/// and 0 when any angle is `>= pi` (non-convex) or `<= 0`.
pub fn eta_from_angles(alpha: [f64; 4]) -> f64 {
    let mut worst: f64 = 0.0;
    for a in alpha {
        if !(a > 0.0 && a < PI) {
            return 0.0;
        }
        worst = worst.max((FRAC_PI_2 - a).abs());
    }
    (1.0 - worst / FRAC_PI_2).max(0.0)
}

/// eta of the quad `[s0, o1, s1, o0]` made of triangles `(s0, s1, o0)` and `(s1, s0, o1)`
/// sharing the diagonal `s0`–`s1`. At the diagonal's endpoints the angle is the *sum* of the
/// two triangles' angles there (3D angles, so surface meshes work); at the opposite vertices it
/// is the triangle's own angle. A pair folded over its diagonal (`o1` on `o0`'s side in the
/// plane; on a surface, the triangles' normals 90 degrees apart or more, where Gmsh's minSICN
/// of the quad turns negative) makes no quad: its eta is 0, although the sums of unsigned
/// angles would read as those of the unfolded quad. On a planar pair that is not folded, eta
/// > 0 is exactly strict convexity.
pub fn quad_eta(p: [[f64; 3]; 4]) -> f64 {
    let [s0, o1, s1, o0] = p;
    let a0 = angle(s0, s1, o0) + angle(s0, o1, s1);
    let a1 = angle(o1, s0, s1);
    let a2 = angle(s1, o0, s0) + angle(s1, s0, o1);
    let a3 = angle(o0, s1, s0);
    let eta = eta_from_angles([a0, a1, a2, a3]);
    if eta > 0.0 && folded(p) {
        return 0.0;
    }
    eta
}

/// Whether the two triangles of the quad `[s0, o1, s1, o0]` (as for [`quad_eta`]) are bent
/// over their diagonal by a right angle or more: their normals, in the orientation they share
/// in the mesh, make an angle of 90 degrees or more (they point away from each other). In a
/// plane, the second triangle lies folded back over the first (the two overlap).
pub fn folded(p: [[f64; 3]; 4]) -> bool {
    use crate::mesh::topology::{cross, dot, sub};
    let [s0, o1, s1, o0] = p;
    let n0 = cross(unit_range(sub(s1, s0)), unit_range(sub(o0, s0)));
    let n1 = cross(unit_range(sub(s0, s1)), unit_range(sub(o1, s1)));
    dot(unit_range(n0), unit_range(n1)) <= 0.0
}

/// The cosine of the angle between the normals of the two triangles of the quad `[s0, o1,
/// s1, o0]` (as for [`quad_eta`]), in the orientation they share in the mesh: 1 flat, 0 at a
/// right angle, -1 folded flat back over each other.
pub fn normals_cos(p: [[f64; 3]; 4]) -> f64 {
    use crate::mesh::topology::{cross, dot, sub};
    let [s0, o1, s1, o0] = p;
    let n0 = cross(unit_range(sub(s1, s0)), unit_range(sub(o0, s0)));
    let n1 = cross(unit_range(sub(s0, s1)), unit_range(sub(o1, s1)));
    let (n0, n1) = (unit_range(n0), unit_range(n1));
    let scale = crate::mesh::topology::norm(n0) * crate::mesh::topology::norm(n1);
    if scale > 0.0 {
        dot(n0, n1) / scale
    } else {
        1.0
    }
}

/// eta of a quad given as a cycle of four corners, as a mesh file holds it: eq. 1 on its four
/// corner angles (the angle between the two sides meeting at each corner), whichever diagonal
/// a writer had in mind. A corner that turns against the quad's orientation (a reflex corner,
/// or one lobe of a self-intersecting "bowtie") has an interior angle above pi: eta 0. The
/// orientation is the quad's vector area (Newell's normal), so curved-surface quads work.
/// Recombined candidates are read across their diagonal instead ([`quad_eta`]): on a planar
/// quad both give the same value (both 0 for a pair folded over its diagonal).
pub fn input_quad_eta(p: [[f64; 3]; 4]) -> f64 {
    match unit_corners(p) {
        Some(q) => {
            eta_from_angles([0, 1, 2, 3].map(|k| angle(q[k], q[(k + 3) % 4], q[(k + 1) % 4])))
        }
        None => 0.0,
    }
}

/// The quad's corners relative to its centroid, scaled to unit size (so that neither the
/// products nor the tolerance depend on the coordinates' magnitude), when every corner turns
/// the way of the quad's vector area (Newell's normal); `None` when one does not (a reflex
/// corner, a bowtie's lobe, a twisted non-planar quad) or the quad is degenerate.
fn unit_corners(p: [[f64; 3]; 4]) -> Option<[[f64; 3]; 4]> {
    use crate::mesh::topology::{cross, dot, sub};
    let c = [0, 1, 2].map(|k| p.iter().map(|v| v[k]).sum::<f64>() / 4.0);
    let rel = p.map(|v| sub(v, c));
    let m = rel.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    if m == 0.0 || !m.is_finite() {
        return None;
    }
    let q = rel.map(|v| v.map(|x| x / m));
    let mut normal = [0.0; 3];
    for k in 0..4 {
        let x = cross(q[k], q[(k + 1) % 4]);
        normal = [normal[0] + x[0], normal[1] + x[1], normal[2] + x[2]];
    }
    (0..4)
        .all(|k| {
            let (prev, here, next) = (q[(k + 3) % 4], q[k], q[(k + 1) % 4]);
            dot(cross(sub(here, prev), sub(next, here)), normal) > 0.0
        })
        .then_some(q)
}

/// Which pairs of neighbouring triangles may be merged: the actions of every policy and the
/// edges of the optimum's matching.
///
/// A quad with a corner angle `>= pi` (eta = 0 in eq. 1: not strictly convex, or folded) is no
/// element a finite-element solver accepts, so by default it is not an action at all. The
/// decision is taken on the f64 reference eta ([`quad_eta`]), whatever computed the rewards,
/// so every backend allows the same pairs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rule {
    /// Only quads with eta > 0 (strictly convex, not folded) and eta >= `min_eta`.
    Valid {
        /// Lowest eta of a quad that may be made; 0 means any strictly convex quad.
        min_eta: f64,
    },
    /// Every pair of neighbouring triangles, eta-0 quads included (reward 0): the paper as
    /// written, under which the earlier results were made (`--allow-invalid`).
    AllPairs,
}

impl Default for Rule {
    fn default() -> Rule {
        Rule::Valid { min_eta: 0.0 }
    }
}

impl Rule {
    /// The rule from its two settings: `allow_invalid` keeps every pair (and then
    /// `min_eta` must be 0), else the valid-quad rule with threshold `min_eta` in `[0, 1]`.
    pub fn new(min_eta: f64, allow_invalid: bool) -> Result<Rule, RuleError> {
        if !(0.0..=1.0).contains(&min_eta) {
            return Err(RuleError::MinEtaRange(min_eta));
        }
        match (allow_invalid, min_eta > 0.0) {
            (true, true) => Err(RuleError::Conflict(min_eta)),
            (true, false) => Ok(Rule::AllPairs),
            (false, _) => Ok(Rule::Valid { min_eta }),
        }
    }

    /// The threshold: 0 for [`Rule::AllPairs`].
    pub fn min_eta(&self) -> f64 {
        match *self {
            Rule::Valid { min_eta } => min_eta,
            Rule::AllPairs => 0.0,
        }
    }

    /// True for [`Rule::AllPairs`].
    pub fn allows_invalid(&self) -> bool {
        matches!(self, Rule::AllPairs)
    }

    /// Does the rule allow a quad of f64 quality `eta`? Under the valid-quad rule "eta > 0"
    /// means above [`FLAT_ETA`]: a quad whose corner is 180 degrees to within rounding is no
    /// strictly convex quad. A pair's quad needs [`Rule::allows_pair`] too.
    #[inline]
    pub fn allows(&self, eta: f64) -> bool {
        match *self {
            Rule::Valid { min_eta } => eta > FLAT_ETA && eta >= min_eta,
            Rule::AllPairs => true,
        }
    }

    /// Does the rule allow the pair whose quad `[s0, o1, s1, o0]` has f64 quality `eta`
    /// ([`quad_eta`])? Under the valid-quad rule, besides [`Rule::allows`], every corner must
    /// turn the way of the quad's own vector area (Newell's normal), as
    /// [`input_quad_eta`] reads a quad: a non-planar pair can be folded little across its
    /// diagonal (eta > 0) yet twisted across the other one, and Gmsh reads that quad as
    /// inverted (negative Jacobian; a review's pair folded 16 degrees across one diagonal and
    /// 98 across the other, minSICN -0.175). On a planar pair eta > 0 implies it.
    #[inline]
    pub fn allows_pair(&self, eta: f64, quad: [[f64; 3]; 4]) -> bool {
        self.allows(eta) && (self.allows_invalid() || unit_corners(quad).is_some())
    }

    /// [`Rule::allows_pair`] with the quad's eta computed here. The same answer, but for
    /// most quads without eq. 1's six arctangents: a quad whose corners are clear of 0 and pi
    /// (`corners_clear`) has eta > [`FLAT_ETA`] unless folded, one with a reflex corner
    /// has eta 0, and only a quad within 1e-9 of either (or degenerate) is measured. The
    /// arctangents were most of the valid-quad rule's cost outside the search: a fifth of
    /// `recombine`'s time on a 10^5-triangle grid.
    pub fn allows_quad(&self, quad: [[f64; 3]; 4]) -> bool {
        match *self {
            Rule::AllPairs => true,
            Rule::Valid { min_eta } => match corners_clear(quad) {
                Some(false) => false,
                Some(true) if min_eta == 0.0 => !folded(quad) && unit_corners(quad).is_some(),
                _ => self.allows_pair(quad_eta(quad), quad),
            },
        }
    }
}

/// Whether eq. 1's four corner angles of the quad `[s0, o1, s1, o0]` (as [`quad_eta`] sums
/// them) all lie clear inside `(0, pi)` (`Some(true)`: eta before the fold test is above
/// [`FLAT_ETA`]), or one lies clear beyond pi (`Some(false)`: eta 0), decided on their sines
/// with a margin of 1e-9, a million times the rounding of unit vectors; `None` when a corner
/// is within the margin of 0 or pi, or a side is degenerate or not finite. Sides are
/// rescaled as [`angle`] rescales them, so any scale is decided alike. No arctangent:
/// the sine of a corner made of two triangle angles is `sin a cos b + cos a sin b`.
fn corners_clear(p: [[f64; 3]; 4]) -> Option<bool> {
    use crate::mesh::topology::{cross, dot, sub};
    const MARGIN: f64 = 1e-9;
    let [s0, o1, s1, o0] = p;
    let ray = |from: [f64; 3], to: [f64; 3]| unit_range(sub(to, from));
    let norm = |v: [f64; 3]| dot(v, v).sqrt();
    let mut reflex = false;
    // The corners at the diagonal's ends: two triangle angles each, between the diagonal
    // `d` and the rays `a` and `b`. With `|d x a| = |d| |a| sin` and `d . a = |d| |a| cos`,
    // `|d|^2 |a| |b| sin(a + b) = |d x a| (d . b) + (d . a) |d x b|`: no division.
    for (at, other, a, b) in [(s0, s1, o0, o1), (s1, s0, o0, o1)] {
        let (d, a, b) = (ray(at, other), ray(at, a), ray(at, b));
        let sin = norm(cross(d, a)) * dot(d, b) + dot(d, a) * norm(cross(d, b));
        let scale = MARGIN * dot(d, d) * (dot(a, a) * dot(b, b)).sqrt();
        if sin < -scale {
            reflex = true;
        } else if !(sin > scale && scale > 0.0 && scale.is_finite()) {
            return None;
        }
    }
    // The opposite corners: one triangle angle each, in [0, pi]: `|a x b|^2 = |a|^2 |b|^2
    // sin^2`.
    for (at, a, b) in [(o1, s0, s1), (o0, s1, s0)] {
        let (a, b) = (ray(at, a), ray(at, b));
        let c = cross(a, b);
        let scale = MARGIN * MARGIN * dot(a, a) * dot(b, b);
        if !(dot(c, c) > scale && scale > 0.0 && scale.is_finite()) {
            return None;
        }
    }
    Some(!reflex)
}

/// eta at or below which a quad is flat to within rounding: a corner of 180 degrees (a node
/// at the midpoint of its neighbours, as Gmsh's meshers place some) comes out of eq. 1 in
/// f64 as eta 0 or as a few units of 1e-16 to 1e-15 (5.6e-16 to 8.8e-15 on the suite's
/// plate meshes and on a shell a review found, where all-quad's halves of such a quad then
/// read as eta 0 and failed). 1e-12, a corner within 1.6e-12 radians of 180 degrees, is a
/// thousand times that noise; no eta of `borouchaki`, `sphere` or the generated grids lies
/// between 0 and 1e-9.
pub const FLAT_ETA: f64 = 1e-12;

/// The rule in words, as outputs and reports print it: `valid quads (eta > 0)`, `valid
/// quads, eta >= 0.3`, `all pairs, eta-0 quads included (paper-literal)`.
impl std::fmt::Display for Rule {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Rule::Valid { min_eta } if min_eta > 0.0 => write!(f, "valid quads, eta >= {min_eta}"),
            Rule::Valid { .. } => f.write_str("valid quads (eta > 0)"),
            Rule::AllPairs => f.write_str("all pairs, eta-0 quads included (paper-literal)"),
        }
    }
}

/// Settings that make no [`Rule`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RuleError {
    #[error("the lowest eta must lie in [0, 1], not {0:?}")]
    MinEtaRange(f64),
    #[error("a lowest eta of {0:?} contradicts allowing invalid quads (which allows every pair)")]
    Conflict(f64),
}

/// The candidate table: one entry per pair of neighbouring triangles (dual-graph edge).
///
/// Candidates are numbered in order of their lower triangle, then side. `quads[c]` lists the
/// quad's vertices in order `[s0, o1, s1, o0]`: the diagonal (shared edge) is `quads[c][0]`–
/// `quads[c][2]`, and `pairs[c] = [t0, t1]` with `t0 < t1`, `t0 = (s0, s1, o0)`.
#[derive(Debug, Clone, Default)]
pub struct CandidateTable {
    /// The two triangles of each candidate, lower index first.
    pub pairs: Vec<[u32; 2]>,
    /// The quad's four vertices, diagonal at positions 0 and 2.
    pub quads: Vec<[u32; 4]>,
    /// Quality eta of each candidate quad, in `[0, 1]`.
    pub eta: Vec<f64>,
    /// For each triangle, the candidate across each of its sides, or [`NONE`].
    pub by_triangle: Vec<[u32; 3]>,
}

impl CandidateTable {
    /// The table's topology (pairs, quads, `by_triangle`) with eta left at zero, for a device
    /// to fill.
    pub fn topology_only(mesh: &Mesh) -> CandidateTable {
        let nt = mesh.num_triangles();
        let n = mesh.topology.num_dual_edges();
        let mut table = CandidateTable {
            pairs: Vec::with_capacity(n),
            quads: Vec::with_capacity(n),
            eta: vec![0.0; n],
            by_triangle: vec![[NONE; 3]; nt],
        };
        for t in 0..nt {
            for i in 0..3 {
                let u = mesh.topology.neighbours[t][i];
                if u == NONE || (u as usize) < t {
                    continue;
                }
                let tri = mesh.triangles[t];
                let (s0, s1, o0) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
                let other = mesh.triangles[u as usize];
                let j = (0..3)
                    .find(|&j| mesh.topology.neighbours[u as usize][j] == t as u32)
                    .expect("symmetric dual graph");
                let o1 = other[(j + 2) % 3];
                let c = table.pairs.len() as u32;
                table.pairs.push([t as u32, u]);
                table.quads.push([s0, o1, s1, o0]);
                table.by_triangle[t][i] = c;
                table.by_triangle[u as usize][j] = c;
            }
        }
        table
    }

    /// Whether this table can be `mesh`'s: one entry per triangle, and a few candidates
    /// (first, middle, last) whose quads are made of their pairs' vertices. O(1): it tells a
    /// table of another mesh apart, not every corruption.
    pub fn fits(&self, mesh: &Mesh) -> bool {
        if self.by_triangle.len() != mesh.num_triangles()
            || self.quads.len() != self.pairs.len()
            || self.eta.len() != self.pairs.len()
        {
            return false;
        }
        let n = self.pairs.len();
        let nt = mesh.num_triangles() as u32;
        [0, n / 2, n.wrapping_sub(1)]
            .into_iter()
            .filter(|&c| c < n)
            .all(|c| {
                let [a, b] = self.pairs[c];
                a < nt && b < nt && {
                    let (ta, tb) = (mesh.triangles[a as usize], mesh.triangles[b as usize]);
                    self.quads[c]
                        .iter()
                        .all(|v| ta.contains(v) || tb.contains(v))
                }
            })
    }

    /// Panics, naming both sizes, when [`Self::fits`] says this table is not `mesh`'s.
    #[track_caller]
    pub fn assert_fits(&self, mesh: &Mesh) {
        assert!(
            self.fits(mesh),
            "the candidate table ({} triangles, {} candidates) was not built for this mesh ({} \
             triangles): build it with CandidateTable::build(&mesh)",
            self.by_triangle.len(),
            self.pairs.len(),
            mesh.num_triangles()
        );
    }

    /// The full table with eta computed in f64 on the CPU (the reference): every pair of
    /// neighbouring triangles, eta-0 quads included (the paper-literal problem,
    /// `--allow-invalid`). The command line's default, the valid-quad rule, is
    /// `CandidateTable::build(&mesh).restrict(&mesh, Rule::default())` ([`Self::restrict`]).
    pub fn build(mesh: &Mesh) -> CandidateTable {
        let mut table = CandidateTable::topology_only(mesh);
        table.eta = table
            .quads
            .iter()
            .map(|q| quad_eta(q.map(|v| mesh.vertices[v as usize])))
            .collect();
        table
    }

    /// The table of the candidates `rule` allows, in the same order (so indices shift past
    /// each dropped one); the dropped pairs are no neighbours in its dual graph
    /// ([`CandidateTable::dual_graph`]). Validity is decided on the f64 eta of each quad,
    /// computed here, so the result does not depend on what filled `eta`.
    pub fn restrict(self, mesh: &Mesh, rule: Rule) -> CandidateTable {
        self.assert_fits(mesh);
        if rule == Rule::AllPairs {
            return self;
        }
        // On every core, as the CPU twin fills eta (`gpu::layout`).
        use rayon::prelude::*;
        let keep: Vec<bool> = self
            .quads
            .par_iter()
            .with_min_len(1 << 12)
            .map(|q| rule.allows_quad(q.map(|v| mesh.vertices[v as usize])))
            .collect();
        self.retain(&keep)
    }

    /// The table of the candidates `c` with `keep[c]`, in the same order.
    pub fn retain(self, keep: &[bool]) -> CandidateTable {
        assert_eq!(keep.len(), self.len(), "one flag per candidate");
        if keep.iter().all(|&k| k) {
            return self;
        }
        let mut new_index = vec![NONE; self.len()];
        // Sized once: grown by doubling, the arrays kept up to 2x their length for the
        // whole run (a grid's table is most of a 10^6-triangle run's memory after the mesh).
        let n = keep.iter().filter(|&&k| k).count();
        let mut out = CandidateTable {
            pairs: Vec::with_capacity(n),
            quads: Vec::with_capacity(n),
            eta: Vec::with_capacity(n),
            by_triangle: self.by_triangle,
        };
        for c in (0..self.pairs.len()).filter(|&c| keep[c]) {
            new_index[c] = out.pairs.len() as u32;
            out.pairs.push(self.pairs[c]);
            out.quads.push(self.quads[c]);
            out.eta.push(self.eta[c]);
        }
        for sides in &mut out.by_triangle {
            for c in sides.iter_mut().filter(|c| **c != NONE) {
                *c = new_index[*c as usize];
            }
        }
        out
    }

    /// The dual graph the candidates make: for each triangle, the triangle across each side
    /// through a candidate, or [`NONE`]. Without restriction it is the mesh's
    /// (`Topology::neighbours`); after [`CandidateTable::restrict`], the pairs dropped are cut.
    pub fn dual_graph(&self) -> Vec<[u32; 3]> {
        self.by_triangle
            .iter()
            .enumerate()
            .map(|(t, sides)| {
                sides.map(|c| {
                    if c == NONE {
                        NONE
                    } else {
                        self.other(c, t as u32)
                    }
                })
            })
            .collect()
    }

    /// Connected components of [`CandidateTable::dual_graph`] (`dual`): the component of
    /// each triangle, numbered in order of their first triangle, and their sizes. These are
    /// the initial polders.
    pub fn components(dual: &[[u32; 3]]) -> (Vec<u32>, Vec<u32>) {
        let mut component = vec![NONE; dual.len()];
        let mut sizes = Vec::new();
        let mut stack = Vec::new();
        for start in 0..dual.len() {
            if component[start] != NONE {
                continue;
            }
            let id = sizes.len() as u32;
            component[start] = id;
            stack.push(start as u32);
            let mut size = 0u32;
            while let Some(t) = stack.pop() {
                size += 1;
                for &u in &dual[t as usize] {
                    if u != NONE && component[u as usize] == NONE {
                        component[u as usize] = id;
                        stack.push(u);
                    }
                }
            }
            sizes.push(size);
        }
        (component, sizes)
    }

    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    /// True when no two triangles are neighbours.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }

    /// Sum of eta over the candidates `chosen` (eq. 2): 0 for none (not the empty sum's -0).
    pub fn quality_of(&self, chosen: &[u32]) -> f64 {
        chosen.iter().map(|&c| self.eta[c as usize]).sum::<f64>() + 0.0
    }

    /// The triangle paired with `t` by candidate `c`.
    #[inline]
    pub fn other(&self, c: u32, t: u32) -> u32 {
        let [a, b] = self.pairs[c as usize];
        if a == t { b } else { a }
    }
}

/// Element quality of a set of quads beside their sum: the worst, the mean, and how many are
/// poor. A high sum with many triangles left, or with a few near-degenerate quads, is not a
/// better mesh; these say so.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct ElementQuality {
    /// The lowest eta (`None` without quads).
    pub worst: Option<f64>,
    /// The mean eta (`None` without quads).
    pub mean: Option<f64>,
    /// Quads with eta < 0.1.
    pub below_0_1: usize,
    /// Quads with eta < 0.3.
    pub below_0_3: usize,
}

impl ElementQuality {
    /// The figures of quads of quality `eta`.
    pub fn of(eta: impl IntoIterator<Item = f64>) -> ElementQuality {
        let (mut n, mut sum, mut worst) = (0usize, 0.0, f64::INFINITY);
        let mut out = ElementQuality::default();
        for e in eta {
            n += 1;
            sum += e;
            worst = worst.min(e);
            out.below_0_1 += usize::from(e < 0.1);
            out.below_0_3 += usize::from(e < 0.3);
        }
        if n > 0 {
            out.worst = Some(worst);
            out.mean = Some(sum / n as f64);
        }
        out
    }

    /// The figures of the candidates `chosen` of `table`.
    pub fn of_chosen(table: &CandidateTable, chosen: &[u32]) -> ElementQuality {
        ElementQuality::of(chosen.iter().map(|&c| table.eta[c as usize]))
    }
}

/// The recombined mesh given by the chosen candidates (a matching: no triangle twice).
///
/// # Panics
/// When `table` is not `mesh`'s ([`CandidateTable::assert_fits`]), a candidate is out of
/// range, or two candidates share a triangle (they would make overlapping quads).
pub fn recombined(mesh: &Mesh, table: &CandidateTable, chosen: &[u32]) -> Recombined {
    table.assert_fits(mesh);
    let mut used = vec![false; mesh.num_triangles()];
    let mut out = Recombined::default();
    for &c in chosen {
        assert!(
            (c as usize) < table.len(),
            "candidate {c} does not exist (the table has {})",
            table.len()
        );
        let [a, b] = table.pairs[c as usize];
        assert!(
            !used[a as usize] && !used[b as usize],
            "candidate {c} reuses triangle {} of an earlier chosen candidate: not a matching",
            if used[a as usize] { a } else { b }
        );
        used[a as usize] = true;
        used[b as usize] = true;
        out.quads.push(table.quads[c as usize]);
        out.quad_surface.push(mesh.triangle_surface[a as usize]);
        out.quad_eta.push(table.eta[c as usize]);
    }
    out.leftover = (0..mesh.num_triangles() as u32)
        .filter(|&t| !used[t as usize])
        .collect();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rotates `p` about the x axis by `theta` (radians).
    fn about_x(p: [f64; 3], theta: f64) -> [f64; 3] {
        let (s, c) = theta.sin_cos();
        [p[0], c * p[1] - s * p[2], s * p[1] + c * p[2]]
    }

    /// A pair whose corner at the diagonal's end `s1` is 180 degrees (s1 the midpoint of the
    /// two outer corners, as in the review's shell: nodes 112, 439, 24) reads as eta 0 or a
    /// rounding speck; the valid-quad rule takes neither, and still takes a corner of 179.9.
    /// `allows_quad` decides most quads on sines ([`corners_clear`]); it must answer as eq.
    /// 1's arctangents do, [`Rule::allows_pair`] of [`quad_eta`], on every quad: random
    /// planar and non-planar pairs, corners within 1e-6 to 1e-16 of 0 and of pi, degenerate
    /// sides, and coordinates from 1e-200 to 1e200 (whose products leave f64's range).
    #[test]
    fn validity_on_sines_answers_as_the_arctangents_do() {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let rules = [
            Rule::default(),
            Rule::Valid { min_eta: 0.3 },
            Rule::Valid { min_eta: 1e-12 },
            Rule::AllPairs,
        ];
        let mut by_path = [0usize; 3];
        for i in 0..200_000 {
            let mut r = |k: f64| rng.random_range(-k..k);
            let (s0, s1) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]);
            let z = if i % 3 == 0 { 0.5 } else { 0.0 };
            let mut o0 = [r(1.5) + 0.5, r(1.0), r(1.0) * z];
            let mut o1 = [r(1.5) + 0.5, r(1.0), r(1.0) * z];
            match i % 7 {
                // A corner at s0 within `eps` of pi: o1 on the ray from o0 through s0.
                0 | 1 => {
                    let eps = [1e-6, 1e-9, 1e-10, 1e-12, 1e-14, 1e-16, 0.0][i / 7 % 7];
                    let t = r(1.0).abs() + 0.1;
                    o1 = [-o0[0] * t, -o0[1] * t + eps * r(1.0), -o0[2] * t];
                }
                // An opposite corner within `eps` of 0 or pi (o0 on the line of s0 and s1).
                2 => {
                    let eps = [1e-6, 1e-9, 1e-12, 1e-15, 0.0][i / 7 % 5];
                    o0 = [r(2.0) + 0.5, eps * r(1.0), 0.0];
                }
                // Degenerate: o1 on s0.
                3 if i % 2 == 0 => o1 = s0,
                _ => {}
            }
            let scale = [1.0, 1e-200, 1e200, 1e-150, 1e150][i % 5];
            let q = [s0, o1, s1, o0].map(|v| v.map(|x| x * scale));
            by_path[match corners_clear(q) {
                Some(true) => 0,
                Some(false) => 1,
                None => 2,
            }] += 1;
            for rule in rules {
                assert_eq!(
                    rule.allows_quad(q),
                    rule.allows_pair(quad_eta(q), q),
                    "{rule:?} on {q:?}"
                );
            }
        }
        // Every path was taken, most quads decided without arctangents.
        assert!(by_path.iter().all(|&n| n > 1000), "{by_path:?}");
        assert!(by_path[2] < by_path[0] + by_path[1], "{by_path:?}");
    }

    #[test]
    fn a_quad_flat_to_within_rounding_is_not_valid() {
        let mut rng = 0x2545F4914F6CDD1Du64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut specks, rule) = (0, Rule::default());
        for _ in 0..2000 {
            let p: [f64; 3] = [next(), next(), next()];
            let q: [f64; 3] = [next(), next(), next()];
            let s0: [f64; 3] = [next(), next(), next()];
            let mid = [0, 1, 2].map(|k| (p[k] + q[k]) / 2.0);
            let eta = quad_eta([s0, q, mid, p]);
            assert!(eta < 1e-13, "{eta}");
            specks += usize::from(eta > 0.0);
            assert!(!rule.allows(eta), "{eta}");
        }
        // Without the tolerance some of these would be taken as valid quads.
        assert!(specks > 0, "no rounding speck in 2000 flat quads");
        // A kite with a corner of about 179.9 degrees is a valid (poor) quad.
        let kite = [
            [0.0, 0.0, 0.0],
            [0.5, -0.5, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 0.0009, 0.0],
        ];
        let eta = quad_eta(kite);
        assert!(eta > 1e-4 && rule.allows(eta), "{eta}");
    }

    /// A review's non-planar pair (two triangles of a Gmsh 2.2 file, nodes 5, 1, 4, 8 around
    /// the quad, diagonal 5-4): folded about 16 degrees across the diagonal, so eta > 0, but
    /// 98 degrees across the other one; Gmsh read the quad as inverted (minDetJac -0.00037,
    /// minSICN -0.175). The valid-quad rule takes no such pair; the paper-literal rule does.
    #[test]
    fn a_pair_twisted_across_its_other_diagonal_is_not_valid() {
        let n5 = [0.63244283, 0.59694155, -0.17357868];
        let n8 = [0.38724872, 1.13308151, 0.0];
        let n4 = [0.12380746, 0.43987724, 0.04717726];
        let n1 = [-0.03541345, 0.13262932, 0.0];
        for p in [[n5, n1, n4, n8], [n4, n8, n5, n1]] {
            let eta = quad_eta(p);
            assert!(eta > 1e-4 && Rule::default().allows(eta), "{eta}");
            assert_eq!(input_quad_eta(p), 0.0, "a corner turns against the quad");
            assert!(!Rule::default().allows_pair(eta, p));
            assert!(Rule::AllPairs.allows_pair(eta, p));
        }
        // A planar kite, and the same kite bent 30 degrees across its diagonal, are valid.
        let kite = [
            [0.0, 0.0, 0.0],
            [0.5, -0.5, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 0.8, 0.0],
        ];
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        let mut bent = kite;
        bent[3] = [0.5, 0.8 * c, 0.8 * s];
        for p in [kite, bent] {
            assert!(Rule::default().allows_pair(quad_eta(p), p), "{p:?}");
        }
    }

    #[test]
    fn a_pair_folded_over_its_diagonal_makes_no_quad() {
        // The diagonal s0 = (0, 0)-s1 = (1, 0); o0 = (0.5, 1) above it. With o1 = (0.5, -0.5)
        // below, a convex kite; with o1 = (0.5, 0.5), on o0's side, the second triangle lies
        // folded over the first, yet the sums of unsigned angles read as the kite's.
        let [s0, s1, o0] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 1.0, 0.0]];
        let kite = quad_eta([s0, [0.5, -0.5, 0.0], s1, o0]);
        assert!(kite > 0.5, "{kite}");
        assert_eq!(quad_eta([s0, [0.5, 0.5, 0.0], s1, o0]), 0.0);
        assert_eq!(input_quad_eta([s0, [0.5, 0.5, 0.0], s1, o0]), 0.0);
        // Bent about the diagonal (the x axis): the same angles, so the same eta, while the
        // triangles' normals stay less than 90 degrees apart; none from 90 degrees on.
        for (deg, same) in [(30.0, true), (80.0, true), (100.0, false), (150.0, false)] {
            let o1 = about_x([0.5, -0.5, 0.0], f64::to_radians(deg));
            let eta = quad_eta([s0, o1, s1, o0]);
            if same {
                assert!((eta - kite).abs() < 1e-12, "bent {deg}: {eta} vs {kite}");
            } else {
                assert_eq!(eta, 0.0, "bent {deg} degrees");
            }
        }
    }

    #[test]
    fn unit_square_has_eta_one() {
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        assert!((quad_eta(p) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn rhombus_60_degrees() {
        // Angles 60 and 120: worst deviation 30 degrees -> eta = 1 - 30/90 = 2/3.
        let h = 3f64.sqrt() / 2.0;
        let p = [
            [0.0, 0.0, 0.0],
            [0.5, -h, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, h, 0.0],
        ];
        assert!((quad_eta(p) - 2.0 / 3.0).abs() < 1e-12, "{}", quad_eta(p));
    }

    #[test]
    fn non_convex_quad_has_eta_zero() {
        // Dart: the diagonal endpoint s1 sees a reflex angle.
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, -1.0, 0.0],
            [0.3, 0.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        assert_eq!(quad_eta(p), 0.0);
    }

    #[test]
    fn input_quads_that_cross_themselves_have_eta_zero() {
        let [a, b, c, d] = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        assert_eq!(input_quad_eta([a, b, c, d]), 1.0);
        // Corners 1, 3, 2, 4: the halves about the diagonal overlap, a 180-degree fold:
        // quad_eta gives 0 too (its sums of unsigned angles alone read 0.5).
        assert_eq!(quad_eta([a, c, b, d]), 0.0);
        assert_eq!(input_quad_eta([a, c, b, d]), 0.0);
    }

    #[test]
    fn input_quads_are_read_by_their_corners_not_a_diagonal() {
        // A kite whose diagonal 1-3 makes two different triangles than 2-4: read from any
        // starting corner, in either direction, it has the same eta (the corners' angles).
        let kite = [
            [0.0, 0.0, 0.0],
            [2.0, -0.5, 0.0],
            [3.0, 0.3, 0.0],
            [1.0, 1.7, 0.0],
        ];
        let want = input_quad_eta(kite);
        assert!(want > 0.2 && want < 0.9, "{want}");
        for shift in 0..4 {
            let p: [[f64; 3]; 4] = std::array::from_fn(|k| kite[(k + shift) % 4]);
            let r: [[f64; 3]; 4] = std::array::from_fn(|k| p[3 - k]);
            assert!((input_quad_eta(p) - want).abs() < 1e-12);
            assert!((input_quad_eta(r) - want).abs() < 1e-12);
        }
        // On a planar convex quad, the same as the candidate reading across 1-3.
        assert!((quad_eta(kite) - want).abs() < 1e-12);
        // A dart: reflex corner at index 2, whichever diagonal is taken.
        let dart = [
            [0.0, 0.0, 0.0],
            [1.0, -1.0, 0.0],
            [0.3, 0.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        for shift in 0..4 {
            let p: [[f64; 3]; 4] = std::array::from_fn(|k| dart[(k + shift) % 4]);
            assert_eq!(input_quad_eta(p), 0.0);
        }
        // The same dart read across its other diagonal (corners 2-4) is a pair folded over
        // it, which the sums of unsigned angles alone read as convex: 0 as well.
        let p: [[f64; 3]; 4] = std::array::from_fn(|k| dart[(k + 1) % 4]);
        assert_eq!(quad_eta(p), 0.0);
    }

    #[test]
    fn eta_does_not_depend_on_the_scale() {
        // A jittered quad and the 60-degree rhombus, scaled from 1e-300 to 1e300: eta within
        // rounding of the unscaled value (before the rescaling, squares under- or overflowed
        // past 1e-77 and 1e77: eta 0, or 1 - 5e-13 instead of 1).
        let h = 3f64.sqrt() / 2.0;
        for p in [
            [
                [0.0, 0.0, 0.0],
                [0.5, -h, 0.0],
                [1.0, 0.0, 0.0],
                [0.5, h, 0.0],
            ],
            [
                [0.1, -0.05, 0.0],
                [1.02, 0.03, 0.01],
                [0.97, 1.1, -0.02],
                [-0.04, 0.93, 0.0],
            ],
        ] {
            let want = quad_eta(p);
            assert!(want > 0.5);
            for s in [
                1e-300, 1e-160, 1e-100, 1e-78, 1e-30, 1e30, 1e78, 1e100, 1e160, 1e300,
            ] {
                let q = p.map(|v| v.map(|x| x * s));
                let got = quad_eta(q);
                assert!((got - want).abs() < 1e-12, "scale {s:e}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn folded_quad_uses_intrinsic_3d_angles() {
        // The unit square's triangle (0,0,0), (1,1,0), (0,1,0) turned about the diagonal
        // (0,0,0)-(1,1,0) by theta: every 3D angle is still 90 degrees, so eta stays 1 (a
        // planar projection would not) while the triangles' normals are less than 90 degrees
        // apart; from 90 degrees on the pair is folded, no quad (Gmsh's minSICN of such a quad
        // changes sign there too: 0.8 at 89 degrees, -0.8 at 91).
        let z = std::f64::consts::FRAC_1_SQRT_2;
        for (deg, want) in [
            (0.0, 1.0),
            (60.0, 1.0),
            (89.0, 1.0),
            (91.0, 0.0),
            (120.0, 0.0),
        ] {
            let (s, c) = f64::to_radians(deg).sin_cos();
            let o0 = [0.5 - 0.5 * c, 0.5 + 0.5 * c, z * s];
            let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], o0];
            assert!((quad_eta(p) - want).abs() < 1e-12, "{deg}: {}", quad_eta(p));
        }
    }
}
