//! Vulkan adapters and devices (created once, apart from the work) and the quality kernel
//! on a device: [`Kernel`] (pipeline built once per device) and [`evaluate`].

use super::layout::{Batch, LOCAL_QUAD_BYTES, Params, VERTEX_BYTES, Vertex};
use super::{GpuError, shader};
use std::borrow::Cow;
use std::sync::{Mutex, mpsc};
use std::time::{Duration, Instant};

/// Invocations per workgroup of the stream-copy kernel (`@workgroup_size` in its shader).
const WORKGROUP: usize = 256;

/// Every Vulkan adapter the loader reports, best first: discrete, integrated, virtual,
/// other, then CPU (lavapipe). Set `VK_DRIVER_FILES` to choose the drivers.
pub fn adapters() -> Vec<wgpu::Adapter> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: wgpu::Backends::VULKAN,
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    });
    let mut all = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
    all.sort_by_key(|a| rank(a.get_info().device_type));
    all
}

fn rank(t: wgpu::DeviceType) -> u8 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Other => 3,
        wgpu::DeviceType::Cpu => 4,
    }
}

/// True for a software adapter (lavapipe / llvmpipe).
pub fn is_software(info: &wgpu::AdapterInfo) -> bool {
    info.device_type == wgpu::DeviceType::Cpu
}

/// The name recorded in results, e.g. `vulkan: NVIDIA H200` or `vulkan: llvmpipe (...)`.
pub fn adapter_name(info: &wgpu::AdapterInfo) -> String {
    format!("{}: {}", info.backend, info.name)
}

/// Opens a device on `adapter` with the adapter's own limits (large storage buffers) and
/// timestamp queries where supported.
pub fn open_device(adapter: &wgpu::Adapter) -> Result<(wgpu::Device, wgpu::Queue), GpuError> {
    let desc = wgpu::DeviceDescriptor {
        label: Some("quadrecomb"),
        required_features: adapter.features() & wgpu::Features::TIMESTAMP_QUERY,
        required_limits: adapter.limits(),
        ..Default::default()
    };
    pollster::block_on(adapter.request_device(&desc)).map_err(|e| GpuError::RequestDevice {
        adapter: adapter_name(&adapter.get_info()),
        message: e.to_string(),
    })
}

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

/// Device timestamps around compute passes (pairs: 0 and 1 around one pass, ...): the query
/// set, and the buffers its values are resolved into and read back from.
#[derive(Debug)]
struct Timestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    count: u32,
}

impl Timestamps {
    /// `None` when the adapter cannot write timestamps.
    fn new(device: &wgpu::Device, label: &str) -> Option<Timestamps> {
        Timestamps::with_count(device, label, 2)
    }

    /// Room for `count` timestamps.
    fn with_count(device: &wgpu::Device, label: &str, count: u32) -> Option<Timestamps> {
        if !device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            return None;
        }
        let buffer = |usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 8 * count as u64,
                usage,
                mapped_at_creation: false,
            })
        };
        Some(Timestamps {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some(label),
                ty: wgpu::QueryType::Timestamp,
                count,
            }),
            resolve: buffer(wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC),
            read: buffer(wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST),
            count,
        })
    }

    /// Writes for a pass: timestamp 0 at its beginning and/or 1 at its end.
    fn writes(&self, begin: Option<u32>, end: Option<u32>) -> wgpu::ComputePassTimestampWrites<'_> {
        wgpu::ComputePassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: begin,
            end_of_pass_write_index: end,
        }
    }

    /// Records the copy of every timestamp to the readback buffer.
    fn resolve(&self, enc: &mut wgpu::CommandEncoder) {
        let bytes = 8 * self.count as u64;
        enc.resolve_query_set(&self.set, 0..self.count, &self.resolve, 0);
        enc.copy_buffer_to_buffer(&self.resolve, 0, &self.read, 0, bytes);
    }

    /// Seconds between the two timestamps, once the work has been submitted.
    fn seconds(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<f64, GpuError> {
        Ok(self.pairs(device, queue)?[0])
    }

    /// Seconds between timestamps 2k and 2k + 1, for every pair.
    fn pairs(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<Vec<f64>, GpuError> {
        let bytes = read_back(device, &self.read, 8 * self.count as u64)?;
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes);
        let period = queue.get_timestamp_period() as f64 * 1e-9;
        Ok(ticks
            .chunks_exact(2)
            .map(|t| t[1].wrapping_sub(t[0]) as f64 * period)
            .collect())
    }
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

/// Runs `f`, turning any wgpu validation or out-of-memory error it raises into a
/// [`GpuError::Device`].
fn checked<T>(device: &wgpu::Device, what: &str, f: impl FnOnce() -> T) -> Result<T, GpuError> {
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let val = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let out = f();
    let e1 = pollster::block_on(val.pop());
    let e2 = pollster::block_on(oom.pop());
    match e1.or(e2) {
        Some(e) => Err(GpuError::Device(format!("{what}: {e}"))),
        None => Ok(out),
    }
}

fn wait(device: &wgpu::Device) -> Result<(), GpuError> {
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| GpuError::Device(format!("waiting for the device: {e}")))
}

/// Maps `buffer[..len]` for reading, waits, and returns a copy of the bytes.
fn read_back(device: &wgpu::Device, buffer: &wgpu::Buffer, len: u64) -> Result<Vec<u8>, GpuError> {
    let (tx, rx) = mpsc::channel();
    buffer.map_async(wgpu::MapMode::Read, 0..len, move |r| {
        let _ = tx.send(r);
    });
    wait(device)?;
    rx.recv()
        .map_err(|_| GpuError::Device("buffer map callback never ran".into()))?
        .map_err(|e| GpuError::Device(format!("mapping a buffer: {e}")))?;
    let bytes = buffer
        .get_mapped_range(0..len)
        .map_err(|e| GpuError::Device(format!("reading a mapped buffer: {e}")))?
        .to_vec();
    buffer.unmap();
    Ok(bytes)
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
        let wg_max = limits.max_compute_workgroups_per_dimension as usize;
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
            *cache = Some(checked(device, "allocating buffers", || {
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

            // Upload.
            let t = Instant::now();
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
            let mut enc = device.create_command_encoder(&Default::default());
            enc.copy_buffer_to_buffer(eta_buf, 0, read_buf, 0, bytes);
            queue.submit([enc.finish()]);
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

/// Times `reps` dispatches of `pipeline` on `grid` (one compute pass each, timestamps around
/// it) after about `warm_up` of untimed back-to-back dispatches, all in one submission; the
/// warm-up count comes from one timed dispatch first. `None` without timestamp queries.
fn timed_dispatches(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    pipeline: &wgpu::ComputePipeline,
    bind: &wgpu::BindGroup,
    (gx, gy): (u32, u32),
    reps: u32,
    warm_up: Duration,
) -> Result<Option<Vec<f64>>, GpuError> {
    let submit = |warm: u32, reps: u32| -> Result<Option<Vec<f64>>, GpuError> {
        let Some(queries) = Timestamps::with_count(device, "dispatch times", 2 * reps) else {
            return Ok(None);
        };
        let mut enc = device.create_command_encoder(&Default::default());
        if warm > 0 {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, bind, &[]);
            for _ in 0..warm {
                pass.dispatch_workgroups(gx, gy, 1);
            }
        }
        for r in 0..reps {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("timed dispatch"),
                timestamp_writes: Some(queries.writes(Some(2 * r), Some(2 * r + 1))),
            });
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, bind, &[]);
            pass.dispatch_workgroups(gx, gy, 1);
        }
        queries.resolve(&mut enc);
        checked(device, "running timed dispatches", || {
            queue.submit([enc.finish()])
        })?;
        wait(device)?;
        queries.pairs(device, queue).map(Some)
    };
    let warm = if warm_up.is_zero() {
        0
    } else {
        let Some(first) = submit(0, 1)? else {
            return Ok(None);
        };
        (warm_up.as_secs_f64() / first[0].max(1e-6)).ceil().min(1e5) as u32
    };
    submit(warm, reps.max(1))
}

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
