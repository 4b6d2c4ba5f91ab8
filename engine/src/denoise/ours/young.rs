//! `<name>.young_*` (ours_young_input.comp, ours_young_conv.comp, ours_young_kernel.comp):
//! a small trained network that estimates a frame on its own, for the frames where every
//! state of the filter restarted (the first frame, after a reset or a resize), whose
//! output is otherwise one frame's samples filtered in space. The network is defined and
//! trained in `tools/young/` (model.py, train.py) and exported by `tools/young/export.py`
//! as `assets/young/young.{json,bin}`; these passes are its mirror, and tests/young.rs
//! holds them to torch's output:
//!
//! - `young_input`: per pixel log(1 + noisy), the guide albedo, the surface normal and
//!   log(1 + ours' estimate), averaged over 2×2 pixels;
//! - `young_trunk0..`: 3×3 convolutions at half resolution, dilated (1, 2, 4, 8, 1 in the
//!   shipped network), each with a leaky ReLU;
//! - `young_head`: a 1×1 convolution to nine logits per kernel level and one blend logit;
//! - `young_level0..`: at full resolution, the logits upsampled bilinearly and
//!   softmax-normalised weigh 3×3 taps (dilations 1, 2, 4, 8) of the noisy radiance, one
//!   level after another, so the estimate is a convex combination of the frame's pixels;
//!   the last level blends it with ours' estimate by the blend logit's sigmoid.
//!
//! Tensors are images with four channels per texel, the channel groups of a
//! half-resolution tensor tiled a few to a row ([`Layout`]), so that every frame size the
//! device renders keeps them within its 2D image limit.

use crate::denoise::rae::{groups, read_weight_floats, weight_buffer, weights_error};
use crate::error::Result;
use crate::gpu::{GpuContext, ImageDesc, Pipeline, SpecValue};
use crate::gpu_block;
use crate::graph::{BufferHandle, Extent, Frame, ImageHandle, RenderGraph};
use ash::vk;
use std::cell::Cell;
use std::path::{Path, PathBuf};

gpu_block! {
    /// `OursYoungInputPush` in ours_young_input.comp.
    pub struct OursYoungInputPush {
        pub width: u32,
        pub height: u32,
        pub columns: u32,
        pub pad0: u32,
    }
}

gpu_block! {
    /// `OursYoungConvPush` in ours_young_conv.comp.
    pub struct OursYoungConvPush {
        pub width: u32,
        pub height: u32,
        pub groups_in: u32,
        pub radius: i32,
        pub dilation: i32,
        pub weights_offset: u32,
        pub bias_offset: u32,
        pub slope: f32,
        pub columns: u32,
        pub pad0: u32,
        pub pad1: u32,
        pub pad2: u32,
    }
}

gpu_block! {
    /// `OursYoungKernelPush` in ours_young_kernel.comp.
    pub struct OursYoungKernelPush {
        pub width: u32,
        pub height: u32,
        pub first_logit: u32,
        pub dilation: i32,
        pub blend_logit: u32,
        pub last: u32,
        pub columns: u32,
        pub pad0: u32,
    }
}

/// The manifest format this engine reads.
pub const FORMAT: &str = "dvr-young-1";
/// The network's inputs per pixel: log noisy radiance, guide albedo, surface normal and
/// log ours' estimate, three channels each (ours_young_input.comp writes them).
pub const YOUNG_FEATURES: u32 = 12;
/// The largest width and dilation a manifest may give (a guard against a corrupt file,
/// far above the shipped network's 12 channels and dilation 8).
const YOUNG_MAX: u32 = 64;

/// One convolution as the shaders see it.
#[derive(Clone, Debug, PartialEq, Eq, serde::Deserialize)]
pub struct YoungLayer {
    pub name: String,
    pub inputs: u32,
    pub outputs: u32,
    /// 9 (3×3) in the trunk, 1 in the head.
    pub taps: u32,
    pub dilation: u32,
    /// In floats.
    pub weights_offset: u64,
    pub bias_offset: u64,
}

impl YoungLayer {
    fn weight_floats(&self) -> u64 {
        u64::from(groups(self.outputs) * groups(self.inputs) * self.taps * 16)
    }
}

#[derive(serde::Deserialize)]
struct Manifest {
    format: String,
    width: u32,
    trunk_dilations: Vec<u32>,
    kernel_dilations: Vec<u32>,
    leaky_relu_slope: f32,
    weights: String,
    floats: u64,
    layers: Vec<YoungLayer>,
}

/// The network's weights and shape, checked against its manifest.
#[derive(Clone, Debug)]
pub struct YoungWeights {
    pub manifest: PathBuf,
    pub width: u32,
    pub kernel_dilations: Vec<u32>,
    pub slope: f32,
    /// The trunk's convolutions, then the head.
    pub layers: Vec<YoungLayer>,
    pub floats: Vec<f32>,
}

impl YoungWeights {
    /// The shipped network, `<assets>/young/young.json` and the weight file it names.
    pub fn builtin() -> Result<Self> {
        Self::load(&crate::assets::young_manifest())
    }

    /// Reads a manifest and its weight file; every inconsistency (format, layer list,
    /// offsets, file size, non-finite weights) is an error naming the file.
    pub fn load(manifest_path: &Path) -> Result<Self> {
        let bad = |problem: String| weights_error(manifest_path, problem);
        let text = crate::files::read_text(manifest_path, crate::files::MAX_TEXT_FILE_BYTES)
            .map_err(|e| bad(format!("cannot read: {e}")))?;
        let m: Manifest = serde_json::from_str(&text)
            .map_err(|e| bad(format!("not a young-pixel network manifest: {e}")))?;
        if m.format != FORMAT {
            return Err(bad(format!("format {:?}, expected {FORMAT:?}", m.format)));
        }
        let in_range = |v: &u32| (1..=YOUNG_MAX).contains(v);
        if !in_range(&m.width)
            || m.trunk_dilations.is_empty()
            || m.kernel_dilations.is_empty()
            || !m
                .trunk_dilations
                .iter()
                .chain(&m.kernel_dilations)
                .all(in_range)
        {
            return Err(bad(format!(
                "width {} and dilations {:?}, {:?}: need 1..={YOUNG_MAX}, at least one of each",
                m.width, m.trunk_dilations, m.kernel_dilations
            )));
        }
        if !m.leaky_relu_slope.is_finite() {
            return Err(bad("the leaky ReLU slope is not finite".into()));
        }
        // The architecture the shaders run, layer by layer.
        let trunk = m.trunk_dilations.iter().enumerate().map(|(i, &d)| {
            let inputs = if i == 0 { YOUNG_FEATURES } else { m.width };
            (format!("trunk{i}"), inputs, m.width, 9, d)
        });
        let outputs = 9 * m.kernel_dilations.len() as u32 + 1;
        let specs: Vec<_> = trunk
            .chain([("head".into(), m.width, outputs, 1, 1)])
            .collect();
        if specs.len() != m.layers.len() {
            return Err(bad(format!(
                "{} layers, the architecture has {}",
                m.layers.len(),
                specs.len()
            )));
        }
        let mut end = 0u64;
        for ((name, inputs, outputs, taps, dilation), l) in specs.iter().zip(&m.layers) {
            let want = (name, *inputs, *outputs, *taps, *dilation);
            if (&l.name, l.inputs, l.outputs, l.taps, l.dilation) != want {
                return Err(bad(format!(
                    "layer {:?} ({} -> {}, {} taps, dilation {}) where the architecture has {want:?}",
                    l.name, l.inputs, l.outputs, l.taps, l.dilation
                )));
            }
            if l.weights_offset != end || l.bias_offset != end + l.weight_floats() {
                return Err(bad(format!(
                    "layer {name:?}: offsets do not follow the packed layout"
                )));
            }
            end = l.bias_offset + u64::from(groups(l.outputs) * 4);
        }
        if end != m.floats {
            return Err(bad(format!(
                "manifest says {} floats, its layers need {end}",
                m.floats
            )));
        }
        let floats = read_weight_floats(manifest_path, &m.weights, end)?;
        Ok(Self {
            manifest: manifest_path.to_path_buf(),
            width: m.width,
            kernel_dilations: m.kernel_dilations,
            slope: m.leaky_relu_slope,
            layers: m.layers,
            floats,
        })
    }

    fn head(&self) -> &YoungLayer {
        // load() checked that the list ends with the head.
        &self.layers[self.layers.len() - 1]
    }
}

/// How a frame's tensors are laid out: each channel group a half-resolution tile, tiled
/// `columns` to a row (include/ours_young.glsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Pixels per group.
    pub width: u32,
    pub height: u32,
    pub columns: u32,
}

impl Layout {
    /// The layout for a frame of `size` whose widest tensor has `groups` channel groups,
    /// within `limit` texels a side; None where no tiling fits.
    pub fn new(size: Extent, groups: u32, limit: u32) -> Option<Self> {
        let (width, height) = (size.width.div_ceil(2), size.height.div_ceil(2));
        let columns = groups.min(limit / width.max(1));
        let fits = columns > 0 && groups.div_ceil(columns) * height <= limit;
        fits.then_some(Self {
            width,
            height,
            columns,
        })
    }

    /// A tensor of `channels` channels.
    fn tensor(&self, channels: u32) -> ImageDesc {
        let g = groups(channels);
        ImageDesc::d2(
            self.width * g.min(self.columns),
            self.height * g.div_ceil(self.columns),
            vk::Format::R32G32B32A32_SFLOAT,
        )
    }
}

/// What the network reads (full-resolution rgba32f images).
#[derive(Clone, Copy, Debug)]
pub struct YoungInputs {
    pub noisy: ImageHandle,
    /// The guide albedo composited along each ray (rgb).
    pub albedo: ImageHandle,
    /// The surface features' gradient normal (xyz; zero where a ray finds no surface).
    pub normal: ImageHandle,
    /// Ours' estimate of the frame (rgb).
    pub ours: ImageHandle,
}

/// The network's pipelines and weights.
pub struct YoungNet {
    pub weights: YoungWeights,
    input: Pipeline<OursYoungInputPush>,
    trunk: Pipeline<OursYoungConvPush>,
    head: Pipeline<OursYoungConvPush>,
    kernel: Pipeline<OursYoungKernelPush>,
    /// The weight buffer this instance last filled (filled once per graph buffer).
    uploaded: Cell<Option<BufferHandle>>,
}

impl YoungNet {
    pub fn new(ctx: &GpuContext, weights: YoungWeights) -> Result<Self> {
        let conv = |outputs: u32| {
            let spec = [("GROUPS_OUT", SpecValue::I32(groups(outputs) as i32))];
            ctx.pipeline("ours_young_conv", &spec)
        };
        Ok(Self {
            input: ctx.pipeline("ours_young_input", &[])?,
            trunk: conv(weights.width)?,
            head: conv(weights.head().outputs)?,
            kernel: ctx.pipeline("ours_young_kernel", &[])?,
            weights,
            uploaded: Cell::new(None),
        })
    }

    /// The layout of a frame of `size`'s tensors on this device; None where they cannot
    /// fit its image limit (a frame tens of thousands of pixels wide).
    pub fn layout(&self, ctx: &GpuContext, size: Extent) -> Option<Layout> {
        let widest = groups(self.weights.head().outputs).max(groups(YOUNG_FEATURES));
        let widest = widest.max(groups(self.weights.width));
        Layout::new(size, widest, ctx.info.max_image_dimension_2d)
    }

    /// Adds the network's passes (`<name>.young_*`) for a frame of `size` laid out as
    /// `layout`; returns its estimate (rgba32f, a 1).
    #[allow(clippy::too_many_arguments)]
    pub fn add<'f>(
        &'f self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        name: &str,
        size: Extent,
        layout: Layout,
        inputs: YoungInputs,
    ) -> Result<ImageHandle> {
        let wts = &self.weights;
        let buffer = format!("{name}.young_weights");
        let weights = weight_buffer(ctx, graph, &buffer, &wts.floats, &self.uploaded)?;
        let (hw, hh, columns) = (layout.width, layout.height, layout.columns);
        let tensor = |channels: u32| layout.tensor(channels);
        let features = graph.image(ctx, &format!("{name}.young_x"), tensor(YOUNG_FEATURES))?;
        let push = OursYoungInputPush {
            width: size.width,
            height: size.height,
            columns,
            pad0: 0,
        };
        frame.add_compute(
            format!("{name}.young_input"),
            &self.input,
            push,
            [hw, hh, 1],
            |b| {
                b.read("noisy", inputs.noisy)
                    .read("albedo", inputs.albedo)
                    .read("normal", inputs.normal)
                    .read("ours", inputs.ours)
                    .write("dst", features);
            },
        );
        let hidden = [
            graph.image(ctx, &format!("{name}.young_a"), tensor(wts.width))?,
            graph.image(ctx, &format!("{name}.young_b"), tensor(wts.width))?,
        ];
        let head = wts.head();
        let logits = graph.image(ctx, &format!("{name}.young_logits"), tensor(head.outputs))?;
        let mut src = features;
        let trunk = wts.layers.len() - 1;
        for (i, layer) in wts.layers.iter().enumerate() {
            let is_head = i == trunk;
            let dst = if is_head { logits } else { hidden[i % 2] };
            let push = OursYoungConvPush {
                width: hw,
                height: hh,
                groups_in: groups(layer.inputs),
                radius: (layer.taps > 1) as i32,
                dilation: layer.dilation as i32,
                weights_offset: (layer.weights_offset / 4) as u32,
                bias_offset: (layer.bias_offset / 4) as u32,
                slope: if is_head { 1.0 } else { wts.slope },
                columns,
                pad0: 0,
                pad1: 0,
                pad2: 0,
            };
            let (pass, pipeline) = match is_head {
                true => (format!("{name}.young_head"), &self.head),
                false => (format!("{name}.young_trunk{i}"), &self.trunk),
            };
            frame.add_compute(pass, pipeline, push, [hw, hh, 1], |b| {
                b.read("src", src)
                    .write("dst", dst)
                    .read("weights", weights);
            });
            src = dst;
        }
        let desc = ImageDesc::d2(size.width, size.height, vk::Format::R32G32B32A32_SFLOAT);
        let out = graph.image(ctx, &format!("{name}.young"), desc)?;
        let levels = [
            graph.image(ctx, &format!("{name}.young_y0"), desc)?,
            graph.image(ctx, &format!("{name}.young_y1"), desc)?,
        ];
        let count = wts.kernel_dilations.len();
        let mut src = inputs.noisy;
        for (l, &dilation) in wts.kernel_dilations.iter().enumerate() {
            let last = l + 1 == count;
            let dst = if last { out } else { levels[l % 2] };
            let push = OursYoungKernelPush {
                width: size.width,
                height: size.height,
                first_logit: 9 * l as u32,
                dilation: dilation as i32,
                blend_logit: 9 * count as u32,
                last: last as u32,
                columns,
                pad0: 0,
            };
            frame.add_compute(
                format!("{name}.young_level{l}"),
                &self.kernel,
                push,
                size,
                |b| {
                    b.read("src", src)
                        .read("logits", logits)
                        .read("ours", inputs.ours)
                        .write("dst", dst);
                },
            );
            src = dst;
        }
        Ok(out)
    }
}
