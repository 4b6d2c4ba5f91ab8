//! `#[repr(C)]` mirrors of the GLSL uniform and push-constant blocks. The GLSL in
//! shaders/glsl is the source of truth; `tests::layouts_match_reflection` compares every
//! field offset here with the offsets SPIR-V reflection reads from the compiled shaders.

use bytemuck::{Pod, Zeroable};
use glam::{IVec4, Mat4, UVec4, Vec4};

/// Mirrors `frame.glsl`'s MAX_LIGHTS (scenes are checked against the same number).
pub use crate::scene::light::MAX_LIGHTS;
pub const LIGHT_POINT: f32 = 0.0;
pub const LIGHT_AREA: f32 = 1.0;
pub const LIGHT_ENV: f32 = 2.0;
pub const ENV_CONSTANT: f32 = 0.0;
pub const ENV_GRADIENT: f32 = 1.0;
pub const ENV_MAP: f32 = 2.0;

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable, PartialEq)]
pub struct GpuLight {
    pub position_kind: Vec4,
    pub radiance: Vec4,
    pub u_axis: Vec4,
    pub v_axis: Vec4,
}

/// `FrameBlock` in frame.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniforms {
    pub view_proj: Mat4,
    pub inv_view_proj: Mat4,
    pub prev_view_proj: Mat4,
    pub camera_pos: Vec4,
    pub box_min: Vec4,
    pub box_max: Vec4,
    pub dims: IVec4,
    pub counts: IVec4,
    pub params: Vec4,
    pub seeds: UVec4,
    pub lights: [GpuLight; MAX_LIGHTS],
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct PathTracePush {
    pub sample_offset: u32,
    pub spp: u32,
    pub width: u32,
    pub height: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct FeaturesPush {
    pub width: u32,
    pub height: u32,
    pub step_voxels: f32,
    pub pad: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct MotionPush {
    pub width: u32,
    pub height: u32,
    pub pad0: u32,
    pub pad1: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct AccumulatePush {
    pub width: u32,
    pub height: u32,
    pub history_valid: u32,
    pub weight: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WrlsUpdatePush {
    pub camera: Vec4,
    pub width: u32,
    pub height: u32,
    pub history_valid: u32,
    pub lambda: f32,
    pub alpha: f32,
    pub h: f32,
    pub delta: f32,
    pub tolerance: f32,
    pub change_ratio: f32,
    pub outlier_sigmas: f32,
    pub gradient_valid: u32,
    pub drift_valid: u32,
    pub stratum: u32,
    pub lambda_min: f32,
    pub change_gain: f32,
    pub shrink: f32,
    pub drift_z: f32,
    pub pad0: f32,
    pub pad1: f32,
    pub pad2: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WrlsConstantPush {
    pub camera: Vec4,
    pub width: u32,
    pub height: u32,
    pub history_valid: u32,
    pub lambda: f32,
    pub delta: f32,
    pub tolerance: f32,
    pub change_ratio: f32,
    pub outlier_sigmas: f32,
    pub gradient_valid: u32,
    pub drift_valid: u32,
    pub stratum: u32,
    pub lambda_min: f32,
    pub change_gain: f32,
    pub shrink: f32,
    pub drift_z: f32,
    pub spp: f32,
    pub lambda_moving: f32,
    pub pad0: f32,
    pub pad1: f32,
    pub pad2: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WrlsDriftPush {
    pub width: u32,
    pub height: u32,
    pub radius: i32,
    pub pad0: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WrlsAtrousPush {
    pub width: u32,
    pub height: u32,
    pub step: i32,
    pub kappa: f32,
    pub last: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WrlsGradientPush {
    pub prev_inv_view_proj: Mat4,
    pub prev_camera: Vec4,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub prev_frame: u32,
    pub stratum: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct WrlsSpatialPush {
    pub width: u32,
    pub height: u32,
    pub sigma_spatial: f32,
    pub sigma_range: f32,
    pub kappa: f32,
    pub pad0: f32,
    pub pad1: f32,
    pub pad2: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct TaaPush {
    pub camera: Vec4,
    pub width: u32,
    pub height: u32,
    pub history_valid: u32,
    pub alpha: f32,
    pub gamma: f32,
    pub tolerance: f32,
    pub pad0: f32,
    pub pad1: f32,
}

/// `RaeConvPush` in include/rae_conv.glsl (rae_conv.comp and its fp16 variant; see
/// engine/src/denoise/rae.rs).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct RaeConvPush {
    pub width: u32,
    pub height: u32,
    pub groups_a: u32,
    pub groups_b: u32,
    pub a_upsample: u32,
    pub b_enabled: u32,
    pub weights_offset: u32,
    pub bias_offset: u32,
    pub slope: f32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
}

/// `RaePoolPush` in include/rae_pool.glsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct RaePoolPush {
    pub width: u32,
    pub height: u32,
    pub groups: u32,
    pub pad0: u32,
}

/// `RaeIoPush` in include/rae_io.glsl (the input and output transforms).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct RaeIoPush {
    pub width: u32,
    pub height: u32,
    pub src_width: u32,
    pub src_height: u32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct SvgfTemporalPush {
    pub camera: Vec4,
    pub width: u32,
    pub height: u32,
    pub history_valid: u32,
    pub tolerance: f32,
    pub color_alpha: f32,
    pub moments_alpha: f32,
    pub demod_eps: f32,
    pub feature_step: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct SvgfVariancePush {
    pub width: u32,
    pub height: u32,
    pub min_history: f32,
    pub sigma_z: f32,
    pub sigma_n: f32,
    pub pad0: f32,
    pub pad1: f32,
    pub pad2: f32,
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct SvgfAtrousPush {
    pub width: u32,
    pub height: u32,
    pub step: i32,
    pub modulate: u32,
    pub sigma_z: f32,
    pub sigma_n: f32,
    pub sigma_l: f32,
    pub luminance_eps: f32,
    pub demod_eps: f32,
    pub pad0: f32,
    pub pad1: f32,
    pub pad2: f32,
}

/// `PresentPush` in present.comp.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct PresentPush {
    pub target_width: u32,
    pub target_height: u32,
    pub offset_x: i32,
    pub offset_y: i32,
    pub source_width: u32,
    pub source_height: u32,
    pub split_x: i32,
    pub exposure: f32,
    pub background: Vec4,
}

/// Field names and offsets of a mirror struct, for the layout test.
#[macro_export]
macro_rules! field_offsets {
    ($t:ty { $($f:ident),* $(,)? }) => {
        vec![$((stringify!($f), std::mem::offset_of!($t, $f))),*]
    };
}

/// (shader, block name or "push", size, field offsets) for every mirrored block.
/// A mirrored block: shader, block name (or "push"), Rust size, Rust field offsets.
pub type MirroredLayout = (
    &'static str,
    &'static str,
    usize,
    Vec<(&'static str, usize)>,
);

pub fn mirrored_layouts() -> Vec<MirroredLayout> {
    vec![
        (
            "path_trace",
            "FrameBlock",
            std::mem::size_of::<FrameUniforms>(),
            field_offsets!(FrameUniforms {
                view_proj,
                inv_view_proj,
                prev_view_proj,
                camera_pos,
                box_min,
                box_max,
                dims,
                counts,
                params,
                seeds,
                lights
            }),
        ),
        (
            "path_trace",
            "push",
            std::mem::size_of::<PathTracePush>(),
            field_offsets!(PathTracePush {
                sample_offset,
                spp,
                width,
                height
            }),
        ),
        (
            "surface_features",
            "push",
            std::mem::size_of::<FeaturesPush>(),
            field_offsets!(FeaturesPush {
                width,
                height,
                step_voxels,
                pad
            }),
        ),
        (
            "motion",
            "push",
            std::mem::size_of::<MotionPush>(),
            field_offsets!(MotionPush {
                width,
                height,
                pad0,
                pad1
            }),
        ),
        (
            "accumulate",
            "push",
            std::mem::size_of::<AccumulatePush>(),
            field_offsets!(AccumulatePush {
                width,
                height,
                history_valid,
                weight
            }),
        ),
        (
            "wrls_update",
            "push",
            std::mem::size_of::<WrlsUpdatePush>(),
            field_offsets!(WrlsUpdatePush {
                camera,
                width,
                height,
                history_valid,
                lambda,
                alpha,
                h,
                delta,
                tolerance,
                change_ratio,
                outlier_sigmas,
                gradient_valid,
                drift_valid,
                stratum,
                lambda_min,
                change_gain,
                shrink,
                drift_z,
                pad0,
                pad1,
                pad2
            }),
        ),
        (
            "wrls_constant",
            "push",
            std::mem::size_of::<WrlsConstantPush>(),
            field_offsets!(WrlsConstantPush {
                camera,
                width,
                height,
                history_valid,
                lambda,
                delta,
                tolerance,
                change_ratio,
                outlier_sigmas,
                gradient_valid,
                drift_valid,
                stratum,
                lambda_min,
                change_gain,
                shrink,
                drift_z,
                spp,
                lambda_moving,
                pad0,
                pad1,
                pad2
            }),
        ),
        (
            "wrls_drift",
            "push",
            std::mem::size_of::<WrlsDriftPush>(),
            field_offsets!(WrlsDriftPush {
                width,
                height,
                radius,
                pad0
            }),
        ),
        (
            "wrls_atrous",
            "push",
            std::mem::size_of::<WrlsAtrousPush>(),
            field_offsets!(WrlsAtrousPush {
                width,
                height,
                step,
                kappa,
                last,
                pad0,
                pad1,
                pad2
            }),
        ),
        (
            "wrls_gradient",
            "push",
            std::mem::size_of::<WrlsGradientPush>(),
            field_offsets!(WrlsGradientPush {
                prev_inv_view_proj,
                prev_camera,
                width,
                height,
                spp,
                prev_frame,
                stratum,
                pad0,
                pad1,
                pad2
            }),
        ),
        (
            "wrls_spatial",
            "push",
            std::mem::size_of::<WrlsSpatialPush>(),
            field_offsets!(WrlsSpatialPush {
                width,
                height,
                sigma_spatial,
                sigma_range,
                kappa,
                pad0,
                pad1,
                pad2
            }),
        ),
        (
            "taa",
            "push",
            std::mem::size_of::<TaaPush>(),
            field_offsets!(TaaPush {
                camera,
                width,
                height,
                history_valid,
                alpha,
                gamma,
                tolerance,
                pad0,
                pad1
            }),
        ),
        (
            "rae_conv",
            "push",
            std::mem::size_of::<RaeConvPush>(),
            field_offsets!(RaeConvPush {
                width,
                height,
                groups_a,
                groups_b,
                a_upsample,
                b_enabled,
                weights_offset,
                bias_offset,
                slope,
                pad0,
                pad1,
                pad2
            }),
        ),
        (
            "rae_pool",
            "push",
            std::mem::size_of::<RaePoolPush>(),
            field_offsets!(RaePoolPush {
                width,
                height,
                groups,
                pad0
            }),
        ),
        (
            "rae_input",
            "push",
            std::mem::size_of::<RaeIoPush>(),
            field_offsets!(RaeIoPush {
                width,
                height,
                src_width,
                src_height
            }),
        ),
        (
            "svgf_temporal",
            "push",
            std::mem::size_of::<SvgfTemporalPush>(),
            field_offsets!(SvgfTemporalPush {
                camera,
                width,
                height,
                history_valid,
                tolerance,
                color_alpha,
                moments_alpha,
                demod_eps,
                feature_step
            }),
        ),
        (
            "svgf_variance",
            "push",
            std::mem::size_of::<SvgfVariancePush>(),
            field_offsets!(SvgfVariancePush {
                width,
                height,
                min_history,
                sigma_z,
                sigma_n,
                pad0,
                pad1,
                pad2
            }),
        ),
        (
            "svgf_atrous",
            "push",
            std::mem::size_of::<SvgfAtrousPush>(),
            field_offsets!(SvgfAtrousPush {
                width,
                height,
                step,
                modulate,
                sigma_z,
                sigma_n,
                sigma_l,
                luminance_eps,
                demod_eps,
                pad0,
                pad1,
                pad2
            }),
        ),
        (
            "present",
            "push",
            std::mem::size_of::<PresentPush>(),
            field_offsets!(PresentPush {
                target_width,
                target_height,
                offset_x,
                offset_y,
                source_width,
                source_height,
                split_x,
                exposure,
                background
            }),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::pipeline::shader_reflection;

    #[test]
    fn layouts_match_reflection() {
        for (shader, block, size, fields) in mirrored_layouts() {
            let r = shader_reflection(shader).expect("embedded shader reflects");
            let members = if block == "push" {
                assert_eq!(
                    r.push_constant_size as usize, size,
                    "{shader}: push-constant size differs from the Rust mirror"
                );
                r.push_constants.clone().expect("shader has push constants")
            } else {
                let m = r
                    .blocks
                    .get(block)
                    .unwrap_or_else(|| panic!("{shader} has no block {block}"));
                let end = m
                    .iter()
                    .map(|m| (m.offset + m.size) as usize)
                    .max()
                    .unwrap_or(0);
                assert_eq!(
                    end, size,
                    "{shader}: {block} size differs from the Rust mirror"
                );
                m.clone()
            };
            assert_eq!(
                members.len(),
                fields.len(),
                "{shader}: {block} member count"
            );
            for (m, (name, offset)) in members.iter().zip(&fields) {
                assert_eq!(&m.name, name, "{shader}: {block} member order");
                assert_eq!(
                    m.offset as usize, *offset,
                    "{shader}: {block}.{name} offset"
                );
            }
        }
    }

    #[test]
    fn light_struct_is_four_vec4() {
        assert_eq!(std::mem::size_of::<GpuLight>(), 64);
    }
}
