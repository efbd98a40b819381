//! Pipelines and dispatch sizes: the helpers every pass builds its pipelines with (made once
//! per device through [`crate::gpu::compiled`]); its bind groups are declared
//! ([`crate::gpu::binding`]).

use crate::gpu::Gpu;

impl Gpu {
    /// Runs `module`'s entry point `main` (`@workgroup_size(64)`, bind group 0 = `group` of
    /// the named `resources`) over `n` invocations, submits and waits for nothing: the GPU side
    /// of a CPU twin's test, read back with [`Gpu::read_buffer`].
    pub fn run_once(
        &self,
        label: &str,
        module: &wgpu::ShaderModule,
        group: &crate::gpu::binding::Group,
        resources: &[(&str, wgpu::BindingResource)],
        n: u32,
    ) {
        let (layout, group) = group.layout_and_bind(&self.device, resources);
        let pipeline = compute_pipeline(&self.device, label, module, "main", &[&layout], &[]);
        let mut enc = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        {
            let mut pass =
                enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None });
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(groups(n, 64), 1, 1);
        }
        self.queue.submit([enc.finish()]);
    }

    /// [`Gpu::run_once`] with one more resource, `output`: a zeroed storage buffer made here for
    /// `n` values of `T`, which the invocations write and which is read back once they are done.
    pub fn run_once_read<T: bytemuck::Pod>(
        &self,
        label: &str,
        module: &wgpu::ShaderModule,
        group: &crate::gpu::binding::Group,
        resources: &[(&str, wgpu::BindingResource)],
        output: &str,
        n: usize,
    ) -> crate::error::Result<Vec<T>> {
        let size = (n.max(1) * size_of::<T>()) as u64;
        let buffer = self.zeroed_buffer(label, size, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
        let mut resources = resources.to_vec();
        resources.push((output, buffer.as_entire_binding()));
        self.run_once(label, module, group, &resources, n as u32);
        let bytes = self.read_buffer(&buffer, size)?;
        Ok(bytemuck::cast_slice::<u8, T>(&bytes)[..n].to_vec())
    }
}

/// Runs `pipeline` once per pixel of a `width × height` image (8×8 workgroups) with bind
/// groups 0, 1, … set to `bind_groups`.
pub fn dispatch_pixels(
    pass: &mut wgpu::ComputePass,
    pipeline: &wgpu::ComputePipeline,
    bind_groups: &[&wgpu::BindGroup],
    width: u32,
    height: u32,
) {
    pass.set_pipeline(pipeline);
    for (i, g) in bind_groups.iter().enumerate() {
        pass.set_bind_group(i as u32, *g, &[]);
    }
    pass.dispatch_workgroups(groups(width, 8), groups(height, 8), 1);
}

/// A pipeline layout of bind groups 0, 1, … = `layouts`.
pub fn pipeline_layout(device: &wgpu::Device, label: &str, layouts: &[&wgpu::BindGroupLayout]) -> wgpu::PipelineLayout {
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(|&l| Some(l)).collect();
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layouts,
        immediate_size: 0,
    })
}

/// A render pipeline that draws every triangle of the scene by vertex pulling (`vs_main` of
/// `shader.0`, no vertex buffers, no culling) with bind groups `shader.1`, fragment stage `fs`
/// into one colour `target`; with `depth`, a depth test of that format that keeps the larger
/// depth (the eye's reversed Z; the ray view's back-to-front peel).
pub fn scene_raster_pipeline(
    device: &wgpu::Device,
    label: &str,
    shader: (&wgpu::ShaderModule, &[&wgpu::BindGroupLayout]),
    fs: &str,
    target: wgpu::ColorTargetState,
    depth: Option<wgpu::TextureFormat>,
) -> wgpu::RenderPipeline {
    let (module, layouts) = shader;
    crate::gpu::compiled::raster_pipeline(device, shader, fs, &target, depth, || {
        let layout = pipeline_layout(device, label, layouts);
        let start = web_time::Instant::now();
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: depth.map(|format| wgpu::DepthStencilState {
                format,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(fs),
                compilation_options: Default::default(),
                targets: &[Some(target.clone())],
            }),
            multiview_mask: None,
            cache: None,
        });
        log::debug!("pipeline {label} ({fs}) created in {:.2} s", start.elapsed().as_secs_f64());
        pipeline
    })
}

/// A compute pipeline for `module`'s entry point `entry`, with bind groups `layouts` and values
/// for the shader's pipeline-overridable constants (`override` declarations; none: `&[]`), e.g.
/// [`crate::gpu_scene::GpuScene::pipeline_constants`]: the device's one of them, compiled on
/// first use ([`crate::gpu::compiled`]).
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    entry: &str,
    layouts: &[&wgpu::BindGroupLayout],
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    crate::gpu::compiled::compute_pipeline(device, module, entry, layouts, constants, || {
        let layout = pipeline_layout(device, label, layouts);
        let start = web_time::Instant::now();
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(&layout),
            module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
            cache: None,
        });
        log::debug!("pipeline {label} ({entry}) created in {:.2} s", start.elapsed().as_secs_f64());
        pipeline
    })
}

/// Number of workgroups of `size` needed to cover `n` items.
pub fn groups(n: u32, size: u32) -> u32 {
    n.div_ceil(size)
}
