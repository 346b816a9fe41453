//! Adapters and devices: which GPUs wgpu sees (`cryoslosh devices`) and opening one for compute.
//!
//! Software rasterisers (Mesa's llvmpipe/lavapipe) are real Vulkan adapters but slower than the
//! CPU backend, so `--backend auto` takes only hardware; `--backend gpu` takes the best adapter
//! there is, software included (that is how CI runs the WGSL on lavapipe).

use std::fmt::Write as _;

/// Why no GPU could be opened.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found (wgpu, Vulkan). Install a Vulkan driver for your GPU, or Mesa's \
         software driver (Debian/Ubuntu: `apt-get install mesa-vulkan-drivers`) to run the \
         WGSL kernels on the CPU, or use `--backend cpu`"
    )]
    NoAdapter,
    #[error("GPU adapter {adapter} refused a device: {message}")]
    Device { adapter: String, message: String },
    #[error("GPU error: {0}")]
    Runtime(String),
}

/// What `devices` reports for one adapter.
#[derive(Clone, Debug)]
pub struct AdapterSummary {
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    pub max_storage_binding_bytes: u64,
    pub max_buffer_bytes: u64,
    pub max_workgroups_per_dimension: u32,
    pub shader_f64: bool,
    /// A hardware GPU (not a CPU rasteriser or unknown).
    pub hardware: bool,
}

/// An open device and the facts about it the engine needs.
pub struct Gpu {
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: AdapterSummary,
}

fn instance() -> wgpu::Instance {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::VULKAN;
    desc.flags = wgpu::InstanceFlags::empty();
    wgpu::Instance::new(desc)
}

fn is_hardware(t: wgpu::DeviceType) -> bool {
    matches!(
        t,
        wgpu::DeviceType::DiscreteGpu
            | wgpu::DeviceType::IntegratedGpu
            | wgpu::DeviceType::VirtualGpu
    )
}

fn summarize(a: &wgpu::Adapter) -> AdapterSummary {
    let info = a.get_info();
    let limits = a.limits();
    AdapterSummary {
        name: info.name.clone(),
        backend: format!("{:?}", info.backend),
        device_type: format!("{:?}", info.device_type),
        driver: format!("{} {}", info.driver, info.driver_info)
            .trim()
            .to_string(),
        max_storage_binding_bytes: limits.max_storage_buffer_binding_size,
        max_buffer_bytes: limits.max_buffer_size,
        max_workgroups_per_dimension: limits.max_compute_workgroups_per_dimension,
        shader_f64: a.features().contains(wgpu::Features::SHADER_F64),
        hardware: is_hardware(info.device_type),
    }
}

/// Every adapter wgpu can open, best first (discrete, integrated, virtual, CPU, other).
fn ranked_adapters() -> Vec<wgpu::Adapter> {
    let mut all = pollster::block_on(instance().enumerate_adapters(wgpu::Backends::VULKAN));
    let rank = |t: wgpu::DeviceType| match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    };
    all.sort_by_key(|a| rank(a.get_info().device_type));
    all
}

/// All adapters, for `cryoslosh devices`.
pub fn adapters() -> Vec<AdapterSummary> {
    ranked_adapters().iter().map(summarize).collect()
}

/// The `devices` listing, one block per adapter.
pub fn describe_adapters(list: &[AdapterSummary]) -> String {
    if list.is_empty() {
        return format!("{}\n", GpuError::NoAdapter);
    }
    let mut s = String::new();
    for (i, a) in list.iter().enumerate() {
        let _ = writeln!(
            s,
            "[{i}] {} ({}, {}{})\n    driver: {}\n    max storage binding: {} MiB, max buffer: {} MiB, \
             max workgroups per dimension: {}, SHADER_F64: {}",
            a.name,
            a.backend,
            a.device_type,
            if a.hardware { "" } else { ", software: used only with --backend gpu" },
            a.driver,
            a.max_storage_binding_bytes >> 20,
            a.max_buffer_bytes >> 20,
            a.max_workgroups_per_dimension,
            if a.shader_f64 { "yes" } else { "no" },
        );
    }
    s
}

/// Open the best adapter; with `hardware_only`, a software rasteriser does not count.
pub fn open(hardware_only: bool) -> Result<Gpu, GpuError> {
    let adapter = ranked_adapters()
        .into_iter()
        .find(|a| !hardware_only || is_hardware(a.get_info().device_type))
        .ok_or(GpuError::NoAdapter)?;
    let info = summarize(&adapter);
    let limits = adapter.limits();
    let desc = wgpu::DeviceDescriptor {
        label: Some("cryoslosh"),
        required_features: wgpu::Features::empty(),
        required_limits: wgpu::Limits {
            max_storage_buffer_binding_size: limits.max_storage_buffer_binding_size,
            max_buffer_size: limits.max_buffer_size,
            // The kernel binds 8 storage buffers (`GpuEngine::dispatch`): WebGPU's default limit,
            // which every Vulkan, Metal and D3D12 adapter meets.
            max_storage_buffers_per_shader_stage: 8,
            ..wgpu::Limits::downlevel_defaults()
        },
        ..Default::default()
    };
    let (device, queue) =
        pollster::block_on(adapter.request_device(&desc)).map_err(|e| GpuError::Device {
            adapter: info.name.clone(),
            message: e.to_string(),
        })?;
    Ok(Gpu {
        device,
        queue,
        info,
    })
}
