//! Compute pipelines built from the embedded SPIR-V. The descriptor-set layout and the
//! push-constant range come from reflection, so the GLSL declaration is the only place a
//! binding number or block size is written; Rust refers to bindings by name. Building a
//! pipeline checks the Rust blocks it will be fed against the shader's: the frame block
//! whenever the shader declares it, the push constants for a typed [`Pipeline`].
//!
//! Pipelines live in the context's [`PipelineCache`]: a pass asks for one with
//! [`GpuContext::pipeline`] and keeps the handle; the cache builds each (shader,
//! specialisation) once and destroys them all with the device, so no pass or renderer
//! writes a `destroy`.

use super::context::GpuContext;
use super::reflect::{self, MemberInfo, Reflection};
use crate::error::{EngineError, Result, VkContext};
use crate::shaders::frame::{FrameBlock, FRAME_BLOCK};
use crate::shaders::GpuBlock;
use ash::vk;
use std::collections::HashMap;
use std::marker::PhantomData;
use std::sync::{Arc, Mutex};

/// A value for a specialisation constant, given by the constant's GLSL name.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpecValue {
    Bool(bool),
    U32(u32),
    I32(i32),
    F32(f32),
}

impl SpecValue {
    fn bytes(self) -> [u8; 4] {
        match self {
            SpecValue::Bool(b) => (b as u32).to_ne_bytes(),
            SpecValue::U32(v) => v.to_ne_bytes(),
            SpecValue::I32(v) => v.to_ne_bytes(),
            SpecValue::F32(v) => v.to_ne_bytes(),
        }
    }
}

/// The SPIR-V of an embedded shader, by name (`path_trace` for `path_trace.comp`).
pub fn shader_words(name: &str) -> Result<Vec<u32>> {
    let bytes = crate::shaders::SHADERS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, b)| *b)
        .ok_or_else(|| EngineError::UnknownShader(name.into()))?;
    reflect::words(bytes).map_err(|problem| EngineError::Reflection {
        shader: name.into(),
        problem,
    })
}

/// Reflection of an embedded shader.
pub fn shader_reflection(name: &str) -> Result<Reflection> {
    reflect::reflect(&shader_words(name)?).map_err(|problem| EngineError::Reflection {
        shader: name.into(),
        problem,
    })
}

pub struct ComputePipeline {
    pub name: String,
    pub pipeline: vk::Pipeline,
    pub layout: vk::PipelineLayout,
    pub set_layout: vk::DescriptorSetLayout,
    pub reflection: Reflection,
}

impl ComputePipeline {
    /// Builds a pipeline the caller owns and must [`destroy`](Self::destroy); passes use
    /// [`GpuContext::pipeline`] instead.
    pub(crate) fn new(ctx: &GpuContext, shader: &str, spec: &[(&str, SpecValue)]) -> Result<Self> {
        let words = shader_words(shader)?;
        let reflection = reflect::reflect(&words).map_err(|problem| EngineError::Reflection {
            shader: shader.into(),
            problem,
        })?;
        if let Some(members) = reflection.blocks.get(FRAME_BLOCK) {
            let end = members.iter().map(|m| m.offset + m.size).max().unwrap_or(0);
            check_block::<FrameBlock>(shader, FRAME_BLOCK, members, end)?;
        }
        if let Some(b) = reflection.bindings.iter().find(|b| b.set != 0) {
            return Err(EngineError::Reflection {
                shader: shader.into(),
                problem: format!(
                    "binding {:?} uses set {}; passes use set 0 only",
                    b.name, b.set
                ),
            });
        }
        let d = &ctx.device;
        let layout_bindings: Vec<_> = reflection
            .bindings
            .iter()
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b.binding)
                    .descriptor_type(b.ty)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::COMPUTE)
            })
            .collect();
        let set_info = vk::DescriptorSetLayoutCreateInfo::default()
            .flags(vk::DescriptorSetLayoutCreateFlags::PUSH_DESCRIPTOR_KHR)
            .bindings(&layout_bindings);
        let set_layout = unsafe { d.create_descriptor_set_layout(&set_info, None) }
            .vk("vkCreateDescriptorSetLayout")?;
        let ranges = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::COMPUTE)
            .offset(0)
            .size(reflection.push_constant_size)];
        let set_layouts = [set_layout];
        let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
        if reflection.push_constant_size > 0 {
            if reflection.push_constant_size > ctx.info.max_push_constants_size {
                return Err(EngineError::Reflection {
                    shader: shader.into(),
                    problem: format!(
                        "push constants of {} bytes exceed the device's {}",
                        reflection.push_constant_size, ctx.info.max_push_constants_size
                    ),
                });
            }
            layout_info = layout_info.push_constant_ranges(&ranges);
        }
        let layout =
            unsafe { d.create_pipeline_layout(&layout_info, None) }.vk("vkCreatePipelineLayout")?;

        let mut entries = Vec::new();
        let mut data = Vec::new();
        for (name, value) in spec {
            let id =
                reflection
                    .spec_constants
                    .get(*name)
                    .ok_or_else(|| EngineError::Reflection {
                        shader: shader.into(),
                        problem: format!(
                            "no specialisation constant named {name:?} (has: {:?})",
                            reflection.spec_constants.keys().collect::<Vec<_>>()
                        ),
                    })?;
            entries.push(
                vk::SpecializationMapEntry::default()
                    .constant_id(*id)
                    .offset(data.len() as u32)
                    .size(4),
            );
            data.extend_from_slice(&value.bytes());
        }
        let spec_info = vk::SpecializationInfo::default()
            .map_entries(&entries)
            .data(&data);
        let module_info = vk::ShaderModuleCreateInfo::default().code(&words);
        let module =
            unsafe { d.create_shader_module(&module_info, None) }.vk("vkCreateShaderModule")?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main")
            .specialization_info(&spec_info);
        let info = [vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout)];
        let pipeline =
            unsafe { d.create_compute_pipelines(vk::PipelineCache::null(), &info, None) };
        unsafe { d.destroy_shader_module(module, None) };
        let pipeline = pipeline.map_err(|(_, e)| EngineError::Vk {
            call: "vkCreateComputePipelines",
            result: e,
        })?[0];
        super::context::set_name(ctx, pipeline, shader);
        Ok(Self {
            name: shader.into(),
            pipeline,
            layout,
            set_layout,
            reflection,
        })
    }

    /// Workgroups needed to cover `grid` invocations.
    pub fn groups(&self, grid: [u32; 3]) -> [u32; 3] {
        let local = self.reflection.local_size;
        [0, 1, 2].map(|i| grid[i].div_ceil(local[i].max(1)))
    }

    fn release(&self, ctx: &GpuContext) {
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline_layout(self.layout, None);
            ctx.device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

/// Checks that `T` mirrors the reflected block `block` of `shader` (members `members`,
/// `size` bytes): same size, same member names in the same order at the same offsets.
pub fn check_block<T: GpuBlock>(
    shader: &str,
    block: &str,
    members: &[MemberInfo],
    size: u32,
) -> Result<()> {
    let fail = |problem: String| {
        Err(EngineError::Reflection {
            shader: shader.into(),
            problem: format!("{block} and its Rust mirror {}: {problem}", T::NAME),
        })
    };
    let rust_size = std::mem::size_of::<T>();
    if size as usize != rust_size {
        return fail(format!("{size} bytes in GLSL, {rust_size} in Rust"));
    }
    if members.len() != T::FIELDS.len() {
        return fail(format!(
            "{} members in GLSL, {} in Rust",
            members.len(),
            T::FIELDS.len()
        ));
    }
    for (m, f) in members.iter().zip(T::FIELDS) {
        if m.name != f.name || m.offset as usize != f.offset {
            return fail(format!(
                "GLSL has {} at offset {} where Rust has {} at {}",
                m.name, m.offset, f.name, f.offset
            ));
        }
    }
    Ok(())
}

/// A shared compute pipeline fed push constants of type `P` (checked against the
/// shader's push-constant block when it was built).
pub struct Pipeline<P> {
    inner: Arc<ComputePipeline>,
    push: PhantomData<fn(&P)>,
}

impl<P> Clone for Pipeline<P> {
    fn clone(&self) -> Self {
        Self {
            inner: Arc::clone(&self.inner),
            push: PhantomData,
        }
    }
}

impl<P> std::ops::Deref for Pipeline<P> {
    type Target = ComputePipeline;
    fn deref(&self) -> &ComputePipeline {
        &self.inner
    }
}

/// Key of a cached pipeline: the shader and its specialisation constants' names and bytes.
type PipelineKey = (String, Vec<(String, [u8; 4])>);

/// The context's compute pipelines, one per shader and specialisation.
#[derive(Default)]
pub struct PipelineCache {
    pipelines: Mutex<HashMap<PipelineKey, Arc<ComputePipeline>>>,
}

impl PipelineCache {
    /// Destroys every pipeline (the context does, before the device goes). Handles
    /// that passes still hold are dead from here on, as is the device they need.
    pub(crate) fn destroy(&self, ctx: &GpuContext) {
        let mut map = self.pipelines.lock().unwrap_or_else(|e| e.into_inner());
        for (_, p) in map.drain() {
            p.release(ctx);
        }
    }
}

impl GpuContext {
    /// The pipeline of `shader` specialised with `spec`, fed push constants `P`: built on
    /// first use, then shared. Fails if `P` does not mirror the shader's push-constant
    /// block.
    pub fn pipeline<P: GpuBlock>(
        &self,
        shader: &str,
        spec: &[(&str, SpecValue)],
    ) -> Result<Pipeline<P>> {
        let key = (
            shader.to_string(),
            spec.iter()
                .map(|(n, v)| (n.to_string(), v.bytes()))
                .collect::<Vec<_>>(),
        );
        let mut map = self
            .pipelines
            .pipelines
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        let inner = match map.get(&key) {
            Some(p) => Arc::clone(p),
            None => {
                let p = Arc::new(ComputePipeline::new(self, shader, spec)?);
                map.insert(key, Arc::clone(&p));
                p
            }
        };
        let r = &inner.reflection;
        let Some(members) = &r.push_constants else {
            return Err(EngineError::Reflection {
                shader: shader.into(),
                problem: format!("has no push constants, but is fed {}", P::NAME),
            });
        };
        check_block::<P>(shader, "push constants", members, r.push_constant_size)?;
        Ok(Pipeline {
            inner,
            push: PhantomData,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu_block;
    use glam::Vec4;

    gpu_block! {
        struct Misnamed {
            width: u32,
            height: u32,
            history: u32,
            weight: f32,
        }
    }

    gpu_block! {
        struct Short {
            width: u32,
            height: u32,
        }
    }

    gpu_block! {
        struct Accumulate {
            width: u32,
            height: u32,
            history_valid: u32,
            weight: f32,
        }
    }

    gpu_block! {
        struct Padded {
            a: Vec4,
        }
    }

    fn push_of(shader: &str) -> (Vec<MemberInfo>, u32) {
        let r = shader_reflection(shader).expect("reflects");
        (
            r.push_constants.expect("has push constants"),
            r.push_constant_size,
        )
    }

    #[test]
    fn block_check_reads_the_struct() {
        let (members, size) = push_of("accumulate");
        assert!(check_block::<Accumulate>("accumulate", "push", &members, size).is_ok());
        let misnamed = check_block::<Misnamed>("accumulate", "push", &members, size)
            .expect_err("a renamed member is caught")
            .to_string();
        assert!(
            misnamed.contains("history_valid") && misnamed.contains("history"),
            "{misnamed}"
        );
        let short = check_block::<Short>("accumulate", "push", &members, size)
            .expect_err("a missing member is caught")
            .to_string();
        assert!(short.contains("16 bytes in GLSL, 8 in Rust"), "{short}");
        // Same size, different members.
        assert!(check_block::<Padded>("accumulate", "push", &members, size).is_err());
    }

    #[test]
    fn frame_block_matches_every_shader_that_declares_it() {
        let mut checked = 0;
        for (name, _) in crate::shaders::SHADERS {
            let r = shader_reflection(name).expect("reflects");
            if let Some(members) = r.blocks.get(FRAME_BLOCK) {
                let end = members.iter().map(|m| m.offset + m.size).max().unwrap_or(0);
                check_block::<FrameBlock>(name, FRAME_BLOCK, members, end).expect("matches");
                checked += 1;
            }
        }
        assert!(
            checked >= 5,
            "only {checked} shaders declare the frame block"
        );
    }
}
