//! Vulkan adapters and devices, created once and apart from the work: every adapter the
//! loader reports, ranked, and a device opened on one with its own limits.

use crate::gpu::GpuError;

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
