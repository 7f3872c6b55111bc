// Quad quality eta of candidate quads, one invocation per candidate.
//
// CPU twin: `src/gpu/cpu.rs` (same function, same buffer layout, f32). Buffer structs:
// `src/gpu/layout.rs`. The f64 reference is `quality::quad_eta` in `src/quality.rs`.
//
// Each candidate is a quad [s0, o1, s1, o0] made of the triangles (s0, s1, o0) and
// (s1, s0, o1) sharing the diagonal s0-s1. The angle at s0 and at s1 is the SUM of the two
// triangles' angles there; at o1 and o0 it is the triangle's own angle. Angles are 3D
// angles atan2(|u x v|, u . v), so folded surface quads work. eta = max(0, 1 - 2/pi *
// max_k |pi/2 - alpha_k|), and 0 when an angle is outside (0, pi).
//
// Precision: positions arrive normalised per mesh (centre subtracted, divided by the
// extent, in f64 on the host) and split into hi + lo f32 parts, so an edge vector
// (a.hi - b.hi) + (a.lo - b.lo) keeps about 2^-24 relative accuracy even for coordinates
// of 1e8 with unit edges. Each edge vector is then scaled by its own largest component
// (angles are scale-invariant), so nothing under- or overflows. atan2 is our own
// polynomial, not the driver's (Vulkan allows 4096 ulp for atan2), accurate to ~3e-7.

/// Mirrors `gpu::layout::Vertex`: a position split as hi + lo (w unused).
struct Vertex {
    hi: vec4<f32>,
    lo: vec4<f32>,
}

/// Mirrors `gpu::layout::Params`: one dispatch's candidate count, the number of
/// invocations per row of the 2D grid, and the index subtracted from every vertex index.
struct Params {
    count: u32,
    row: u32,
    vertex_base: u32,
    pad: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> vertices: array<Vertex>;
@group(0) @binding(2) var<storage, read> quads: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read_write> eta: array<f32>;

const PI: f32 = 3.14159265358979;
const FRAC_PI_2: f32 = 1.57079632679490;
const FRAC_PI_6: f32 = 0.52359877559830;
const SQRT_3: f32 = 1.73205080756888;
const TAN_PI_12: f32 = 0.26794919243112;

/// b - a with hi/lo compensation, scaled so that its largest component is 1 (0 stays 0).
fn edge(a: Vertex, b: Vertex) -> vec3<f32> {
    let d = (b.hi.xyz - a.hi.xyz) + (b.lo.xyz - a.lo.xyz);
    let m = max(abs(d.x), max(abs(d.y), abs(d.z)));
    if m > 0.0 {
        return d * (1.0 / m);
    }
    return vec3<f32>(0.0);
}

/// atan(a) for a in [0, 1]: reduced to |t| <= tan(pi/12), then the Taylor series to t^13
/// (truncation error below 2e-10).
fn atan_unit(a: f32) -> f32 {
    var t = a;
    var base = 0.0;
    if a > TAN_PI_12 {
        t = (a * SQRT_3 - 1.0) / (a + SQRT_3);
        base = FRAC_PI_6;
    }
    let s = t * t;
    let p = 1.0 + s * (-1.0 / 3.0 + s * (1.0 / 5.0 + s * (-1.0 / 7.0 + s * (1.0 / 9.0
        + s * (-1.0 / 11.0 + s * (1.0 / 13.0))))));
    return base + t * p;
}

/// atan2(y, x) for y >= 0, in [0, pi]; (0, 0) gives 0.
fn atan2_pos(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    let hi = max(y, ax);
    if hi == 0.0 {
        return 0.0;
    }
    var r = atan_unit(min(y, ax) / hi);
    if y > ax {
        r = FRAC_PI_2 - r;
    }
    if x < 0.0 {
        r = PI - r;
    }
    return r;
}

/// Angle between u and v, in [0, pi]; 0 when either is zero.
fn angle(u: vec3<f32>, v: vec3<f32>) -> f32 {
    return atan2_pos(length(cross(u, v)), dot(u, v));
}

/// eta of the quad [s0, o1, s1, o0].
fn quad_eta(s0: Vertex, o1: Vertex, s1: Vertex, o0: Vertex) -> f32 {
    let a = edge(s0, s1);
    let e0 = edge(s0, o0);
    let e1 = edge(s0, o1);
    let f0 = edge(s1, o0);
    let f1 = edge(s1, o1);
    let alpha = vec4<f32>(
        angle(a, e0) + angle(e1, a),
        angle(e1, f1),
        angle(f0, -a) + angle(-a, f1),
        angle(f0, e0),
    );
    if any(alpha <= vec4<f32>(0.0)) || any(alpha >= vec4<f32>(PI)) {
        return 0.0;
    }
    let dev = abs(vec4<f32>(FRAC_PI_2) - alpha);
    let worst = max(max(dev.x, dev.y), max(dev.z, dev.w));
    return max(0.0, 1.0 - worst / FRAC_PI_2);
}

@compute @workgroup_size(256)
fn quad_quality(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.y * params.row + gid.x;
    if i >= params.count {
        return;
    }
    let q = quads[i] - vec4<u32>(params.vertex_base);
    eta[i] = quad_eta(vertices[q.x], vertices[q.y], vertices[q.z], vertices[q.w]);
}
