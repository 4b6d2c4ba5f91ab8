//! The layout contract between a `#[repr(C)]` Rust struct and the GLSL block it fills.
//!
//! [`gpu_block!`](crate::gpu_block) declares the struct and, from the same tokens, its
//! member list ([`GpuBlock::FIELDS`]: names and `offset_of!` offsets), so no field is
//! ever listed twice by hand. Pipelines compare that list with what SPIR-V reflection
//! reads from the compiled shader (`gpu::pipeline::check_block`) when they are built, so
//! a struct and its shader block that disagree fail the first test that builds the pass.

/// One member of a block: its name (as in GLSL) and byte offset (as in Rust).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    pub name: &'static str,
    pub offset: usize,
}

/// A struct that mirrors a GLSL uniform or push-constant block member for member.
pub trait GpuBlock: bytemuck::Pod {
    /// The members in declaration order, as the struct declares them.
    const FIELDS: &'static [Field];
    /// The Rust type's name, for error messages.
    const NAME: &'static str;
}

/// Declares a `#[repr(C)]` struct that mirrors a GLSL block (members in the same order,
/// with the same names, explicit padding members where std140/std430 pads) and
/// implements [`GpuBlock`] for it from the same field list. The struct derives `Clone,
/// Copy, Debug, Default, PartialEq` and bytemuck's `Pod, Zeroable`.
///
/// ```ignore
/// gpu_block! {
///     /// `AccumulatePush` in accumulate.comp.
///     pub struct AccumulatePush {
///         pub width: u32,
///         pub height: u32,
///         pub history_valid: u32,
///         pub weight: f32,
///     }
/// }
/// ```
#[macro_export]
macro_rules! gpu_block {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $($(#[$fmeta:meta])* $fvis:vis $field:ident : $ty:ty),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
        $vis struct $name {
            $($(#[$fmeta])* $fvis $field: $ty),*
        }

        impl $crate::shaders::GpuBlock for $name {
            const FIELDS: &'static [$crate::shaders::Field] = &[
                $($crate::shaders::Field {
                    name: stringify!($field),
                    offset: std::mem::offset_of!($name, $field),
                }),*
            ];
            const NAME: &'static str = stringify!($name);
        }
    };
}
