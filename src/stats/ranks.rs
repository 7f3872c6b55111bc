//! Comparing several methods over several blocks (here: meshes), one value per method and
//! block (a per-mesh median): Friedman's test with its Iman–Davenport F form, the average
//! ranks, Nemenyi's critical difference, and the Wilcoxon signed-rank test of every pair of
//! methods over the blocks with Holm's correction (Demšar, "Statistical comparisons of
//! classifiers over multiple data sets", JMLR 7, 2006).
//!
//! Ranks go from 1 (the largest value of a block: the best, for a quality) to k; tied values
//! share the average of their ranks. The statistic follows `scipy.stats.friedmanchisquare`
//! (with its tie correction), which ranks the other way round: the statistic is the same.

use super::compare::{SignedRank, holm, ranks, signed_rank};
use super::dist::{chi2_sf, f_sf};

/// Ranks of one block's values, 1 for the largest, ties averaged; and the sizes of the tie
/// groups.
pub fn block_ranks(values: &[f64]) -> (Vec<f64>, Vec<usize>) {
    let (r, ties) = ranks(values.iter().map(|v| -v));
    (r, ties)
}

/// Friedman's test of `k` methods over `n` blocks.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Friedman {
    /// Blocks (meshes), `n`.
    pub blocks: usize,
    /// Methods, `k`.
    pub methods: usize,
    /// Each method's average rank over the blocks (1 is best).
    pub average_ranks: Vec<f64>,
    /// Friedman's chi-square statistic, corrected for ties as scipy does.
    pub chi2: f64,
    /// Its p-value: chi-square with `k - 1` degrees of freedom.
    pub p: f64,
    /// Iman and Davenport's `F = (n-1) chi2 / (n(k-1) - chi2)` (infinite when every block ranks
    /// the methods the same way without ties).
    pub f: f64,
    /// Degrees of freedom of `F`: `k - 1` and `(k-1)(n-1)`.
    pub f_df: (f64, f64),
    /// The p-value of `F` (less conservative than the chi-square one).
    pub p_f: f64,
}

/// Friedman's test of `values[block][method]`. `None` with fewer than 2 blocks or 2
/// methods, blocks of different lengths, or a value that is not finite.
pub fn friedman(values: &[Vec<f64>]) -> Option<Friedman> {
    let n = values.len();
    let k = values.first()?.len();
    if n < 2
        || k < 2
        || values
            .iter()
            .any(|b| b.len() != k || b.iter().any(|v| !v.is_finite()))
    {
        return None;
    }
    let mut sums = vec![0.0; k];
    let mut ties = 0.0;
    for block in values {
        let (r, t) = block_ranks(block);
        for (s, r) in sums.iter_mut().zip(r) {
            *s += r;
        }
        ties += t
            .iter()
            .map(|&t| {
                let t = t as f64;
                t * (t * t - 1.0)
            })
            .sum::<f64>();
    }
    let (nf, kf) = (n as f64, k as f64);
    let c = 1.0 - ties / (kf * (kf * kf - 1.0) * nf);
    let ssbn: f64 = sums.iter().map(|s| s * s).sum();
    let chi2 = if c <= 0.0 {
        // Every block ties every method: no evidence of any difference.
        0.0
    } else {
        ((12.0 / (kf * nf * (kf + 1.0)) * ssbn - 3.0 * nf * (kf + 1.0)) / c).max(0.0)
    };
    let df = kf - 1.0;
    let f_df = (kf - 1.0, (kf - 1.0) * (nf - 1.0));
    let denom = nf * (kf - 1.0) - chi2;
    let f = if denom <= 0.0 {
        f64::INFINITY
    } else {
        (nf - 1.0) * chi2 / denom
    };
    Some(Friedman {
        blocks: n,
        methods: k,
        average_ranks: sums.iter().map(|s| s / nf).collect(),
        chi2,
        p: chi2_sf(chi2, df),
        f,
        f_df,
        p_f: f_sf(f, f_df.0, f_df.1),
    })
}

/// The smallest p-value Friedman's exact test can give for `k` methods over `n` blocks:
/// every block ranking the methods the same way without ties, `(k!)^(1-n)` (each block's
/// ranking is one of k! equally likely ones under the null hypothesis). Above 0.05, no data
/// of that shape can be significant.
pub fn friedman_min_p(k: usize, n: usize) -> f64 {
    let ln_k_factorial: f64 = (2..=k).map(|i| (i as f64).ln()).sum();
    (-(n.max(1) as f64 - 1.0) * ln_k_factorial).exp().min(1.0)
}

/// The critical values `q_0.05` of the two-tailed Nemenyi test for `k = 2..=20` methods: the
/// studentized range's 95 % quantile with infinite degrees of freedom over sqrt 2 (Demšar's
/// Table 5a up to k = 10). scipy 1.17.1:
/// `[studentized_range.ppf(0.95, k, np.inf) / np.sqrt(2) for k in range(2, 21)]`.
const NEMENYI_Q05: [f64; 19] = [
    1.959964, 2.343701, 2.569032, 2.727774, 2.849705, 2.948320, 3.030878, 3.101730, 3.163684,
    3.218654, 3.268004, 3.312739, 3.353618, 3.391230, 3.426041, 3.458425, 3.488685, 3.517073,
    3.543799,
];

/// Most methods [`nemenyi_cd`] has a critical value for.
pub const NEMENYI_MAX_METHODS: usize = NEMENYI_Q05.len() + 1;

/// Nemenyi's critical difference at 0.05 for `k` methods over `n` blocks:
/// `q_0.05 sqrt(k (k+1) / (6 n))`. Two methods whose average ranks differ by at least this
/// much differ significantly. `None` for `k < 2`, `k >` [`NEMENYI_MAX_METHODS`] or `n = 0`.
pub fn nemenyi_cd(k: usize, n: usize) -> Option<f64> {
    if k < 2 || n == 0 {
        return None;
    }
    let q = *NEMENYI_Q05.get(k - 2)?;
    Some(q * ((k * (k + 1)) as f64 / (6.0 * n as f64)).sqrt())
}

/// Groups of methods that do not differ by Nemenyi's test: the maximal runs of methods, in
/// order of average rank, whose ranks lie within `cd` of each other, as (first, last) indices
/// into `sorted_ranks` (ascending). Runs of one method are left out (what the
/// critical-difference diagram joins with a bar).
pub fn cliques(sorted_ranks: &[f64], cd: f64) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for i in 0..sorted_ranks.len() {
        let mut j = i;
        while j + 1 < sorted_ranks.len() && sorted_ranks[j + 1] - sorted_ranks[i] < cd {
            j += 1;
        }
        // A run inside the previous one is not maximal.
        if j > i && out.last().is_none_or(|&(_, last)| j > last) {
            out.push((i, j));
        }
    }
    out
}

/// The Wilcoxon signed-rank test of two methods over the blocks (paired by block).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PairTest {
    /// Index of the first method.
    pub first: usize,
    /// Index of the second method.
    pub second: usize,
    /// The test of the first's values minus the second's against 0 (zero differences
    /// dropped).
    pub test: SignedRank,
    /// Holm-adjusted p within the family of all pairs.
    pub p_holm: f64,
    /// Smallest two-sided p the test can give with this many non-zero differences
    /// (`2 / 2^n` without ties): above 0.05, it cannot find a difference however large.
    pub p_min: f64,
}

/// The smallest two-sided p of the exact signed-rank test with `n` non-zero differences:
/// every difference of one sign, `2 / 2^n` (1 for `n = 0`).
pub fn signed_rank_min_p(n: usize) -> f64 {
    (2.0 * 0.5f64.powi(n.min(10_000) as i32)).min(1.0)
}

/// Every pair `i < j` of methods of `values[block][method]` tested with the signed-rank test
/// over the blocks, Holm-corrected together. Empty with fewer than 2 methods or ragged blocks.
pub fn pairwise_signed_rank(values: &[Vec<f64>]) -> Vec<PairTest> {
    let k = values.first().map_or(0, Vec::len);
    if k < 2 || values.iter().any(|b| b.len() != k) {
        return Vec::new();
    }
    let mut out = Vec::new();
    for i in 0..k {
        for j in i + 1..k {
            // Zero differences dropped here (Wilcoxon's method), so that the exact
            // distribution of the others is used, as scipy does.
            let d: Vec<f64> = (values.iter().map(|b| b[i] - b[j]))
                .filter(|d| *d != 0.0)
                .collect();
            let test = signed_rank(&d, 0.0);
            out.push(PairTest {
                first: i,
                second: j,
                test,
                p_holm: test.p,
                p_min: signed_rank_min_p(test.n),
            });
        }
    }
    let p: Vec<f64> = out.iter().map(|t| t.test.p).collect();
    for (t, adj) in out.iter_mut().zip(holm(&p)) {
        t.p_holm = adj;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    #[test]
    fn friedman_by_hand() {
        // 3 blocks ranking 3 methods the same way: rank sums 3, 6, 9; chi2 = 12/(3*3*4) *
        // (9+36+81) - 3*3*4 = 42 - 36 = 6; p = exp(-6/2) (2 df); F = 2*6/(3*2-6) = inf.
        let v = vec![
            vec![3.0, 2.0, 1.0],
            vec![30.0, 20.0, 10.0],
            vec![0.3, 0.2, 0.1],
        ];
        let f = friedman(&v).unwrap();
        assert_eq!(f.average_ranks, vec![1.0, 2.0, 3.0]);
        assert!(close(f.chi2, 6.0, 1e-12), "{}", f.chi2);
        assert!(close(f.p, (-3.0f64).exp(), 1e-12));
        assert_eq!(f.f, f64::INFINITY);
        assert_eq!(f.p_f, 0.0);
        // Every value tied: nothing to see.
        let f = friedman(&[vec![1.0, 1.0], vec![2.0, 2.0]]).unwrap();
        assert_eq!((f.chi2, f.p), (0.0, 1.0));
        assert_eq!(f.average_ranks, vec![1.5, 1.5]);
        // Too little to test.
        assert!(friedman(&[vec![1.0, 2.0]]).is_none());
        assert!(friedman(&[vec![1.0], vec![2.0]]).is_none());
        assert!(friedman(&[vec![1.0, 2.0], vec![2.0]]).is_none());
        assert!(friedman(&[vec![1.0, f64::NAN], vec![2.0, 1.0]]).is_none());
    }

    /// Seven meshes, four methods, with ties (a whole block tied but one value, a tied pair).
    const SEVEN_BY_FOUR: [[f64; 4]; 7] = [
        [91.2, 92.5, 93.1, 88.0],
        [90.1, 90.1, 92.0, 87.5],
        [85.3, 86.0, 86.0, 86.0],
        [95.0, 95.5, 96.2, 94.0],
        [70.2, 72.8, 71.9, 69.0],
        [88.8, 89.9, 90.4, 89.0],
        [93.3, 93.0, 94.1, 91.2],
    ];

    #[test]
    fn friedman_and_pairs_match_scipy() {
        // scipy 1.17.1, v = np.array(SEVEN_BY_FOUR), n, k = v.shape:
        //   r = friedmanchisquare(*v.T)            -> (14.16923076923077, 0.002683620491207465)
        //   F = (n-1)*r.statistic/(n*(k-1)-r.statistic); f.sf(F, k-1, (k-1)*(n-1))
        //                                          -> 12.44594594594595, 0.00012077512277861653
        //   np.mean([rankdata(-row) for row in v], axis=0)
        //                                          -> [3.0714, 2.0714, 1.2857, 3.5714]
        //   wilcoxon(v[:, i], v[:, j]).pvalue for i < j
        //                                          -> 0.0625 0.015625 0.078125 0.21875 0.03125 0.03125
        let v: Vec<Vec<f64>> = SEVEN_BY_FOUR.iter().map(|b| b.to_vec()).collect();
        let f = friedman(&v).unwrap();
        assert!(close(f.chi2, 14.16923076923077, 1e-12), "{}", f.chi2);
        assert!(close(f.p, 0.002683620491207465, 1e-9), "{}", f.p);
        assert!(close(f.f, 12.44594594594595, 1e-12), "{}", f.f);
        assert_eq!(f.f_df, (3.0, 18.0));
        assert!(close(f.p_f, 0.00012077512277861653, 1e-9), "{}", f.p_f);
        let want = [43.0 / 14.0, 29.0 / 14.0, 9.0 / 7.0, 25.0 / 7.0];
        for (a, b) in f.average_ranks.iter().zip(want) {
            assert!(close(*a, b, 1e-12), "{:?}", f.average_ranks);
        }
        let pairs = pairwise_signed_rank(&v);
        let p: Vec<f64> = pairs.iter().map(|t| t.test.p).collect();
        let want = [0.0625, 0.015625, 0.078125, 0.21875, 0.03125, 0.03125];
        for (a, b) in p.iter().zip(want) {
            assert!(close(*a, b, 1e-12), "{p:?}");
        }
        // Pair (0, 1) has a zero difference (mesh 2): 6 differences ranked.
        assert_eq!(pairs[0].test.n, 6);
        assert_eq!(pairs[0].p_min, 0.03125);
        // Holm over the 6 pairs: the smallest p times 6.
        assert!(
            close(pairs[1].p_holm, 0.09375, 1e-12),
            "{}",
            pairs[1].p_holm
        );
    }

    #[test]
    fn smallest_friedman_p() {
        // k = 2 over n = 5: 2!^-4 = 1/16; k = 3 over 3: 6^-2 = 1/36; one block: 1.
        assert!(close(friedman_min_p(2, 5), 0.0625, 1e-12));
        assert!(close(friedman_min_p(3, 3), 1.0 / 36.0, 1e-12));
        assert_eq!(friedman_min_p(4, 1), 1.0);
        // By brute force for k = 3, n = 2: of the 36 pairs of rankings, the 6 where both
        // blocks agree give the largest statistic.
        let perms = [
            [1.0, 2.0, 3.0],
            [1.0, 3.0, 2.0],
            [2.0, 1.0, 3.0],
            [2.0, 3.0, 1.0],
            [3.0, 1.0, 2.0],
            [3.0, 2.0, 1.0],
        ];
        let mut stats = Vec::new();
        for a in &perms {
            for b in &perms {
                stats.push(friedman(&[a.to_vec(), b.to_vec()]).unwrap().chi2);
            }
        }
        let max = stats.iter().copied().fold(0.0, f64::max);
        let at_max = stats.iter().filter(|s| (**s - max).abs() < 1e-9).count();
        assert!(close(at_max as f64 / 36.0, friedman_min_p(3, 2), 1e-12));
    }

    #[test]
    fn nemenyi_critical_difference() {
        // Demšar 2006, Section 3.2.2: k = 4 methods over n = 14 data sets, q = 2.569,
        // CD = 2.569 sqrt(4*5/(6*14)) = 1.25.
        let cd = nemenyi_cd(4, 14).unwrap();
        assert!((cd - 1.2536).abs() < 1e-3, "{cd}");
        // k = 2: q is the normal 97.5 % quantile.
        assert!((nemenyi_cd(2, 6).unwrap() - 1.959964 * (1.0f64 / 6.0).sqrt()).abs() < 1e-9);
        assert!(nemenyi_cd(1, 5).is_none());
        assert!(nemenyi_cd(NEMENYI_MAX_METHODS + 1, 5).is_none());
        assert!(nemenyi_cd(3, 0).is_none());
    }

    #[test]
    fn cliques_are_maximal_runs() {
        // Ranks 1, 1.5, 2.2, 4 with CD 1.3: {1, 1.5, 2.2} and nothing joins 4.
        assert_eq!(cliques(&[1.0, 1.5, 2.2, 4.0], 1.3), vec![(0, 2)]);
        // Overlapping runs: {1, 2}, {2, 2.8, 3.1}; {2.8, 3.1} lies inside the second.
        assert_eq!(cliques(&[1.0, 2.0, 2.8, 3.1], 1.2), vec![(0, 1), (1, 3)]);
        assert!(cliques(&[1.0, 3.0, 5.0], 1.0).is_empty());
    }

    #[test]
    fn min_p_of_the_signed_rank_test() {
        assert_eq!(signed_rank_min_p(0), 1.0);
        assert_eq!(signed_rank_min_p(5), 0.0625);
        assert_eq!(signed_rank_min_p(6), 0.03125);
        // Five meshes all one way: p is that minimum.
        let t = pairwise_signed_rank(&[
            vec![2.0, 1.0],
            vec![3.0, 1.5],
            vec![4.0, 1.2],
            vec![5.0, 1.1],
            vec![6.0, 1.3],
        ]);
        assert_eq!(t.len(), 1);
        assert_eq!(t[0].test.p, 0.0625);
        assert_eq!(t[0].p_min, 0.0625);
    }
}
