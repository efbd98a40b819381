// Per-iteration uniforms, bind group 1 (frame.rs).

struct Frame {
    view_proj: mat4x4f,
    eye: vec3f,
    iteration: u32,
    resolution: vec2u,
    seed: u32,
    light_samples: u32,
    ray_epsilon: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(1) @binding(0) var<uniform> frame: Frame;
