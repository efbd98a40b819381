//! Structs that Rust and WGSL share, declared once, in Rust: [`gpu_struct!`] defines the
//! `#[repr(C)]` plain-old-data struct a pass uploads and generates its WGSL declaration
//! ([`GpuStruct::wgsl`]), which the pass composes into its shader in place of a hand-written
//! twin. The layout test (`layout_test.rs`) parses every declaration with naga and checks each
//! member's offset and the struct's size against Rust's (`offset_of!`, `size_of`).
//!
//! A field's WGSL type follows from its Rust type ([`WgslType`]: `f32`, `u32`, `i32`,
//! `[f32; 2..4]` → `vec2f..vec4f`, `[u32; 2..4]` → `vec2u..vec4u`, or another shared struct),
//! or is given after `as` (`[[f32; 4]; 4] as "mat4x4f"`). A field whose name begins with
//! `_pad` is padding: it becomes one scalar member per lane (`_pad0: u32, _pad1: u32, …`),
//! since a `vec3u` would be aligned to 16 bytes where Rust's `[u32; 3]` is aligned to 4.

/// The WGSL type of a Rust field type: its name, and for padding its scalar and lanes.
pub trait WgslType {
    const WGSL: &'static str;
    const SCALAR: &'static str;
    const LANES: usize;
}

macro_rules! wgsl_types {
    ($($ty:ty => $wgsl:literal, $scalar:literal, $lanes:literal;)*) => {
        $(impl WgslType for $ty {
            const WGSL: &'static str = $wgsl;
            const SCALAR: &'static str = $scalar;
            const LANES: usize = $lanes;
        })*
    };
}

wgsl_types! {
    f32 => "f32", "f32", 1;
    u32 => "u32", "u32", 1;
    i32 => "i32", "i32", 1;
    [f32; 2] => "vec2f", "f32", 2;
    [f32; 3] => "vec3f", "f32", 3;
    [f32; 4] => "vec4f", "f32", 4;
    [u32; 2] => "vec2u", "u32", 2;
    [u32; 3] => "vec3u", "u32", 3;
    [u32; 4] => "vec4u", "u32", 4;
}

/// One member of a shared struct as Rust lays it out.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Member {
    pub name: &'static str,
    /// Its WGSL type; for padding, the scalar type of each lane.
    pub wgsl: &'static str,
    /// Lanes of padding (0 for a member that is not padding).
    pub pad_lanes: usize,
    pub offset: usize,
    /// Its doc comment's lines.
    pub doc: &'static [&'static str],
}

/// A struct declared by [`gpu_struct!`].
pub trait GpuStruct: bytemuck::Pod {
    /// Its name in WGSL.
    const WGSL_NAME: &'static str;
    /// Its members in order, with Rust's offsets.
    fn members() -> Vec<Member>;

    /// The WGSL declaration: the struct with its members' doc comments.
    fn wgsl() -> String {
        let mut s =
            format!("// {} (generated from Rust: gpu/structs.rs).\nstruct {} {{\n", Self::WGSL_NAME, Self::WGSL_NAME);
        for m in Self::members() {
            for line in m.doc {
                s += &format!("    //{line}\n");
            }
            if m.pad_lanes > 1 {
                for k in 0..m.pad_lanes {
                    s += &format!("    {}{k}: {},\n", m.name, m.wgsl);
                }
            } else {
                s += &format!("    {}: {},\n", m.name, m.wgsl);
            }
        }
        s + "}\n"
    }
}

/// Declares a `#[repr(C)]` struct shared with WGSL (module docs): the Rust struct, deriving
/// `Clone, Copy, Debug, Pod, Zeroable` (and what its own attributes add), and its
/// [`GpuStruct`] and [`WgslType`] impls.
///
/// ```text
/// gpu_struct! {
///     /// `Resolve` in `resolve.wgsl`.
///     pub(crate) struct ResolveUniforms as "Resolve" {
///         pub(crate) resolution: [u32; 2],
///         pub(crate) _pad: [u32; 2],
///     }
/// }
/// ```
macro_rules! gpu_struct {
    (
        $(#[$attr:meta])*
        $vis:vis struct $name:ident as $wgsl_name:literal {
            $(
                $(#[doc = $doc:literal])*
                $fvis:vis $field:ident : $ty:ty $(as $wgsl:literal)?
            ),* $(,)?
        }
    ) => {
        $(#[$attr])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
        $vis struct $name {
            $($(#[doc = $doc])* $fvis $field: $ty,)*
        }

        impl $crate::gpu::structs::GpuStruct for $name {
            const WGSL_NAME: &'static str = $wgsl_name;
            fn members() -> Vec<$crate::gpu::structs::Member> {
                vec![$($crate::gpu::structs::member(
                    stringify!($field),
                    $crate::gpu::structs::wgsl_of!($ty $(, $wgsl)?),
                    ::core::mem::offset_of!($name, $field),
                    &[$($doc),*],
                ),)*]
            }
        }

        impl $crate::gpu::structs::WgslType for $name {
            const WGSL: &'static str = $wgsl_name;
            const SCALAR: &'static str = $wgsl_name;
            const LANES: usize = 1;
        }
    };
}
pub(crate) use gpu_struct;

/// A field's WGSL type, its scalar and its lanes: those of its Rust type ([`WgslType`]), or
/// the type given after `as` (never padding).
macro_rules! wgsl_of {
    ($ty:ty, $wgsl:literal) => {
        ($wgsl, $wgsl, 0)
    };
    ($ty:ty) => {
        (
            <$ty as $crate::gpu::structs::WgslType>::WGSL,
            <$ty as $crate::gpu::structs::WgslType>::SCALAR,
            <$ty as $crate::gpu::structs::WgslType>::LANES,
        )
    };
}
pub(crate) use wgsl_of;

/// The [`Member`] of field `name` of WGSL type, scalar and lanes `ty` ([`wgsl_of!`]): a field
/// named `_pad…` is padding, one scalar per lane.
pub fn member(
    name: &'static str,
    (wgsl, scalar, lanes): (&'static str, &'static str, usize),
    offset: usize,
    doc: &'static [&'static str],
) -> Member {
    let pad = name.starts_with("_pad");
    Member { name, wgsl: if pad { scalar } else { wgsl }, pad_lanes: if pad { lanes } else { 0 }, offset, doc }
}

#[cfg(test)]
mod tests {
    use super::*;

    gpu_struct! {
        /// A struct with each kind of member (only its declaration is read).
        #[allow(dead_code)]
        struct Sample as "Sample" {
            /// Where: three floats, then a word in the vector's fourth lane.
            origin: [f32; 3],
            flags: u32,
            view: [[f32; 4]; 4] as "mat4x4f",
            nested: Inner,
            _pad: [u32; 3],
        }
    }

    gpu_struct! {
        #[allow(dead_code)]
        struct Inner as "InnerName" {
            size: [u32; 2],
            _pad: u32,
            scale: f32,
        }
    }

    /// The declaration written out by hand: types from Rust's, the `as` override, the nested
    /// struct by its WGSL name, padding as scalars, docs as comments.
    #[test]
    fn the_generated_declaration_is_the_wgsl_one_would_write() {
        let expected = "// Sample (generated from Rust: gpu/structs.rs).\nstruct Sample {\n    \
                        // Where: three floats, then a word in the vector's fourth lane.\n    \
                        origin: vec3f,\n    flags: u32,\n    view: mat4x4f,\n    nested: InnerName,\n    \
                        _pad0: u32,\n    _pad1: u32,\n    _pad2: u32,\n}\n";
        assert_eq!(Sample::wgsl(), expected);
        assert_eq!(Inner::wgsl().lines().nth(3), Some("    _pad: u32,"));
        let offsets: Vec<usize> = Sample::members().iter().map(|m| m.offset).collect();
        assert_eq!(offsets, [0, 12, 16, 80, 96]);
    }
}
