//! The GPU side of the evaluator: [`adapter`] lists Vulkan adapters and opens a device on
//! one (once, apart from the work); [`kernel`] runs the quality kernel on a device that the
//! caller passes in ([`Kernel`], [`evaluate`]).

mod adapter;
mod kernel;

pub use adapter::{adapter_name, adapters, is_software, open_device};
pub use kernel::{Kernel, KernelOptions, Layout, Timings, evaluate};
