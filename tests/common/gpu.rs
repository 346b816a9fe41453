//! One compute dispatch of a test kernel on any adapter: how the WGSL-against-Rust tests
//! (`tests/gpu_props.rs`, `tests/gpu_insulation.rs`) run their cases.

use wgpu::util::DeviceExt;

/// A device and queue on any adapter with the adapter's name, or `None` (after printing
/// "skipped") when there is none; with `CRYOSLOSH_REQUIRE_GPU=1` a missing adapter panics.
pub fn device_or_skip() -> Option<(wgpu::Device, wgpu::Queue, String)> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle());
    let found = pollster::block_on(instance.request_adapter(&Default::default()))
        .ok()
        .and_then(|adapter| {
            let name = adapter.get_info().name;
            let (device, queue) =
                pollster::block_on(adapter.request_device(&Default::default())).ok()?;
            Some((device, queue, name))
        });
    if found.is_none() {
        if std::env::var("CRYOSLOSH_REQUIRE_GPU").as_deref() == Ok("1") {
            panic!("CRYOSLOSH_REQUIRE_GPU=1 but no GPU adapter");
        }
        println!("skipped: no GPU adapter");
    }
    found
}

/// Runs `source`'s `main` (workgroup size 64) over `invocations` invocations with `inputs` as
/// read-only storage buffers at bindings 0.. and an `array<f32>` of `out_len` values at the
/// next binding, and returns that array.
pub fn dispatch(
    (device, queue): (&wgpu::Device, &wgpu::Queue),
    label: &str,
    source: &str,
    inputs: &[&[u8]],
    out_len: usize,
    invocations: usize,
) -> Vec<f32> {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    let inputs: Vec<wgpu::Buffer> = inputs
        .iter()
        .map(|contents| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
        })
        .collect();
    let size = (out_len * 4) as u64;
    let out = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("out"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("staging"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let entries: Vec<wgpu::BindGroupEntry> = inputs
        .iter()
        .chain([&out])
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &entries,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(invocations.div_ceil(64) as u32, 1, 1);
    }
    encoder.copy_buffer_to_buffer(&out, 0, &staging, 0, size);
    queue.submit([encoder.finish()]);
    staging.map_async(wgpu::MapMode::Read, .., |r| r.expect("map staging buffer"));
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .expect("poll device");
    let view = staging.get_mapped_range(..).expect("mapped range");
    bytemuck::cast_slice(&view).to_vec()
}
