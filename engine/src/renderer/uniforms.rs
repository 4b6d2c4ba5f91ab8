//! The push-constant blocks of `denoise/wrls.rs`, not yet beside it: every other pass
//! declares its block in its own file with `gpu_block!` (engine/src/shaders/block.rs),
//! which derives the member list from the struct and is checked against reflection when
//! the pipeline is built. These five keep the older hand-written list below
//! (`mirrored_layouts`), checked by `tests::layouts_match_reflection`, until wrls.rs moves
//! to the typed pipelines; then this file goes.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec4};

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
}
