// Streaming copy, one vec4<f32> per invocation: measures the memory bandwidth a compute
// kernel reaches through wgpu on this device (the bound `bench gpu` compares the quality
// kernel against). CPU twin: `gpu::cpu::stream_copy`.

@group(0) @binding(0) var<storage, read> src: array<vec4<f32>>;
@group(0) @binding(1) var<storage, read_write> dst: array<vec4<f32>>;

@compute @workgroup_size(256)
fn stream_copy(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    let i = gid.y * groups.x * 256u + gid.x;
    if i < arrayLength(&src) {
        dst[i] = src[i];
    }
}
