//! GPU batch evaluation of quad quality: the WGSL kernel `shaders/quad_quality.wgsl` run
//! through wgpu (Vulkan), and its CPU twin ([`cpu`]), which is the oracle in tests and the
//! fallback when no adapter exists.
//!
//! [`Evaluator`] opens a device once per process and fills the eta column of many meshes'
//! candidate tables in one batch. Lower down, [`evaluate`] / [`Kernel`] take a device and a
//! queue from the caller (tests pass a lavapipe device), and [`layout::Batch`] holds several
//! meshes' vertices and candidates concatenated in the kernel's buffer layout.
//!
//! Values are f32 (within 1e-5 of the f64 reference [`crate::quality::quad_eta`]), and each
//! backend is deterministic: the same meshes give the same eta on the same backend, so the
//! searches that read them are reproducible per backend; the backend's name is recorded
//! with every result.

pub mod cpu;
mod device;
pub mod layout;
pub mod shader;
pub mod synthetic;
pub mod timing;

pub use device::{
    Kernel, KernelOptions, Layout, Timings, adapter_name, adapters, evaluate, is_software,
    open_device,
};
pub use layout::Batch;

use crate::mesh::Mesh;
use crate::quality::CandidateTable;

/// Which device computes the qualities.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Backend {
    /// A real GPU if present, else lavapipe (software Vulkan), else the CPU twin.
    #[default]
    Auto,
    /// A Vulkan adapter (the best one, lavapipe included); an error if there is none.
    Gpu,
    /// The CPU twin of the kernel (f32, all cores).
    Cpu,
}

impl std::fmt::Display for Backend {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Backend::Auto => "auto",
            Backend::Gpu => "gpu",
            Backend::Cpu => "cpu",
        })
    }
}

/// Errors of the GPU path. [`GpuError::NoAdapter`] and [`GpuError::RequestDevice`] are the
/// environment's (no driver); [`GpuError::Shader`] and [`GpuError::Device`] are bugs or
/// device failures, [`GpuError::OutOfMemory`] the device's or the host's memory;
/// [`GpuError::BadIndex`] and [`GpuError::TooLarge`] are the caller's input.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// No Vulkan adapter: install a GPU driver, or lavapipe (Debian: mesa-vulkan-drivers),
    /// or use [`Backend::Cpu`].
    #[error(
        "no Vulkan adapter found (install a GPU driver or lavapipe, Debian package \
         mesa-vulkan-drivers, or use the CPU backend)"
    )]
    NoAdapter,
    /// The adapter refused to open a device.
    #[error("could not open a device on {adapter}: {message}")]
    RequestDevice { adapter: String, message: String },
    /// The WGSL source does not parse or validate (message rendered with spans by naga).
    #[error("shader {path} is invalid:\n{message}")]
    Shader { path: String, message: String },
    /// A wgpu validation or device-lost error while running the kernel.
    #[error("GPU error: {0}")]
    Device(String),
    /// The device (or the driver's host-side staging) could not allocate what the kernel's
    /// buffers or transfers need: what was being done, and wgpu's message.
    #[error("out of GPU memory while {0}")]
    OutOfMemory(String),
    /// A candidate refers to a vertex the mesh does not have.
    #[error(
        "candidate {candidate} of mesh {mesh} in the batch refers to vertex {vertex}, \
         but that mesh has {count} vertices"
    )]
    BadIndex {
        mesh: usize,
        candidate: usize,
        vertex: u32,
        count: usize,
    },
    /// The batch cannot be indexed with u32.
    #[error("batch too large: {0}")]
    TooLarge(String),
}

/// What [`Backend::Auto`] decided while opening an [`Evaluator`], for the caller to show
/// ([`Evaluator::notes`]; the library prints nothing).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BackendNote {
    /// An adapter was opened: a real GPU, or a software one when no GPU was found.
    Picked {
        /// The adapter's name, as recorded ([`Evaluator::name`]).
        adapter: String,
        /// Whether it is a software adapter (lavapipe).
        software: bool,
    },
    /// An adapter was found but could not be used; the next one is tried.
    AdapterFailed {
        /// The adapter's name.
        adapter: String,
        /// Why it failed.
        error: String,
    },
    /// No adapter could be used: the CPU twin computes the qualities.
    CpuFallback,
}

impl std::fmt::Display for BackendNote {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BackendNote::Picked {
                adapter,
                software: true,
            } => write!(
                f,
                "no GPU found, using the software Vulkan adapter {adapter}"
            ),
            BackendNote::Picked { adapter, .. } => write!(f, "using the GPU {adapter}"),
            BackendNote::AdapterFailed { adapter, error } => write!(f, "{adapter} failed: {error}"),
            BackendNote::CpuFallback => f.write_str("no usable Vulkan adapter, using the CPU twin"),
        }
    }
}

/// A device (or the CPU twin) opened once, that fills candidate tables' eta.
#[derive(Debug)]
pub struct Evaluator {
    name: String,
    gpu: Option<Gpu>,
    notes: Vec<BackendNote>,
}

#[derive(Debug)]
struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    kernel: Kernel,
}

impl Evaluator {
    /// Opens the device `backend` asks for and builds the kernel (once); with `auto`, which
    /// backend it picked and why is in [`Evaluator::notes`].
    pub fn new(backend: Backend) -> Result<Evaluator, GpuError> {
        if backend == Backend::Cpu {
            return Ok(Evaluator::cpu_twin());
        }
        let found = adapters();
        let mut last_err = None;
        let mut notes = Vec::new();
        for adapter in &found {
            let info = adapter.get_info();
            let opened = open_device(adapter).and_then(|(device, queue)| {
                let kernel = Kernel::new(&device)?;
                Ok(Gpu {
                    device,
                    queue,
                    kernel,
                })
            });
            match opened {
                Ok(gpu) => {
                    if backend == Backend::Auto {
                        notes.push(BackendNote::Picked {
                            adapter: adapter_name(&info),
                            software: is_software(&info),
                        });
                    }
                    return Ok(Evaluator {
                        name: adapter_name(&info),
                        gpu: Some(gpu),
                        notes,
                    });
                }
                Err(e @ GpuError::Shader { .. }) => return Err(e),
                Err(e) => {
                    if backend == Backend::Auto {
                        notes.push(BackendNote::AdapterFailed {
                            adapter: adapter_name(&info),
                            error: e.to_string(),
                        });
                    }
                    last_err = Some(e);
                }
            }
        }
        match backend {
            Backend::Auto => {
                notes.push(BackendNote::CpuFallback);
                Ok(Evaluator {
                    notes,
                    ..Evaluator::cpu_twin()
                })
            }
            _ => Err(last_err.unwrap_or(GpuError::NoAdapter)),
        }
    }

    /// The CPU twin, without looking for adapters.
    pub fn cpu_twin() -> Evaluator {
        Evaluator {
            name: "cpu-twin".to_string(),
            gpu: None,
            notes: Vec::new(),
        }
    }

    /// What [`Backend::Auto`] decided while opening (empty for the other backends), in order.
    pub fn notes(&self) -> &[BackendNote] {
        &self.notes
    }

    /// What computes the qualities, recorded in results: e.g. `vulkan: NVIDIA H200`,
    /// `vulkan: llvmpipe (LLVM 19.1.7, 256 bits)` or `cpu-twin`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// True when a Vulkan device (GPU or lavapipe) computes the qualities.
    pub fn is_device(&self) -> bool {
        self.gpu.is_some()
    }

    /// Evaluates a batch: eta per candidate in batch order, and the phase times (zero for
    /// the CPU twin except `kernel_s`).
    pub fn evaluate(&self, batch: &Batch) -> Result<(Vec<f32>, Timings), GpuError> {
        match &self.gpu {
            Some(g) => g.kernel.run(&g.device, &g.queue, batch),
            None => {
                let t = std::time::Instant::now();
                let eta = cpu::quad_quality(batch);
                let timings = Timings {
                    kernel_s: t.elapsed().as_secs_f64(),
                    ..Timings::default()
                };
                Ok((eta, timings))
            }
        }
    }

    /// Fills the eta column of every table (built with
    /// [`CandidateTable::topology_only`] or [`CandidateTable::build`]) in one batch.
    pub fn fill(&self, jobs: &mut [(&Mesh, &mut CandidateTable)]) -> Result<(), GpuError> {
        let mut batch = Batch::with_capacity(
            jobs.iter().map(|(m, _)| m.vertices.len()).sum(),
            jobs.iter().map(|(_, t)| t.quads.len()).sum(),
            jobs.len(),
        );
        for (mesh, table) in jobs.iter() {
            batch.push(&mesh.vertices, &table.quads)?;
        }
        let (eta, _) = self.evaluate(&batch)?;
        for ((_, table), span) in jobs.iter_mut().zip(&batch.meshes) {
            table.eta.clear();
            table
                .eta
                .extend(eta[span.candidates.clone()].iter().map(|&e| e as f64));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn evaluator_can_be_shared_between_threads() {
        fn shared<T: Send + Sync>() {}
        shared::<Evaluator>();
        shared::<Kernel>();
    }

    #[test]
    fn cpu_twin_fills_empty_and_candidate_free_tables() {
        let ev = Evaluator::cpu_twin();
        ev.fill(&mut []).unwrap();
        let mesh = Mesh::new(crate::mesh::MeshData {
            vertices: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            triangles: vec![[0, 1, 2]],
            ..Default::default()
        })
        .unwrap();
        let mut table = CandidateTable::topology_only(&mesh);
        ev.fill(&mut [(&mesh, &mut table)]).unwrap();
        assert!(table.eta.is_empty());
        assert_eq!(Backend::default().to_string(), "auto");
    }
}
