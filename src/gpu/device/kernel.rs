//! The quality kernel on a device: [`Kernel`] (pipeline built once per device, buffers kept
//! between runs, batches split into dispatches) and [`evaluate`], with the time each phase
//! took ([`Timings`]).

use crate::gpu::layout::{Batch, LOCAL_QUAD_BYTES, Params, VERTEX_BYTES, Vertex};
use crate::gpu::timing::{Timestamps, checked, read_back, timed_dispatches, wait};
use crate::gpu::{GpuError, shader};
use std::borrow::Cow;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Time spent in each phase of a kernel run, summed over its dispatches (seconds).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Timings {
    /// Host to device: buffer writes until the queue has them.
    pub upload_s: f64,
    /// Submit and wait for the dispatches (host clock).
    pub kernel_s: f64,
    /// The compute passes on the device's clock (timestamp queries), when supported.
    pub kernel_device_s: Option<f64>,
    /// Device to host: copy to a mappable buffer, map, copy out.
    pub readback_s: f64,
    /// Number of dispatches (chunks) the batch needed.
    pub dispatches: usize,
    /// Workgroup rows of the tallest dispatch grid: 1 unless a dispatch needed more
    /// workgroups than one dimension holds (then a 2D grid, rows of the per-dimension
    /// maximum); 0 for an empty batch.
    pub grid_rows: usize,
}

impl Timings {
    /// The kernel time: the device clock when available, else the host clock.
    pub fn kernel_best_s(&self) -> f64 {
        self.kernel_device_s.unwrap_or(self.kernel_s)
    }
}

/// How candidates reach the kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Layout {
    /// Vertex positions once (32 bytes each) and four `u32` indices per candidate: the
    /// fewest bytes over the bus; the kernel gathers four vertices per candidate.
    #[default]
    Indexed,
    /// Five edge vectors per candidate precomputed on the host (64 bytes, entry point
    /// `quad_quality_local`): more bytes over the bus, but the kernel streams without gather.
    Local,
}

/// How the quality kernel is built: the candidate layout and the workgroup size (the WGSL
/// override `WG`). The defaults are the production kernel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct KernelOptions {
    /// How candidates reach the kernel.
    pub layout: Layout,
    /// Invocations per workgroup (1 to the adapter's limit).
    pub workgroup: u32,
    /// The benchmark's diagnostic: the same memory accesses with almost no arithmetic (the
    /// output is not eta).
    pub memory_only: bool,
}

impl Default for KernelOptions {
    fn default() -> Self {
        KernelOptions {
            layout: Layout::Indexed,
            workgroup: 256,
            memory_only: false,
        }
    }
}

impl std::fmt::Display for KernelOptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let layout = match self.layout {
            Layout::Indexed => "indexed",
            Layout::Local => "local edges",
        };
        write!(f, "{layout}, wg {}", self.workgroup)?;
        if self.memory_only {
            f.write_str(", memory accesses only")?;
        }
        Ok(())
    }
}

/// The quality pipeline on one device, built once and reused for every batch.
#[derive(Debug)]
pub struct Kernel {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    timestamps: bool,
    max_chunk: usize,
    max_vertices: usize,
    max_groups: usize,
    options: KernelOptions,
    buffers: Mutex<Option<Buffers>>,
}

/// A kernel's device buffers, kept between runs.
#[derive(Debug)]
struct Buffers {
    vertex_cap: usize,
    chunk: usize,
    params: wgpu::Buffer,
    vertices: wgpu::Buffer,
    quads: wgpu::Buffer,
    eta: wgpu::Buffer,
    read: wgpu::Buffer,
    bind: wgpu::BindGroup,
    queries: Option<Timestamps>,
    /// The grid of the last run when it was a single dispatch (what
    /// [`Kernel::dispatch_times`] repeats).
    single_grid: Option<(u32, u32)>,
}

fn entry(binding: u32, buf: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
    wgpu::BindGroupEntry {
        binding,
        resource: buf.as_entire_binding(),
    }
}

impl Buffers {
    fn new(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        vertex_cap: usize,
        chunk: usize,
        timestamps: bool,
        kind: Layout,
    ) -> Buffers {
        use wgpu::BufferUsages as U;
        let buffer = |label: &str, size: usize, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: (size.max(16) as u64).next_multiple_of(16),
                usage,
                mapped_at_creation: false,
            })
        };
        let params = buffer(
            "params",
            std::mem::size_of::<Params>(),
            U::UNIFORM | U::COPY_DST,
        );
        let vertices = buffer(
            "vertices",
            vertex_cap * VERTEX_BYTES,
            U::STORAGE | U::COPY_DST,
        );
        let per_candidate = match kind {
            Layout::Indexed => 16,
            Layout::Local => LOCAL_QUAD_BYTES,
        };
        let quads = buffer("quads", chunk * per_candidate, U::STORAGE | U::COPY_DST);
        let eta = buffer("eta", chunk * 4, U::STORAGE | U::COPY_SRC);
        let read = buffer("eta readback", chunk * 4, U::MAP_READ | U::COPY_DST);
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("quad_quality"),
            layout,
            entries: &match kind {
                Layout::Indexed => vec![
                    entry(0, &params),
                    entry(1, &vertices),
                    entry(2, &quads),
                    entry(3, &eta),
                ],
                Layout::Local => vec![entry(0, &params), entry(3, &eta), entry(4, &quads)],
            },
        });
        let queries = timestamps
            .then(|| Timestamps::new(device, "kernel time"))
            .flatten();
        Buffers {
            vertex_cap,
            chunk,
            params,
            vertices,
            quads,
            eta,
            read,
            bind,
            queries,
            single_grid: None,
        }
    }
}

/// Evaluates `batch` on `device` (building the pipeline first): eta per candidate, in batch
/// order. Use a [`Kernel`] to build the pipeline once for many batches.
pub fn evaluate(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    batch: &Batch,
) -> Result<Vec<f32>, GpuError> {
    Ok(Kernel::new(device)?.run(device, queue, batch)?.0)
}

impl Kernel {
    /// Validates the shader with naga and builds the pipeline on `device`.
    pub fn new(device: &wgpu::Device) -> Result<Kernel, GpuError> {
        Kernel::with_options(device, KernelOptions::default())
    }

    /// The kernel for a given candidate [`Layout`].
    pub fn with_layout(device: &wgpu::Device, layout: Layout) -> Result<Kernel, GpuError> {
        Kernel::with_options(
            device,
            KernelOptions {
                layout,
                ..KernelOptions::default()
            },
        )
    }

    /// A diagnostic for the benchmark: the kernel's memory accesses (indices, four vertex
    /// gathers, one write) with almost no arithmetic. Its output is not eta.
    pub fn memory_only(device: &wgpu::Device, layout: Layout) -> Result<Kernel, GpuError> {
        Kernel::with_options(
            device,
            KernelOptions {
                layout,
                memory_only: true,
                ..KernelOptions::default()
            },
        )
    }

    /// The kernel built with `options` (layout and launch shape).
    pub fn with_options(device: &wgpu::Device, options: KernelOptions) -> Result<Kernel, GpuError> {
        let max_wg = device.limits().max_compute_invocations_per_workgroup;
        if !(1..=max_wg).contains(&options.workgroup) {
            return Err(GpuError::TooLarge(format!(
                "kernel options {options}: a workgroup holds 1 to {max_wg} invocations here"
            )));
        }
        shader::validate(shader::QUAD_QUALITY, shader::QUAD_QUALITY_PATH)?;
        let pipeline = checked(device, "building the quality pipeline", || {
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(shader::QUAD_QUALITY_PATH),
                source: wgpu::ShaderSource::Wgsl(Cow::Borrowed(shader::QUAD_QUALITY)),
            });
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("quad_quality"),
                layout: None,
                module: &module,
                entry_point: Some(match options.layout {
                    Layout::Indexed => shader::ENTRY_POINT,
                    Layout::Local => shader::ENTRY_POINT_LOCAL,
                }),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &[
                        ("MODE", u32::from(options.memory_only) as f64),
                        ("WG", options.workgroup as f64),
                    ],
                    ..Default::default()
                },
                cache: None,
            })
        })?;
        let layout = pipeline.get_bind_group_layout(0);
        Ok(Kernel {
            pipeline,
            layout,
            timestamps: device.features().contains(wgpu::Features::TIMESTAMP_QUERY),
            max_chunk: usize::MAX,
            max_vertices: usize::MAX,
            max_groups: usize::MAX,
            options,
            buffers: Mutex::new(None),
        })
    }

    /// Caps the candidates per dispatch and the vertices bound whole, below what the
    /// device's limits allow (tests use this to exercise chunking and vertex compaction).
    pub fn with_caps(mut self, max_chunk: usize, max_vertices: usize) -> Kernel {
        self.max_chunk = max_chunk.max(1);
        self.max_vertices = max_vertices;
        self
    }

    /// Caps the workgroups per grid dimension below the device's
    /// `max_compute_workgroups_per_dimension` (at least 1), so that tests reach the 2D
    /// grid, which the device's limit puts above 16.7 million candidates per dispatch.
    pub fn with_group_cap(mut self, groups_per_dimension: u32) -> Kernel {
        self.max_groups = groups_per_dimension.max(1) as usize;
        self
    }

    /// True when the kernel time comes from timestamp queries.
    pub fn has_timestamps(&self) -> bool {
        self.timestamps
    }

    /// Evaluates `batch`: eta per candidate in batch order, and the time of each phase.
    ///
    /// The vertex buffer is uploaded once when it fits one storage binding; otherwise each
    /// dispatch uploads the vertices its candidates use (compacted, indices remapped). The
    /// candidates are split into dispatches that fit `max_storage_buffer_binding_size`,
    /// `max_buffer_size` and a 2D grid of `max_compute_workgroups_per_dimension`.
    pub fn run(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        batch: &Batch,
    ) -> Result<(Vec<f32>, Timings), GpuError> {
        let n = batch.len();
        let mut timings = Timings::default();
        if n == 0 {
            return Ok((Vec::new(), timings));
        }
        let limits = device.limits();
        let bind_max = limits
            .max_storage_buffer_binding_size
            .min(limits.max_buffer_size) as usize;
        let wg_max = (limits.max_compute_workgroups_per_dimension as usize).min(self.max_groups);
        let local = self.options.layout == Layout::Local;
        let wg = self.options.workgroup as usize;
        let whole = local
            || batch.vertices.len() * VERTEX_BYTES <= bind_max
                && batch.vertices.len() <= self.max_vertices;
        let per_candidate = if local { LOCAL_QUAD_BYTES } else { 16 };
        let mut chunk = (bind_max / per_candidate)
            .min(wg_max.saturating_mul(wg_max).saturating_mul(wg))
            .min(self.max_chunk)
            .min(n);
        if !whole {
            // A compacted chunk has at most 4 vertices per candidate.
            chunk = chunk
                .min(bind_max / VERTEX_BYTES / 4)
                .min(self.max_vertices / 4)
                .max(1);
        }
        let vertex_cap = if local {
            0
        } else if whole {
            batch.vertices.len()
        } else {
            (4 * chunk).min(batch.vertices.len())
        };

        // Buffers are kept between runs and grown when a batch needs more, so a process
        // that evaluates many batches allocates (and pins host memory) once.
        let mut cache = self.buffers.lock().unwrap_or_else(|e| e.into_inner());
        if cache
            .as_ref()
            .is_none_or(|b| b.vertex_cap < vertex_cap || b.chunk < chunk)
        {
            *cache = None; // free the old ones first
            let bytes = vertex_cap * VERTEX_BYTES + chunk * (per_candidate + 8);
            let what = format!(
                "allocating its buffers ({}: {chunk} candidates, {vertex_cap} vertices)",
                mib(bytes)
            );
            *cache = Some(checked(device, &what, || {
                Buffers::new(
                    device,
                    &self.layout,
                    vertex_cap,
                    chunk,
                    self.timestamps,
                    self.options.layout,
                )
            })?);
        }
        let bufs = cache.as_mut().expect("just allocated");
        let (params_buf, vertex_buf, quad_buf, eta_buf, read_buf, bind) = (
            &bufs.params,
            &bufs.vertices,
            &bufs.quads,
            &bufs.eta,
            &bufs.read,
            &bufs.bind,
        );
        let queries = bufs.queries.as_ref();
        let mut last_grid = None;

        let mut out = Vec::with_capacity(n);
        let mut remap = if whole {
            Vec::new()
        } else {
            vec![u32::MAX; batch.vertices.len()]
        };
        let mut local_vertices: Vec<Vertex> = Vec::new();
        let mut local_quads: Vec<[u32; 4]> = Vec::new();
        let mut device_s = 0.0;
        for start in (0..n).step_by(chunk) {
            let count = chunk.min(n - start);
            let quads = &batch.quads[start..start + count];
            let groups = count.div_ceil(wg);
            let (gx, gy) = if groups <= wg_max {
                (groups, 1)
            } else {
                (wg_max, groups.div_ceil(wg_max))
            };
            let params = Params {
                count: count as u32,
                row: (gx * wg) as u32,
                vertex_base: 0,
                plane: count as u32,
            };
            last_grid = Some((gx as u32, gy as u32));
            timings.grid_rows = timings.grid_rows.max(gy);

            // Upload. wgpu's writes report running out of memory (the staging copies) to the
            // device's error handler, which panics unless a scope takes it.
            let t = Instant::now();
            let what = format!("uploading {count} candidates");
            let upload = checked(device, &what, || {
                queue.write_buffer(params_buf, 0, bytemuck::bytes_of(&params));
                if local {
                    let planes = batch.local_planes(start..start + count);
                    queue.write_buffer(quad_buf, 0, bytemuck::cast_slice(&planes));
                } else if whole {
                    if start == 0 {
                        queue.write_buffer(vertex_buf, 0, bytemuck::cast_slice(&batch.vertices));
                    }
                    queue.write_buffer(quad_buf, 0, bytemuck::cast_slice(quads));
                } else {
                    local_vertices.clear();
                    local_quads.clear();
                    for q in quads {
                        local_quads.push(q.map(|v| {
                            let r = &mut remap[v as usize];
                            if *r == u32::MAX {
                                *r = local_vertices.len() as u32;
                                local_vertices.push(batch.vertices[v as usize]);
                            }
                            *r
                        }));
                    }
                    for q in quads {
                        for &v in q {
                            remap[v as usize] = u32::MAX;
                        }
                    }
                    queue.write_buffer(vertex_buf, 0, bytemuck::cast_slice(&local_vertices));
                    queue.write_buffer(quad_buf, 0, bytemuck::cast_slice(&local_quads));
                }
                queue.submit([]);
            });
            upload?;
            wait(device)?;
            timings.upload_s += t.elapsed().as_secs_f64();

            // Kernel.
            let t = Instant::now();
            let mut enc = device.create_command_encoder(&Default::default());
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("quad_quality"),
                    timestamp_writes: queries.map(|q| q.writes(Some(0), Some(1))),
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, bind, &[]);
                pass.dispatch_workgroups(gx as u32, gy as u32, 1);
            }
            if let Some(q) = queries {
                q.resolve(&mut enc);
            }
            checked(device, "running the quality kernel", || {
                queue.submit([enc.finish()])
            })?;
            wait(device)?;
            timings.kernel_s += t.elapsed().as_secs_f64();
            if let Some(q) = queries {
                device_s += q.seconds(device, queue)?;
            }

            // Readback.
            let t = Instant::now();
            let bytes = (count * 4) as u64;
            checked(device, &format!("copying {count} results back"), || {
                let mut enc = device.create_command_encoder(&Default::default());
                enc.copy_buffer_to_buffer(eta_buf, 0, read_buf, 0, bytes);
                queue.submit([enc.finish()]);
            })?;
            let data = read_back(device, read_buf, bytes)?;
            out.extend_from_slice(bytemuck::cast_slice::<u8, f32>(&data));
            timings.readback_s += t.elapsed().as_secs_f64();
            timings.dispatches += 1;
        }
        if queries.is_some() {
            timings.kernel_device_s = Some(device_s);
        }
        // Only a single dispatch's data is all still on the device.
        bufs.single_grid = last_grid.filter(|_| timings.dispatches == 1);
        Ok((out, timings))
    }

    /// Device times (seconds) of `reps` dispatches of the previous [`Kernel::run`] (when it
    /// was a single dispatch), on the data it left on the device, after `warm_up` of
    /// back-to-back dispatches in the same submission: the kernel's time with the device
    /// busy. (A GPU that was idle runs a lone dispatch at its idle clock: an H100 stayed at
    /// 345 MHz through `run`'s single dispatches and reached 1980 MHz only under sustained
    /// work.) `None` without timestamp queries, before a run, or after a run of several
    /// dispatches (the device holds only the last one's data).
    pub fn dispatch_times(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        reps: u32,
        warm_up: Duration,
    ) -> Result<Option<Vec<f64>>, GpuError> {
        let cache = self.buffers.lock().unwrap_or_else(|e| e.into_inner());
        let Some((bufs, grid)) = cache.as_ref().and_then(|b| Some((b, b.single_grid?))) else {
            return Ok(None);
        };
        timed_dispatches(
            device,
            queue,
            &self.pipeline,
            &bufs.bind,
            grid,
            reps,
            warm_up,
        )
    }
}

/// `bytes` in MiB, for messages.
fn mib(bytes: usize) -> String {
    format!("{:.1} MiB", bytes as f64 / (1024.0 * 1024.0))
}
