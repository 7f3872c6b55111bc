//! The device's memory bandwidth, the bound the quality kernel is compared against: a
//! buffer-to-buffer copy ([`copy_bandwidth`]) and a compute kernel that streams a buffer
//! (`shaders/stream_copy.wgsl`, [`stream_bandwidth`]). Benchmarks only: the evaluator never
//! measures its device.

use quadrecomb::internals::gpu::timing::{Timestamps, checked, timed_dispatches, wait};
use quadrecomb::internals::gpu::{GpuError, shader};
use std::borrow::Cow;
use std::time::{Duration, Instant};

/// Invocations per workgroup of the stream-copy kernel (`@workgroup_size` in its shader).
const WORKGROUP: usize = 256;

/// Device memory bandwidth measured with a buffer-to-buffer copy of `bytes` bytes (read +
/// write counted), in bytes per second: the bound the kernel is compared against.
pub fn copy_bandwidth(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    bytes: u64,
) -> Result<f64, GpuError> {
    let limits = device.limits();
    let bytes = bytes.min(limits.max_buffer_size).max(1 << 20) / 16 * 16;
    let (src, dst) = checked(device, "allocating the bandwidth buffers", || {
        let mk = |label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        (mk("bandwidth src"), mk("bandwidth dst"))
    })?;
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t = Instant::now();
        let mut enc = device.create_command_encoder(&Default::default());
        let queries = Timestamps::new(device, "copy time");
        // Timestamps around the copy from two empty compute passes (writing timestamps
        // inside an encoder needs a feature few adapters have).
        let mark = |enc: &mut wgpu::CommandEncoder, i: u32| {
            if let Some(q) = &queries {
                enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: None,
                    timestamp_writes: Some(q.writes(Some(i), None)),
                });
            }
        };
        mark(&mut enc, 0);
        enc.copy_buffer_to_buffer(&src, 0, &dst, 0, bytes);
        mark(&mut enc, 1);
        if let Some(q) = &queries {
            q.resolve(&mut enc);
        }
        queue.submit([enc.finish()]);
        wait(device)?;
        let mut s = t.elapsed().as_secs_f64();
        if let Some(q) = &queries {
            let d = q.seconds(device, queue)?;
            if d > 0.0 {
                s = d;
            }
        }
        best = best.min(s);
    }
    Ok(2.0 * bytes as f64 / best)
}

/// Device memory bandwidth reached by a compute kernel (`shaders/stream_copy.wgsl`, one
/// vec4 per invocation) copying `bytes` bytes, read + write counted, in bytes per second
/// (the fastest of ten copies after half a second of back-to-back copies): the fairest
/// bound for the quality kernel, which goes through the same path.
pub fn stream_bandwidth(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    bytes: u64,
) -> Result<f64, GpuError> {
    shader::validate(shader::STREAM_COPY, shader::STREAM_COPY_PATH)?;
    let limits = device.limits();
    let bytes = bytes
        .min(limits.max_buffer_size)
        .min(limits.max_storage_buffer_binding_size)
        .max(1 << 20)
        / 4096
        * 4096;
    let items = (bytes / 16) as usize;
    let groups = items.div_ceil(WORKGROUP);
    let wg_max = limits.max_compute_workgroups_per_dimension as usize;
    let gx = groups.min(wg_max).min(32768);
    let gy = groups.div_ceil(gx);
    if gy > wg_max {
        return Err(GpuError::TooLarge(format!(
            "{bytes} bytes for one stream copy"
        )));
    }
    let (pipeline, src, dst) = checked(device, "building the stream-copy kernel", || {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(shader::STREAM_COPY_PATH),
            source: wgpu::ShaderSource::Wgsl(Cow::Borrowed(shader::STREAM_COPY)),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("stream_copy"),
            layout: None,
            module: &module,
            entry_point: Some("stream_copy"),
            compilation_options: Default::default(),
            cache: None,
        });
        let mk = |label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE,
                mapped_at_creation: false,
            })
        };
        (pipeline, mk("stream src"), mk("stream dst"))
    })?;
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("stream_copy"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: src.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: dst.as_entire_binding(),
            },
        ],
    });
    // Ten timed copies after half a second of untimed ones (clocks up, as for
    // `Kernel::dispatch_times`); without timestamps, the host clock over one.
    let grid = (gx as u32, gy as u32);
    let warm_up = Duration::from_millis(500);
    let t = Instant::now();
    let timed = timed_dispatches(device, queue, &pipeline, &bind, grid, 10, warm_up)?;
    // A driver whose timestamps do not advance gets the host clock too.
    let fastest = timed.map(|times| times.into_iter().fold(f64::INFINITY, f64::min));
    let best = match fastest.filter(|&s| s > 0.0) {
        Some(s) => s,
        None => {
            let mut enc = device.create_command_encoder(&Default::default());
            {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &bind, &[]);
                pass.dispatch_workgroups(grid.0, grid.1, 1);
            }
            queue.submit([enc.finish()]);
            wait(device)?;
            t.elapsed().as_secs_f64()
        }
    };
    Ok(2.0 * bytes as f64 / best)
}
