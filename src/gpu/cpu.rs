//! CPU twin of `shaders/quad_quality.wgsl`: the same function on the same buffer layout, in
//! f32, step for step. It is the oracle in the GPU tests and the fallback when no Vulkan
//! adapter exists. Parallel over candidates with rayon (run it inside a one-thread pool for
//! a serial figure).

use super::layout::{Batch, LocalQuad, Vertex};
use rayon::prelude::*;

const PI: f32 = std::f32::consts::PI;
const FRAC_PI_2: f32 = std::f32::consts::FRAC_PI_2;

type V3 = [f32; 3];

/// `b - a` with hi/lo compensation, scaled so that its largest component is 1.
#[inline]
fn edge(a: &Vertex, b: &Vertex) -> V3 {
    let d: V3 = [0, 1, 2].map(|k| (b.hi[k] - a.hi[k]) + (b.lo[k] - a.lo[k]));
    let m = d[0].abs().max(d[1].abs()).max(d[2].abs());
    if m > 0.0 {
        let s = 1.0 / m;
        d.map(|x| x * s)
    } else {
        [0.0; 3]
    }
}

/// atan(a) for a in [0, 1]: the kernel's degree-15 odd minimax polynomial.
#[inline]
fn atan_unit(a: f32) -> f32 {
    let s = a * a;
    let p = 0.999_999_34
        + s * (-0.333_298_6
            + s * (0.199_465_66
                + s * (-0.139_086_29
                    + s * (0.096_421_95
                        + s * (-0.055_912_3 + s * (0.021_862_94 + s * -0.004_054_56))))));
    a * p
}

/// atan2(y, x) for y >= 0, in [0, pi]; (0, 0) gives 0.
#[inline]
fn atan2_pos(y: f32, x: f32) -> f32 {
    let ax = x.abs();
    let hi = y.max(ax);
    let t = if hi == 0.0 { 0.0 } else { y.min(ax) / hi };
    let mut r = atan_unit(t);
    if y > ax {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    r
}

#[inline]
fn angle(u: V3, v: V3) -> f32 {
    let c = cross(u, v);
    atan2_pos(dot(c, c).sqrt(), dot(u, v))
}

#[inline]
fn neg(u: V3) -> V3 {
    u.map(|x| -x)
}

/// The kernel's edge vectors `[a, e0, e1, f0, f1]` of the quad `[s0, o1, s1, o0]`.
fn quad_edges(s0: &Vertex, o1: &Vertex, s1: &Vertex, o0: &Vertex) -> [V3; 5] {
    [
        edge(s0, s1),
        edge(s0, o0),
        edge(s0, o1),
        edge(s1, o0),
        edge(s1, o1),
    ]
}

/// The kernel's `eta_from_edges` angles from `[a, e0, e1, f0, f1]`.
fn angles_from_edges([a, e0, e1, f0, f1]: [V3; 5]) -> [f32; 4] {
    [
        angle(a, e0) + angle(e1, a),
        angle(e1, f1),
        angle(f0, neg(a)) + angle(neg(a), f1),
        angle(f0, e0),
    ]
}

/// eta of the quad `[s0, o1, s1, o0]`, as the kernel's `quad_eta`.
pub fn quad_eta(s0: &Vertex, o1: &Vertex, s1: &Vertex, o0: &Vertex) -> f32 {
    eta_from_edges(quad_edges(s0, o1, s1, o0))
}

/// The kernel's `eta_from_edges`: 0 for a pair folded over its diagonal (the triangles'
/// normals `a x e0` and `-a x f1` 90 degrees apart or more), else eq. 1 on the angles.
fn eta_from_edges(edges: [V3; 5]) -> f32 {
    let [a, e0, _, _, f1] = edges;
    if dot(cross(a, e0), cross(neg(a), f1)) <= 0.0 {
        return 0.0;
    }
    eta_from_angles(angles_from_edges(edges))
}

#[inline]
fn cross(u: V3, v: V3) -> V3 {
    [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ]
}

#[inline]
fn dot(u: V3, v: V3) -> f32 {
    u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
}

fn eta_from_angles(alpha: [f32; 4]) -> f32 {
    if alpha.iter().any(|&a| a <= 0.0 || a >= PI) {
        return 0.0;
    }
    let worst = alpha
        .iter()
        .map(|&a| (FRAC_PI_2 - a).abs())
        .fold(0.0f32, f32::max);
    (1.0 - worst / FRAC_PI_2).max(0.0)
}

/// The kernel's entry point on the CPU: eta of every candidate of `batch`.
pub fn quad_quality(batch: &Batch) -> Vec<f32> {
    let v = &batch.vertices;
    batch
        .quads
        .par_iter()
        .with_min_len(4096)
        .map(|q| {
            quad_eta(
                &v[q[0] as usize],
                &v[q[1] as usize],
                &v[q[2] as usize],
                &v[q[3] as usize],
            )
        })
        .collect()
}

/// The kernel's entry point `quad_quality_local` on the CPU (precomputed-edges layout).
pub fn quad_quality_local(locals: &[LocalQuad]) -> Vec<f32> {
    locals
        .par_iter()
        .with_min_len(4096)
        .map(|l| eta_from_edges(l.edges()))
        .collect()
}

/// CPU twin of `shaders/stream_copy.wgsl`.
pub fn stream_copy(src: &[[f32; 4]], dst: &mut [[f32; 4]]) {
    dst.par_iter_mut().zip(src).for_each(|(d, s)| *d = *s);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polynomial_atan2_is_accurate() {
        let mut worst = 0.0f64;
        for i in 0..=20000 {
            let t = i as f64 / 20000.0 * std::f64::consts::PI;
            let (y, x) = (t.sin() as f32, t.cos() as f32);
            let got = atan2_pos(y.abs(), x) as f64;
            let want = (y.abs() as f64).atan2(x as f64);
            worst = worst.max((got - want).abs());
        }
        assert!(worst < 5e-7, "worst atan2 error {worst}");
        assert_eq!(atan2_pos(0.0, 0.0), 0.0);
        assert_eq!(atan2_pos(0.0, -1.0), PI);
    }

    #[test]
    fn twin_gives_a_folded_pair_eta_zero_as_f64_does() {
        // The second triangle (s1, s0, o1) lies folded over the first (o1 on o0's side of
        // the diagonal): no quad, though the sums of unsigned angles read as a kite's.
        let pts = [
            [0.0, 0.0, 0.0],
            [0.5, 0.5, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 1.0, 0.0],
        ];
        let mut b = Batch::new();
        b.push(&pts, &[[0, 1, 2, 3]]).unwrap();
        assert_eq!(crate::quality::quad_eta(pts), 0.0);
        assert_eq!(quad_quality(&b), vec![0.0]);
        let local: Vec<LocalQuad> = b.local_quads(0..1);
        assert_eq!(quad_quality_local(&local), vec![0.0]);
    }

    #[test]
    fn twin_matches_f64_on_a_rhombus() {
        let h = 3f64.sqrt() / 2.0;
        let pts = [
            [0.0, 0.0, 0.0],
            [0.5, -h, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, h, 0.0],
        ];
        let mut b = Batch::new();
        b.push(&pts, &[[0, 1, 2, 3]]).unwrap();
        let eta = quad_quality(&b);
        assert!((eta[0] as f64 - crate::quality::quad_eta(pts)).abs() < 1e-6);
    }
}
