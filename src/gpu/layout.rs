//! Buffer layout shared by the WGSL kernel and its CPU twin, and the [`Batch`] that holds
//! several meshes' candidates concatenated into those buffers.

use super::GpuError;
use std::ops::Range;

/// Mirrors WGSL `struct Vertex` in `shaders/quad_quality.wgsl`: a position normalised per
/// mesh (centre subtracted, divided by the extent, in f64) and split into `hi + lo` f32
/// parts; `w` is unused. 32 bytes.
#[allow(unsafe_code)] // the bytemuck derives expand to `unsafe impl`
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub hi: [f32; 4],
    pub lo: [f32; 4],
}

/// Mirrors WGSL `struct Params` in `shaders/quad_quality.wgsl`: one dispatch's candidate
/// count, invocations per row of the 2D dispatch grid, the index subtracted from every
/// vertex index, and the stride (in vec4) between the local layout's four planes. 16 bytes.
#[allow(unsafe_code)] // the bytemuck derives expand to `unsafe impl`
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Params {
    pub count: u32,
    pub row: u32,
    pub vertex_base: u32,
    pub plane: u32,
}

/// One candidate of the local layout, mirroring WGSL `locals` in `shaders/quad_quality.wgsl`
/// (which holds `v[0..4]`, `v[4..8]`, `v[8..12]`, `v[12..16]` in four planes, see
/// [`Batch::local_planes`]): the five edge vectors `a = s1 - s0, e0 = o0 - s0,
/// e1 = o1 - s0, f0 = o0 - s1, f1 = o1 - s1`, computed in f64 and each scaled to a largest
/// component of 1, packed as `[a.xyz e0.x] [e0.yz e1.xy] [e1.z f0.xyz] [f1.xyz 0]`.
/// 64 bytes, read without gather.
#[allow(unsafe_code)] // the bytemuck derives expand to `unsafe impl`
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct LocalQuad {
    pub v: [f32; 16],
}

impl LocalQuad {
    /// The edges of the quad `[s0, o1, s1, o0]`.
    pub fn new(p: [[f64; 3]; 4]) -> LocalQuad {
        let [s0, o1, s1, o0] = p;
        let edge = |a: [f64; 3], b: [f64; 3]| {
            let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let m = d[0].abs().max(d[1].abs()).max(d[2].abs());
            if m > 0.0 {
                d.map(|x| (x / m) as f32)
            } else {
                [0.0; 3]
            }
        };
        let (a, e0, e1, f0, f1) = (
            edge(s0, s1),
            edge(s0, o0),
            edge(s0, o1),
            edge(s1, o0),
            edge(s1, o1),
        );
        LocalQuad {
            v: [
                a[0], a[1], a[2], e0[0], e0[1], e0[2], e1[0], e1[1], e1[2], f0[0], f0[1], f0[2],
                f1[0], f1[1], f1[2], 0.0,
            ],
        }
    }

    /// The five edges `[a, e0, e1, f0, f1]`.
    pub fn edges(&self) -> [[f32; 3]; 5] {
        let v = &self.v;
        [
            [v[0], v[1], v[2]],
            [v[3], v[4], v[5]],
            [v[6], v[7], v[8]],
            [v[9], v[10], v[11]],
            [v[12], v[13], v[14]],
        ]
    }
}

/// Bytes of one [`LocalQuad`].
pub const LOCAL_QUAD_BYTES: usize = std::mem::size_of::<LocalQuad>();

/// Bytes the kernel reads per candidate (its four `u32` vertex indices) and writes (eta).
pub const CANDIDATE_BYTES: usize = 16 + 4;
/// Bytes of one [`Vertex`].
pub const VERTEX_BYTES: usize = std::mem::size_of::<Vertex>();

impl Vertex {
    /// `p` normalised by `(centre, inv_scale)` and split into hi + lo parts.
    pub fn new(p: [f64; 3], centre: [f64; 3], inv_scale: f64) -> Vertex {
        let mut v = Vertex::default();
        for k in 0..3 {
            let x = (p[k] - centre[k]) * inv_scale;
            let hi = x as f32;
            v.hi[k] = hi;
            v.lo[k] = (x - hi as f64) as f32;
        }
        v
    }
}

/// Where one mesh's data sits in a [`Batch`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MeshSpan {
    /// The mesh's vertices in [`Batch::vertices`].
    pub vertices: Range<usize>,
    /// The mesh's candidates in [`Batch::quads`] (and in the output eta).
    pub candidates: Range<usize>,
}

/// Several meshes' vertices and candidate quads, concatenated: what one call of the kernel
/// (one or more dispatches) evaluates. Quad indices are global (the mesh's vertex offset is
/// added when it is pushed), so the kernel needs no per-mesh table.
#[derive(Debug, Clone, Default)]
pub struct Batch {
    /// Normalised positions of every mesh, one after the other.
    pub vertices: Vec<Vertex>,
    /// Candidate quads `[s0, o1, s1, o0]` as global indices into `vertices`.
    pub quads: Vec<[u32; 4]>,
    /// One span per pushed mesh, in order.
    pub meshes: Vec<MeshSpan>,
}

impl Batch {
    /// An empty batch.
    pub fn new() -> Batch {
        Batch::default()
    }

    /// An empty batch with room for `meshes` meshes of `vertices` vertices and `quads`
    /// candidates in all: pushing them then moves nothing (a batch of a whole suite grown
    /// push by push reallocated its arrays several times).
    pub fn with_capacity(vertices: usize, quads: usize, meshes: usize) -> Batch {
        Batch {
            vertices: Vec::with_capacity(vertices),
            quads: Vec::with_capacity(quads),
            meshes: Vec::with_capacity(meshes),
        }
    }

    /// Appends one mesh's vertices and candidate quads (indices local to `vertices`) and
    /// returns its index. Positions are normalised by the mesh's bounding box so that f32
    /// keeps its precision for huge and tiny coordinates.
    pub fn push(&mut self, vertices: &[[f64; 3]], quads: &[[u32; 4]]) -> Result<usize, GpuError> {
        let base = self.vertices.len();
        let total = base + vertices.len();
        if total > u32::MAX as usize {
            return Err(GpuError::TooLarge(format!(
                "{total} vertices in one batch; at most {} fit u32 indices",
                u32::MAX
            )));
        }
        if let Some((c, &v)) = quads.iter().enumerate().find_map(|(c, q)| {
            q.iter()
                .find(|&&v| v as usize >= vertices.len())
                .map(|v| (c, v))
        }) {
            return Err(GpuError::BadIndex {
                mesh: self.meshes.len(),
                candidate: c,
                vertex: v,
                count: vertices.len(),
            });
        }
        let (centre, inv_scale) = normalisation(vertices);
        self.vertices
            .extend(vertices.iter().map(|&p| Vertex::new(p, centre, inv_scale)));
        let first = self.quads.len();
        let b = base as u32;
        self.quads.extend(quads.iter().map(|q| q.map(|v| v + b)));
        self.meshes.push(MeshSpan {
            vertices: base..total,
            candidates: first..self.quads.len(),
        });
        Ok(self.meshes.len() - 1)
    }

    /// Total number of candidates.
    pub fn len(&self) -> usize {
        self.quads.len()
    }

    /// True when the batch has no candidate.
    pub fn is_empty(&self) -> bool {
        self.quads.is_empty()
    }

    /// The precomputed-edges layout of candidates `range` (from the normalised positions,
    /// recombined to f64 from their hi + lo parts), in parallel.
    pub fn local_quads(&self, range: Range<usize>) -> Vec<LocalQuad> {
        use rayon::prelude::*;
        let f64_of = |v: &Vertex| [0, 1, 2].map(|k| v.hi[k] as f64 + v.lo[k] as f64);
        self.quads[range]
            .par_iter()
            .with_min_len(4096)
            .map(|q| LocalQuad::new(q.map(|i| f64_of(&self.vertices[i as usize]))))
            .collect()
    }

    /// The local layout of candidates `range` as the kernel reads it: four planes of
    /// `range.len()` vec4 each (plane k holds `v[4k..4k + 4]` of every [`LocalQuad`]).
    pub fn local_planes(&self, range: Range<usize>) -> Vec<[f32; 4]> {
        use rayon::prelude::*;
        let locals = self.local_quads(range);
        let n = locals.len();
        let mut planes = vec![[0.0f32; 4]; 4 * n];
        planes
            .par_chunks_mut(n.max(1))
            .enumerate()
            .for_each(|(k, plane)| {
                for (dst, l) in plane.iter_mut().zip(&locals) {
                    dst.copy_from_slice(&l.v[4 * k..4 * k + 4]);
                }
            });
        planes
    }

    /// Bytes the kernel must move per candidate at least: indices read, eta written, and
    /// each vertex read once, spread over the candidates.
    pub fn bytes_per_candidate(&self) -> f64 {
        if self.quads.is_empty() {
            return 0.0;
        }
        CANDIDATE_BYTES as f64
            + (self.vertices.len() * VERTEX_BYTES) as f64 / self.quads.len() as f64
    }
}

/// Centre of the bounding box and the inverse of its half extent (1 for an empty or
/// single-point set).
fn normalisation(vertices: &[[f64; 3]]) -> ([f64; 3], f64) {
    let Some(first) = vertices.first() else {
        return ([0.0; 3], 1.0);
    };
    let (mut lo, mut hi) = (*first, *first);
    for p in vertices {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let half = (0..3).map(|k| 0.5 * (hi[k] - lo[k])).fold(0.0, f64::max);
    let inv = if half > 0.0 && half.is_finite() {
        // Below about 5.6e-309 (subnormal), 1 / half overflows: the largest power of two
        // still brings every coordinate into f32's normal range (eta does not depend on
        // the scale). An infinite scale made every eta 0 on a mesh of extent 1e-310.
        let inv = 1.0 / half;
        if inv.is_finite() {
            inv
        } else {
            2f64.powi(1023)
        }
    } else {
        1.0
    };
    (centre, inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_subnormal_extent_scales_to_finite_coordinates() {
        // A unit square scaled by 1e-310: 1 / half overflowed to inf, the coordinates to
        // inf / NaN, and every eta read 0 on the device and the CPU twin.
        let pts = [
            [0.0, 0.0, 0.0],
            [1e-310, 0.0, 0.0],
            [1e-310, 1e-310, 0.0],
            [0.0, 1e-310, 0.0],
        ];
        let (centre, inv) = normalisation(&pts);
        assert!(inv.is_finite() && inv > 0.0);
        for p in &pts {
            let v = Vertex::new(*p, centre, inv);
            for k in 0..3 {
                let x = v.hi[k] as f64 + v.lo[k] as f64;
                assert!(x.is_finite() && x.abs() <= 1.0, "{p:?} -> {x}");
            }
            assert!(
                v.hi[0].abs() > 1e-3 || p[0] == centre[0],
                "{p:?}: {:?}",
                v.hi
            );
        }
    }

    #[test]
    fn hi_lo_split_keeps_f64_precision() {
        let v = Vertex::new([1e8 + 0.125, -3.0, 1e-9], [0.0; 3], 1.0);
        assert_eq!(v.hi[0] as f64 + v.lo[0] as f64, 1e8 + 0.125);
        let back = v.hi[2] as f64 + v.lo[2] as f64;
        assert!((back - 1e-9).abs() < 1e-22);
    }

    #[test]
    fn push_offsets_indices_and_rejects_bad_ones() {
        let mut b = Batch::new();
        let pts = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        b.push(&pts, &[[0, 1, 2, 3]]).unwrap();
        b.push(&pts, &[[3, 2, 1, 0]]).unwrap();
        assert_eq!(b.quads[1], [7, 6, 5, 4]);
        assert_eq!(b.meshes[1].candidates, 1..2);
        assert!(matches!(
            b.push(&pts, &[[0, 1, 2, 4]]),
            Err(GpuError::BadIndex { vertex: 4, .. })
        ));
        assert_eq!(b.len(), 2);
    }
}
