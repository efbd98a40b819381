//! WGSL composition: a pass's shader is the shared sources (sampling, scene, BVH traversal,
//! per-frame uniforms) followed by the pass's own file. WGSL resolves module-scope names in
//! any order, so the pieces are simply concatenated.

pub const SAMPLING: &str = include_str!("sampling.wgsl");
pub const SCENE: &str = include_str!("gpu_scene.wgsl");
pub const BVH: &str = include_str!("bvh.wgsl");
pub const FRAME: &str = include_str!("frame.wgsl");

/// The common prelude of every pass that reads the scene.
pub fn with_scene(pass: &str) -> String {
    [SAMPLING, SCENE, BVH, FRAME, pass].join("\n")
}

pub fn module(device: &wgpu::Device, label: &str, source: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}
