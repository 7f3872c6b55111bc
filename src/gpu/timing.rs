//! Device timing and error capture: timestamp queries around compute passes
//! ([`Timestamps`]), timed back-to-back dispatches ([`timed_dispatches`]), wgpu errors
//! turned into [`GpuError`] ([`checked`]) and waiting for the device ([`wait`]).
//!
//! The kernel uses them internally (its run timings, [`Kernel::dispatch_times`]); they are
//! public only for the bandwidth probes of `quadrecomb bench gpu`, which time their own
//! copies the same way. A caller that evaluates qualities needs none of them.
//!
//! [`Kernel::dispatch_times`]: crate::gpu::Kernel::dispatch_times

use crate::gpu::GpuError;
use std::sync::mpsc;
use std::time::Duration;

/// Device timestamps around compute passes (pairs: 0 and 1 around one pass, ...): the query
/// set, and the buffers its values are resolved into and read back from.
#[derive(Debug)]
pub struct Timestamps {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    count: u32,
}

impl Timestamps {
    /// `None` when the adapter cannot write timestamps.
    pub fn new(device: &wgpu::Device, label: &str) -> Option<Timestamps> {
        Timestamps::with_count(device, label, 2)
    }

    /// Room for `count` timestamps.
    pub(crate) fn with_count(device: &wgpu::Device, label: &str, count: u32) -> Option<Timestamps> {
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
    pub fn writes(
        &self,
        begin: Option<u32>,
        end: Option<u32>,
    ) -> wgpu::ComputePassTimestampWrites<'_> {
        wgpu::ComputePassTimestampWrites {
            query_set: &self.set,
            beginning_of_pass_write_index: begin,
            end_of_pass_write_index: end,
        }
    }

    /// Records the copy of every timestamp to the readback buffer.
    pub fn resolve(&self, enc: &mut wgpu::CommandEncoder) {
        let bytes = 8 * self.count as u64;
        enc.resolve_query_set(&self.set, 0..self.count, &self.resolve, 0);
        enc.copy_buffer_to_buffer(&self.resolve, 0, &self.read, 0, bytes);
    }

    /// Seconds between the two timestamps, once the work has been submitted.
    pub fn seconds(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> Result<f64, GpuError> {
        Ok(self.pairs(device, queue)?[0])
    }

    /// Seconds between timestamps 2k and 2k + 1, for every pair.
    pub(crate) fn pairs(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<f64>, GpuError> {
        let bytes = read_back(device, &self.read, 8 * self.count as u64)?;
        let ticks: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes);
        let period = queue.get_timestamp_period() as f64 * 1e-9;
        Ok(ticks
            .chunks_exact(2)
            .map(|t| t[1].wrapping_sub(t[0]) as f64 * period)
            .collect())
    }
}

/// Runs `f`, turning a wgpu out-of-memory error it raises into a
/// [`GpuError::OutOfMemory`] and a validation error into a [`GpuError::Device`].
pub fn checked<T>(device: &wgpu::Device, what: &str, f: impl FnOnce() -> T) -> Result<T, GpuError> {
    let oom = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
    let val = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let out = f();
    let e1 = pollster::block_on(val.pop());
    let e2 = pollster::block_on(oom.pop());
    // Out of memory first: a buffer that could not be allocated makes every later use of it
    // a validation error, which would hide the cause.
    if let Some(e) = e2 {
        return Err(GpuError::OutOfMemory(format!("{what} (wgpu: {e})")));
    }
    match e1 {
        Some(e) => Err(GpuError::Device(format!("{what}: {e}"))),
        None => Ok(out),
    }
}

/// Waits until the device has finished the work submitted to it.
pub fn wait(device: &wgpu::Device) -> Result<(), GpuError> {
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| GpuError::Device(format!("waiting for the device: {e}")))
}

/// Maps `buffer[..len]` for reading, waits, and returns a copy of the bytes.
pub(crate) fn read_back(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
    len: u64,
) -> Result<Vec<u8>, GpuError> {
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

/// Times `reps` dispatches of `pipeline` on `grid` (one compute pass each, timestamps around
/// it) after about `warm_up` of untimed back-to-back dispatches, all in one submission; the
/// warm-up count comes from one timed dispatch first. `None` without timestamp queries.
pub fn timed_dispatches(
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
