//! `rae`: the recurrent denoising autoencoder of Chaitanya et al. 2017 ("Interactive
//! reconstruction of Monte Carlo image sequences using a recurrent denoising
//! autoencoder"), colour only, trained on dvr's own renders by `tools/rae/` and run as
//! compute passes. The network is defined once in `tools/rae/model.py`; this file and
//! shaders/glsl/rae_*.comp are its mirror:
//!
//! - `rae.input` (rae_input.comp): log(1 + max(rgb, 0)) into the input tensor,
//!   replicate-padded to a multiple of 2^levels (any frame size works);
//! - per encoder level l: `enc{l}.feat` = lrelu(conv3×3(x_l)), `enc{l}.rec` =
//!   lrelu(conv3×3([a_l, h_l of the previous frame])) — the recurrent state, a graph
//!   history `<name>.h{l}`, read as zero when the history is invalid — then
//!   `pool{l+1}` (rae_pool.comp, 2×2 max) to the next level;
//! - `bottleneck` = lrelu(conv3×3(x_L));
//! - per decoder level l (coarse to fine): `dec{l}` = lrelu(conv3×3([up2(d_{l+1}), h_l])),
//!   the nearest upsampling and the concatenation fused into the convolution's fetch;
//! - `out` = conv3×3(d_0) (linear) and `rae.output` (rae_output.comp):
//!   exp(max(y, 0)) − 1, cropped to the frame.
//!
//! Tensors are images with four channels per texel, channel group g of pixel (x, y) at
//! texel (g·width + x, y) (so the widest tensor is width × channels/4 texels wide,
//! within the 4096-texel minimum of Vulkan's image-size limit for frames up to 1024 wide
//! at 16 channels). They are rgba32f ([`Precision::F32`]: the shaders match torch to
//! about 1e-6) or rgba16f ([`Precision::F16`], the `*_f16` shader variants: half the
//! memory traffic, arithmetic still fp32; tests/rae.rs bounds its difference from
//! torch's fp32). Weights and their manifest are `assets/rae/<net>.{json,bin}`
//! (found through [`crate::assets`], like the TF presets); a missing, truncated or
//! inconsistent file is an error naming the file. Like the paper's network, the
//! recurrent state is never reset on camera, light or TF changes: the network was
//! trained on moving sequences and has no reprojection.

use super::{Build, Built, DenoiseFrame, Denoiser, DenoiserConfig};
use crate::error::{EngineError, Result};
use crate::gpu::{GpuContext, ImageDesc, Pipeline};
use crate::gpu_block;
use crate::graph::{BufferHandle, Frame, ImageHandle, RenderGraph};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::cell::Cell;
use std::path::{Path, PathBuf};

gpu_block! {
    /// `RaeConvPush` in include/rae_conv.glsl (rae_conv.comp and its fp16 variant).
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
}

gpu_block! {
    /// `RaePoolPush` in include/rae_pool.glsl.
    pub struct RaePoolPush {
        pub width: u32,
        pub height: u32,
        pub groups: u32,
        pub pad0: u32,
    }
}

gpu_block! {
    /// `RaeIoPush` in include/rae_io.glsl (the input and output transforms).
    pub struct RaeIoPush {
        pub width: u32,
        pub height: u32,
        pub src_width: u32,
        pub src_height: u32,
    }
}

/// Channels of the network's input and output (colour only).
pub const IN_CHANNELS: u32 = 3;
/// The manifest format this engine reads.
pub const FORMAT: &str = "dvr-rae-1";

/// Storage precision of the tensors (weights and arithmetic are fp32 in both).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    F32,
    F16,
}

impl Precision {
    fn format(self) -> vk::Format {
        match self {
            Precision::F32 => vk::Format::R32G32B32A32_SFLOAT,
            Precision::F16 => vk::Format::R16G16B16A16_SFLOAT,
        }
    }

    /// The shader variant: `rae_conv` or `rae_conv_f16`.
    fn shader(self, stem: &str) -> String {
        match self {
            Precision::F32 => stem.to_string(),
            Precision::F16 => format!("{stem}_f16"),
        }
    }
}

/// The network `rae` runs: the one trained on the scene's built-in dataset, else the mri
/// network, which generalised best to the never-trained cloud (suite eval, 1024-spp
/// references: cloud/orbit 32.0 dB against 30.0 for the phantom network).
pub fn network_for(dataset: Option<&str>) -> &'static str {
    match dataset {
        Some("phantom") => "phantom",
        _ => "mri",
    }
}

/// What a RAE row runs: the shipped network `net` (None: the one trained on the
/// scene's dataset, see [`network_for`]) at `precision`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RaeNet {
    pub net: Option<&'static str>,
    pub precision: Precision,
}

impl RaeNet {
    /// The network and tensor precision it runs on a scene of built-in `dataset`.
    pub fn network(&self, dataset: Option<&str>) -> (&'static str, Precision) {
        (
            self.net.unwrap_or_else(|| network_for(dataset)),
            self.precision,
        )
    }
}

impl Build for RaeNet {
    fn build(&self, ctx: &GpuContext, name: &'static str, config: &DenoiserConfig) -> Built {
        let (net, precision) = self.network(config.dataset);
        let weights = RaeWeights::builtin(net)?;
        Ok(Box::new(Rae::new(ctx, name, weights, precision)?))
    }
}

/// Channel groups of four.
pub fn groups(channels: u32) -> u32 {
    channels.div_ceil(4)
}

/// One convolution as the shaders see it.
#[derive(Clone, Debug, PartialEq, Eq, serde::Deserialize)]
pub struct RaeLayer {
    pub name: String,
    /// Channels of the first input (the upsampled one in the decoder).
    pub in_a: u32,
    /// Channels of the second input (recurrent state or skip); 0 when there is none.
    pub in_b: u32,
    pub out: u32,
    /// Offsets into the weight file, in floats.
    pub weights_offset: u64,
    pub bias_offset: u64,
}

impl RaeLayer {
    fn weight_floats(&self) -> u64 {
        u64::from(groups(self.out) * (groups(self.in_a) + groups(self.in_b)) * 9 * 16)
    }
}

/// The layers of a network with encoder widths `widths[..L]` and bottleneck `widths[L]`,
/// in dispatch and file order (tools/rae/model.py `layer_specs`).
pub fn layer_specs(widths: &[u32]) -> Vec<(String, u32, u32, u32)> {
    let l_count = widths.len() - 1;
    let mut specs = Vec::new();
    for l in 0..l_count {
        let cin = if l == 0 { IN_CHANNELS } else { widths[l - 1] };
        specs.push((format!("enc{l}.feat"), cin, 0, widths[l]));
        specs.push((format!("enc{l}.rec"), widths[l], widths[l], widths[l]));
    }
    specs.push(("bottleneck".into(), widths[l_count - 1], 0, widths[l_count]));
    for l in (0..l_count).rev() {
        specs.push((format!("dec{l}"), widths[l + 1], widths[l], widths[l]));
    }
    specs.push(("out".into(), widths[0], 0, IN_CHANNELS));
    specs
}

#[derive(serde::Deserialize)]
struct Manifest {
    format: String,
    widths: Vec<u32>,
    leaky_relu_slope: f32,
    weights: String,
    floats: u64,
    layers: Vec<RaeLayer>,
}

/// A network's weights and shape, checked against its manifest.
#[derive(Clone, Debug)]
pub struct RaeWeights {
    /// The manifest file it came from.
    pub manifest: PathBuf,
    pub widths: Vec<u32>,
    pub slope: f32,
    pub layers: Vec<RaeLayer>,
    pub floats: Vec<f32>,
}

pub(crate) fn weights_error(file: &Path, problem: impl Into<String>) -> EngineError {
    EngineError::Weights {
        file: file.display().to_string(),
        problem: problem.into(),
    }
}

/// A network's weight buffer `name`, filled with `floats` when the graph made it anew
/// (`uploaded` remembers the buffer last filled).
pub(crate) fn weight_buffer(
    ctx: &GpuContext,
    graph: &mut RenderGraph,
    name: &str,
    floats: &[f32],
    uploaded: &Cell<Option<BufferHandle>>,
) -> Result<BufferHandle> {
    let size = std::mem::size_of_val(floats) as u64;
    let weights = graph.buffer(ctx, name, size, MemoryLocation::CpuToGpu)?;
    if uploaded.get() != Some(weights) {
        graph
            .buffer_mut(weights)
            .write(bytemuck::cast_slice(floats))?;
        uploaded.set(Some(weights));
    }
    Ok(weights)
}

/// The `count` little-endian f32 of the weight file `weights`, named by (and beside)
/// the manifest `manifest_path`: a file of another length (truncated, or another
/// network's) or a non-finite weight is an error naming the file. A longer file is
/// refused unread.
pub(crate) fn read_weight_floats(
    manifest_path: &Path,
    weights: &str,
    count: u64,
) -> Result<Vec<f32>> {
    let bin = manifest_path
        .parent()
        .unwrap_or(Path::new("."))
        .join(weights);
    let bytes = crate::files::read_bounded(&bin, count * 4)
        .map_err(|e| weights_error(&bin, format!("cannot read: {e}")))?;
    if bytes.len() as u64 != count * 4 {
        return Err(weights_error(
            &bin,
            format!(
                "{} bytes, the network of {} needs {} ({count} f32); truncated or from another network?",
                bytes.len(),
                manifest_path.display(),
                count * 4
            ),
        ));
    }
    let floats: Vec<f32> = bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect();
    if let Some(i) = floats.iter().position(|v| !v.is_finite()) {
        return Err(weights_error(&bin, format!("float {i} is not finite")));
    }
    Ok(floats)
}

impl RaeWeights {
    /// The shipped network `net`: `<assets>/rae/<net>.json` and the weight file it names.
    pub fn builtin(net: &str) -> Result<Self> {
        Self::load(&crate::assets::rae_manifest(net))
    }

    /// Reads a manifest and its weight file; every inconsistency (format, layer list,
    /// offsets, file size, non-finite weights) is an error naming the file.
    pub fn load(manifest_path: &Path) -> Result<Self> {
        let text = crate::files::read_text(manifest_path, crate::files::MAX_TEXT_FILE_BYTES)
            .map_err(|e| weights_error(manifest_path, format!("cannot read: {e}")))?;
        let m: Manifest = serde_json::from_str(&text)
            .map_err(|e| weights_error(manifest_path, format!("not a RAE manifest: {e}")))?;
        if m.format != FORMAT {
            return Err(weights_error(
                manifest_path,
                format!("format {:?}, expected {FORMAT:?}", m.format),
            ));
        }
        if m.widths.len() < 2 || m.widths.iter().any(|&w| w == 0 || w > 256) {
            return Err(weights_error(
                manifest_path,
                format!(
                    "widths {:?}: need at least 2 levels of 1..=256 channels",
                    m.widths
                ),
            ));
        }
        let specs = layer_specs(&m.widths);
        if specs.len() != m.layers.len() {
            return Err(weights_error(
                manifest_path,
                format!(
                    "{} layers, the architecture has {}",
                    m.layers.len(),
                    specs.len()
                ),
            ));
        }
        let mut end = 0u64;
        for ((name, a, b, o), layer) in specs.iter().zip(&m.layers) {
            if (&layer.name, layer.in_a, layer.in_b, layer.out) != (name, *a, *b, *o) {
                return Err(weights_error(
                    manifest_path,
                    format!(
                        "layer {:?} ({}+{} -> {}) where the architecture has {name:?} ({a}+{b} -> {o})",
                        layer.name, layer.in_a, layer.in_b, layer.out
                    ),
                ));
            }
            if layer.weights_offset != end || layer.bias_offset != end + layer.weight_floats() {
                return Err(weights_error(
                    manifest_path,
                    format!("layer {name:?}: offsets do not follow the packed layout"),
                ));
            }
            end = layer.bias_offset + u64::from(groups(layer.out) * 4);
        }
        if end != m.floats {
            return Err(weights_error(
                manifest_path,
                format!("manifest says {} floats, its layers need {end}", m.floats),
            ));
        }
        let floats = read_weight_floats(manifest_path, &m.weights, end)?;
        Ok(Self {
            manifest: manifest_path.to_path_buf(),
            widths: m.widths,
            slope: m.leaky_relu_slope,
            layers: m.layers,
            floats,
        })
    }

    /// Encoder levels (the frame is padded to a multiple of 2^levels).
    pub fn levels(&self) -> u32 {
        self.widths.len() as u32 - 1
    }

    fn layer(&self, name: &str) -> &RaeLayer {
        // load() checked the list against layer_specs, so every name exists.
        self.layers
            .iter()
            .find(|l| l.name == name)
            .unwrap_or(&self.layers[0])
    }
}

pub struct Rae {
    name: String,
    pub weights: RaeWeights,
    precision: Precision,
    conv: Pipeline<RaeConvPush>,
    pool: Pipeline<RaePoolPush>,
    input: Pipeline<RaeIoPush>,
    output: Pipeline<RaeIoPush>,
    /// The weight buffer this instance last filled (filled once per graph buffer).
    uploaded: Cell<Option<BufferHandle>>,
}

impl Rae {
    /// `name` prefixes this instance's graph resources and passes.
    pub fn new(
        ctx: &GpuContext,
        name: &str,
        weights: RaeWeights,
        precision: Precision,
    ) -> Result<Self> {
        Ok(Self {
            name: name.to_string(),
            weights,
            precision,
            conv: ctx.pipeline(&precision.shader("rae_conv"), &[])?,
            pool: ctx.pipeline(&precision.shader("rae_pool"), &[])?,
            input: ctx.pipeline(&precision.shader("rae_input"), &[])?,
            output: ctx.pipeline(&precision.shader("rae_output"), &[])?,
            uploaded: Cell::new(None),
        })
    }

    /// The history key of encoder level `l`'s recurrent state.
    pub fn history_name(&self, l: u32) -> String {
        format!("{}.h{l}", self.name)
    }

    /// A tensor image of `channels` channels at `w` × `h`.
    fn tensor(&self, w: u32, h: u32, channels: u32) -> ImageDesc {
        ImageDesc::d2(w * groups(channels), h, self.precision.format())
    }
}

/// The input or output transform (rae_input / rae_output): reads `src` of `src_size`,
/// writes all of `dst` of `dst_size` (padding by replication or cropping).
fn add_io_pass(
    frame: &mut Frame<'_>,
    name: String,
    pipeline: &Pipeline<RaeIoPush>,
    src: ImageHandle,
    src_size: (u32, u32),
    dst: ImageHandle,
    dst_size: (u32, u32),
) {
    let push = RaeIoPush {
        width: dst_size.0,
        height: dst_size.1,
        src_width: src_size.0,
        src_height: src_size.1,
    };
    frame.add_compute(name, pipeline, push, [dst_size.0, dst_size.1, 1], |b| {
        b.read("src", src).write("dst", dst);
    });
}

struct Conv<'a> {
    layer: &'a RaeLayer,
    a: ImageHandle,
    b: Option<ImageHandle>,
    b_enabled: bool,
    a_upsample: bool,
    dst: ImageHandle,
    size: (u32, u32),
    slope: f32,
}

/// A 2×2 max-pool, added before conv number `before`.
struct Pool {
    before: usize,
    src: ImageHandle,
    dst: ImageHandle,
    groups: u32,
    size: (u32, u32),
    level: u32,
}

impl Denoiser for Rae {
    fn add<'f>(&'f self, mut f: DenoiseFrame<'_, 'f>) -> Result<ImageHandle> {
        let (ctx, graph, frame, input) = f.parts();
        let n = &self.name;
        let wts = &self.weights;
        let levels = wts.levels();
        let mult = 1u32 << levels;
        let (fw, fh) = (input.size.width, input.size.height);
        let (pw, ph) = (fw.div_ceil(mult) * mult, fh.div_ceil(mult) * mult);
        let size = |l: u32| (pw >> l, ph >> l);

        let weights = weight_buffer(
            ctx,
            graph,
            &format!("{n}.weights"),
            &wts.floats,
            &self.uploaded,
        )?;

        let x0 = graph.image(ctx, &format!("{n}.x0"), self.tensor(pw, ph, IN_CHANNELS))?;
        add_io_pass(
            frame,
            format!("{n}.input"),
            &self.input,
            input.noisy,
            (fw, fh),
            x0,
            (pw, ph),
        );

        let mut convs: Vec<Conv> = Vec::new();
        let mut pools: Vec<Pool> = Vec::new();
        let mut hidden = Vec::new();
        let mut x = x0;
        for l in 0..levels {
            let w = wts.widths[l as usize];
            let (lw, lh) = size(l);
            let a = graph.image(ctx, &format!("{n}.enc{l}.a"), self.tensor(lw, lh, w))?;
            convs.push(Conv {
                layer: wts.layer(&format!("enc{l}.feat")),
                a: x,
                b: None,
                b_enabled: false,
                a_upsample: false,
                dst: a,
                size: (lw, lh),
                slope: wts.slope,
            });
            let h = graph.history(ctx, &self.history_name(l), self.tensor(lw, lh, w))?;
            convs.push(Conv {
                layer: wts.layer(&format!("enc{l}.rec")),
                a,
                b: Some(h.prev),
                b_enabled: h.valid,
                a_upsample: false,
                dst: h.cur,
                size: (lw, lh),
                slope: wts.slope,
            });
            hidden.push(h.cur);
            let (nw, nh) = size(l + 1);
            let pooled = graph.image(ctx, &format!("{n}.x{}", l + 1), self.tensor(nw, nh, w))?;
            pools.push(Pool {
                before: convs.len(),
                src: h.cur,
                dst: pooled,
                groups: groups(w),
                size: (nw, nh),
                level: l + 1,
            });
            x = pooled;
        }
        let (bw, bh) = size(levels);
        let bottom = wts.widths[levels as usize];
        let mut d = graph.image(ctx, &format!("{n}.bottleneck"), self.tensor(bw, bh, bottom))?;
        convs.push(Conv {
            layer: wts.layer("bottleneck"),
            a: x,
            b: None,
            b_enabled: false,
            a_upsample: false,
            dst: d,
            size: (bw, bh),
            slope: wts.slope,
        });
        for l in (0..levels).rev() {
            let (lw, lh) = size(l);
            let w = wts.widths[l as usize];
            let out = graph.image(ctx, &format!("{n}.dec{l}"), self.tensor(lw, lh, w))?;
            convs.push(Conv {
                layer: wts.layer(&format!("dec{l}")),
                a: d,
                b: Some(hidden[l as usize]),
                b_enabled: true,
                a_upsample: true,
                dst: out,
                size: (lw, lh),
                slope: wts.slope,
            });
            d = out;
        }
        let y = graph.image(ctx, &format!("{n}.y"), self.tensor(pw, ph, IN_CHANNELS))?;
        convs.push(Conv {
            layer: wts.layer("out"),
            a: d,
            b: None,
            b_enabled: false,
            a_upsample: false,
            dst: y,
            size: (pw, ph),
            slope: 1.0,
        });

        let mut pools = pools.into_iter().peekable();
        for (i, c) in convs.into_iter().enumerate() {
            while let Some(p) = pools.next_if(|p| p.before == i) {
                let (src, dst, g, (w, h)) = (p.src, p.dst, p.groups, p.size);
                let push = RaePoolPush {
                    width: w,
                    height: h,
                    groups: g,
                    pad0: 0,
                };
                // One workgroup layer per channel group.
                let name = format!("{n}.pool{}", p.level);
                frame.add_compute(name, &self.pool, push, [w, h, g], |b| {
                    b.read("src", src).write("dst", dst);
                });
            }
            let layer = c.layer;
            let (w, h) = c.size;
            let push = RaeConvPush {
                width: w,
                height: h,
                groups_a: groups(layer.in_a),
                groups_b: groups(layer.in_b),
                a_upsample: c.a_upsample as u32,
                b_enabled: c.b_enabled as u32,
                weights_offset: (layer.weights_offset / 4) as u32,
                bias_offset: (layer.bias_offset / 4) as u32,
                slope: c.slope,
                pad0: 0,
                pad1: 0,
                pad2: 0,
            };
            let (a, dst) = (c.a, c.dst);
            // Without a second input the first is bound twice (the shader skips it).
            let b_img = c.b.unwrap_or(a);
            // One workgroup layer per output channel group.
            let g = groups(layer.out);
            let name = format!("{n}.{}", layer.name);
            frame.add_compute(name, &self.conv, push, [w, h, g], |b| {
                b.read("in_a", a)
                    .read("in_b", b_img)
                    .write("dst", dst)
                    .read("weights", weights);
            });
        }

        let out = graph.image(ctx, &format!("{n}.out"), input.rgba32f())?;
        add_io_pass(
            frame,
            format!("{n}.output"),
            &self.output,
            y,
            (pw, ph),
            out,
            (fw, fh),
        );
        Ok(out)
    }
}
