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
// polynomial, not the driver's (Vulkan allows 4096 ulp for atan2), accurate to ~2e-7.

/// Mirrors `gpu::layout::Vertex`: a position split as hi + lo (w unused).
struct Vertex {
    hi: vec4<f32>,
    lo: vec4<f32>,
}

/// Mirrors `gpu::layout::Params`: one dispatch's candidate count, the number of
/// invocations per row of the 2D grid, the index subtracted from every vertex index, and
/// the stride between the four planes of the local layout.
struct Params {
    count: u32,
    row: u32,
    vertex_base: u32,
    plane: u32,
}

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> vertices: array<Vertex>;
@group(0) @binding(2) var<storage, read> quads: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read_write> eta: array<f32>;
/// The local layout (`gpu::layout::LocalQuad`), as four planes of vec4: candidate i's
/// [a.xyz e0.x] [e0.yz e1.xy] [e1.z f0.xyz] [f1.xyz -] at i, plane + i, 2 plane + i,
/// 3 plane + i, with a = s1 - s0, e0 = o0 - s0, e1 = o1 - s0, f0 = o0 - s1, f1 = o1 - s1
/// computed on the host from f64, each scaled to a largest component of 1.
@group(0) @binding(4) var<storage, read> locals: array<vec4<f32>>;

const PI: f32 = 3.14159265358979;
const FRAC_PI_2: f32 = 1.57079632679490;

/// 0: eta (production). 1: a diagnostic for the benchmark that does the same memory
/// accesses with almost no arithmetic (its output is not eta).
override MODE: u32 = 0u;

/// Invocations per workgroup (the host passes `gpu::KernelOptions::workgroup`). 256 was
/// the fastest on an H100 (64: 11-12 % slower, 1024: 39-44 % slower, indexed layout, two
/// runs of `bench gpu --shapes`).
override WG: u32 = 256u;

/// b - a with hi/lo compensation, scaled so that its largest component is 1 (0 stays 0).
fn edge(a: Vertex, b: Vertex) -> vec3<f32> {
    let d = (b.hi.xyz - a.hi.xyz) + (b.lo.xyz - a.lo.xyz);
    let m = max(abs(d.x), max(abs(d.y), abs(d.z)));
    if m > 0.0 {
        return d * (1.0 / m);
    }
    return vec3<f32>(0.0);
}

/// atan(a) for a in [0, 1]: a minimax-fitted odd polynomial of degree 15 (error 4e-8 in
/// exact arithmetic, about 1.3e-7 evaluated in f32). No branch, no division.
fn atan_unit(a: f32) -> f32 {
    let s = a * a;
    let p = 0.99999934 + s * (-0.33329859 + s * (0.19946566 + s * (-0.13908629
        + s * (0.09642195 + s * (-0.05591230 + s * (0.02186294 + s * -0.00405456))))));
    return a * p;
}

/// atan2(y, x) for y >= 0, in [0, pi]; (0, 0) gives 0. One division, no branch.
fn atan2_pos(y: f32, x: f32) -> f32 {
    let ax = abs(x);
    let hi = max(y, ax);
    let t = select(min(y, ax) / hi, 0.0, hi == 0.0);
    var r = atan_unit(t);
    r = select(r, FRAC_PI_2 - r, y > ax);
    return select(r, PI - r, x < 0.0);
}

/// Angle between u and v, in [0, pi]; 0 when either is zero.
fn angle(u: vec3<f32>, v: vec3<f32>) -> f32 {
    return atan2_pos(length(cross(u, v)), dot(u, v));
}

/// eta of the quad [s0, o1, s1, o0].
fn quad_eta(s0: Vertex, o1: Vertex, s1: Vertex, o0: Vertex) -> f32 {
    return eta_from_edges(edge(s0, s1), edge(s0, o0), edge(s0, o1), edge(s1, o0), edge(s1, o1));
}

/// eta from the edge vectors a = s1 - s0, e0 = o0 - s0, e1 = o1 - s0, f0 = o0 - s1,
/// f1 = o1 - s1 (each at any positive scale). 0 for a pair folded over its diagonal (the
/// triangles' normals 90 degrees apart or more), as `quality::quad_eta`.
fn eta_from_edges(a: vec3<f32>, e0: vec3<f32>, e1: vec3<f32>, f0: vec3<f32>, f1: vec3<f32>) -> f32 {
    if dot(cross(a, e0), cross(-a, f1)) <= 0.0 {
        return 0.0;
    }
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

@compute @workgroup_size(WG)
fn quad_quality(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.y * params.row + gid.x;
    if i >= params.count {
        return;
    }
    let q = quads[i] - vec4<u32>(params.vertex_base);
    let s0 = vertices[q.x];
    let o1 = vertices[q.y];
    let s1 = vertices[q.z];
    let o0 = vertices[q.w];
    if MODE == 1u {
        let m = s0.hi + s0.lo + o1.hi + o1.lo + s1.hi + s1.lo + o0.hi + o0.lo;
        eta[i] = m.x + m.y + m.z + m.w;
        return;
    }
    eta[i] = quad_eta(s0, o1, s1, o0);
}

/// The same function on the precomputed-edges layout: streams 64 bytes per candidate in
/// four coalesced planes, no gather. CPU twin: `gpu::cpu::quad_quality_local`.
@compute @workgroup_size(WG)
fn quad_quality_local(@builtin(global_invocation_id) gid: vec3<u32>) {
    let i = gid.y * params.row + gid.x;
    if i >= params.count {
        return;
    }
    let n = params.plane;
    let p = locals[i];
    let q = locals[n + i];
    let r = locals[2u * n + i];
    let s = locals[3u * n + i];
    if MODE == 1u {
        let m = p + q + r + s;
        eta[i] = m.x + m.y + m.z + m.w;
        return;
    }
    eta[i] = eta_from_edges(
        p.xyz,
        vec3<f32>(p.w, q.x, q.y),
        vec3<f32>(q.z, q.w, r.x),
        r.yzw,
        s.xyz,
    );
}
