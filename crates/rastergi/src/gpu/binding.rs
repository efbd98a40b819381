//! Declared bind groups: what a pass reads and writes, written once.
//!
//! A [`Group`] names each of its bindings, its kind and whether the pass writes it. The
//! bind-group layout is made from the declaration ([`Group::layout`]), the bind group binds
//! resources by those names ([`Group::bind`]), and the layout test checks every declaration
//! against the WGSL of each shader that uses it: the same binding numbers, names, address
//! spaces, access and element sizes (`layout_test.rs`). A pass's declaration is therefore
//! the one place that says what it reads (`read`, `uniform`, textures) and writes (`write`).

use wgpu::ShaderStages;

/// What one binding holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `var<uniform>` of a struct of `size` bytes.
    Uniform { size: u64 },
    /// `var<storage, read>` (`write` false) or `var<storage, read_write>` of `size`-byte
    /// elements (or of one `size`-byte struct).
    Storage { write: bool, size: u64 },
    /// `texture_2d<u32>` (the G-buffer, ray-view layers).
    UintTexture,
    /// `texture_2d<f32>` read texel by texel with `textureLoad` (tables, the texture atlas).
    FloatTexture,
    /// `texture_storage_2d<rgba32uint, write>` (the ray-cast G-buffer).
    UintStorageTexture,
    /// `acceleration_structure` (hardware ray queries).
    Tlas,
}

/// One named binding of a [`Group`].
#[derive(Clone, Copy, Debug)]
pub struct Slot {
    pub binding: u32,
    /// The WGSL variable's name.
    pub name: &'static str,
    pub kind: Kind,
    /// The stages that see it, where not the group's.
    pub stages: Option<ShaderStages>,
}

impl Slot {
    const fn new(binding: u32, name: &'static str, kind: Kind) -> Slot {
        Slot { binding, name, kind, stages: None }
    }

    /// A uniform buffer holding one `T`.
    pub const fn uniform<T>(binding: u32, name: &'static str) -> Slot {
        Slot::new(binding, name, Kind::Uniform { size: size_of::<T>() as u64 })
    }

    /// A storage buffer of `T`s that the pass reads.
    pub const fn read<T>(binding: u32, name: &'static str) -> Slot {
        Slot::new(binding, name, Kind::Storage { write: false, size: size_of::<T>() as u64 })
    }

    /// A storage buffer of `T`s that the pass writes (and may read).
    pub const fn write<T>(binding: u32, name: &'static str) -> Slot {
        Slot::new(binding, name, Kind::Storage { write: true, size: size_of::<T>() as u64 })
    }

    /// A 2D unsigned-integer texture.
    pub const fn uint_texture(binding: u32, name: &'static str) -> Slot {
        Slot::new(binding, name, Kind::UintTexture)
    }

    /// A 2D float texture read with `textureLoad`.
    pub const fn float_texture(binding: u32, name: &'static str) -> Slot {
        Slot::new(binding, name, Kind::FloatTexture)
    }

    /// A 2D `rgba32uint` texture that the pass writes (`textureStore`).
    pub const fn uint_storage_texture(binding: u32, name: &'static str) -> Slot {
        Slot::new(binding, name, Kind::UintStorageTexture)
    }

    /// A top-level acceleration structure.
    pub const fn tlas(binding: u32, name: &'static str) -> Slot {
        Slot::new(binding, name, Kind::Tlas)
    }

    /// The same binding, seen by `stages` only.
    pub const fn only(self, stages: ShaderStages) -> Slot {
        Slot { stages: Some(stages), ..self }
    }

    /// Whether the pass writes it.
    pub fn writes(&self) -> bool {
        matches!(self.kind, Kind::Storage { write: true, .. } | Kind::UintStorageTexture)
    }

    fn entry(&self, stages: ShaderStages) -> wgpu::BindGroupLayoutEntry {
        let buffer = |ty, size| wgpu::BindingType::Buffer {
            ty,
            has_dynamic_offset: false,
            // wgpu refuses a bound buffer smaller than one element, and a shader whose type
            // there is larger.
            min_binding_size: std::num::NonZeroU64::new(size),
        };
        let texture = |sample_type| wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2,
            multisampled: false,
        };
        let ty = match self.kind {
            Kind::Uniform { size } => buffer(wgpu::BufferBindingType::Uniform, size),
            Kind::Storage { write, size } => buffer(wgpu::BufferBindingType::Storage { read_only: !write }, size),
            Kind::UintTexture => texture(wgpu::TextureSampleType::Uint),
            Kind::FloatTexture => texture(wgpu::TextureSampleType::Float { filterable: false }),
            Kind::UintStorageTexture => wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: wgpu::TextureFormat::Rgba32Uint,
                view_dimension: wgpu::TextureViewDimension::D2,
            },
            Kind::Tlas => wgpu::BindingType::AccelerationStructure { vertex_return: false },
        };
        wgpu::BindGroupLayoutEntry { binding: self.binding, visibility: self.stages.unwrap_or(stages), ty, count: None }
    }
}

/// A bind group as a pass declares it: its label, the stages that see it, its bindings.
#[derive(Clone, Debug)]
pub struct Group {
    pub label: &'static str,
    pub stages: ShaderStages,
    pub slots: Vec<Slot>,
}

impl Group {
    pub fn new(label: &'static str, stages: ShaderStages, slots: &[Slot]) -> Group {
        Group { label, stages, slots: slots.to_vec() }
    }

    /// A compute pass's group.
    pub fn compute(label: &'static str, slots: &[Slot]) -> Group {
        Group::new(label, ShaderStages::COMPUTE, slots)
    }

    /// The layout's entries, one per slot.
    pub fn entries(&self) -> Vec<wgpu::BindGroupLayoutEntry> {
        self.slots.iter().map(|s| s.entry(self.stages)).collect()
    }

    /// The bind-group layout (the device's one of these entries, [`crate::gpu::compiled`]).
    pub fn layout(&self, device: &wgpu::Device) -> wgpu::BindGroupLayout {
        crate::gpu::compiled::bind_group_layout(device, self.label, &self.entries())
    }

    /// A bind group on `layout` (of [`Group::layout`]) binding each named resource to its
    /// slot. Every slot must be given, each once, under its declared name: anything else is
    /// a programming error and panics with the names.
    pub fn bind(
        &self,
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        resources: &[(&str, wgpu::BindingResource)],
    ) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry> = self
            .slots
            .iter()
            .map(|s| {
                let mut given = resources.iter().filter(|(n, _)| *n == s.name);
                let (Some((_, resource)), None) = (given.next(), given.next()) else {
                    panic!("bind group {}: slot `{}` must be given exactly once", self.label, s.name)
                };
                wgpu::BindGroupEntry { binding: s.binding, resource: resource.clone() }
            })
            .collect();
        if let Some((n, _)) = resources.iter().find(|(n, _)| !self.slots.iter().any(|s| s.name == *n)) {
            panic!("bind group {}: no slot named `{n}`", self.label);
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(self.label), layout, entries: &entries })
    }

    /// The layout and a bind group of `resources` (see [`Group::bind`]).
    pub fn layout_and_bind(
        &self,
        device: &wgpu::Device,
        resources: &[(&str, wgpu::BindingResource)],
    ) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
        let layout = self.layout(device);
        let group = self.bind(device, &layout, resources);
        (layout, group)
    }
}
