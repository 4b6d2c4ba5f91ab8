//! Compute pipelines built from the embedded SPIR-V. The descriptor-set layout and the
//! push-constant range come from reflection, so the GLSL declaration is the only place a
//! binding number or block size is written; Rust refers to bindings by name.

use super::context::GpuContext;
use super::reflect::{self, Reflection};
use crate::error::{EngineError, Result, VkContext};
use ash::vk;

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
    pub fn new(ctx: &GpuContext, shader: &str, spec: &[(&str, SpecValue)]) -> Result<Self> {
        let words = shader_words(shader)?;
        let reflection = reflect::reflect(&words).map_err(|problem| EngineError::Reflection {
            shader: shader.into(),
            problem,
        })?;
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
        super::resources::set_name(ctx, pipeline, shader);
        Ok(Self {
            name: shader.into(),
            pipeline,
            layout,
            set_layout,
            reflection,
        })
    }

    /// Workgroups needed to cover `w × h` invocations.
    pub fn groups_2d(&self, w: u32, h: u32) -> [u32; 3] {
        let [lx, ly, _] = self.reflection.local_size;
        [w.div_ceil(lx.max(1)), h.div_ceil(ly.max(1)), 1]
    }

    pub fn destroy(&mut self, ctx: &GpuContext) {
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline_layout(self.layout, None);
            ctx.device
                .destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}
