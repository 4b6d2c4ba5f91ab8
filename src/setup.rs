//! From a scene name or file to what the renderer takes: the volume as a texture upload
//! with its brick ranges, the lights as GPU structs, the transfer function(s) as LUTs,
//! and the render settings the scene asks for. The explorer edits the same scene state
//! interactively and turns it into renderer inputs through the same functions
//! ([`gpu_light`], [`frame_inputs`], [`path_trace_features`]).

use crate::profile::PassStats;
use crate::SceneArgs;
use anyhow::{bail, Context, Result};
use dvr_engine::gpu::GpuContext;
use dvr_engine::passes::path_trace::{Estimator, PathTraceFeatures, Phase};
use dvr_engine::passes::Extent;
use dvr_engine::renderer::scene_gpu::{EnvironmentUpload, LutUpload, VolumeUpload};
use dvr_engine::renderer::uniforms::{self, GpuLight};
use dvr_engine::renderer::{CameraMatrices, FrameInputs, RenderSettings, Renderer};
use dvr_engine::scene::{self, Camera, EnvSource, Light, Scene, VolumeSource};
use dvr_engine::transfer::{TfLut, LUT_SIZE};
use dvr_engine::volume::Volume;
use glam::{Vec3, Vec4};
use std::path::Path;
use std::sync::Arc;

/// The scene `dvr` renders when none is named.
pub const DEFAULT_SCENE: &str = "phantom/orbit";

pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size {s:?} is not WIDTHxHEIGHT"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("bad width in {s:?}"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("bad height in {s:?}"))?;
    if w == 0 || h == 0 || w > 8192 || h > 8192 {
        return Err(format!("size {s:?} must be between 1x1 and 8192x8192"));
    }
    Ok((w, h))
}

/// Bins of [`Setup::histogram`].
pub const HISTOGRAM_BINS: usize = 128;

pub struct Setup {
    pub name: String,
    pub scene: Scene,
    pub settings: RenderSettings,
    pub volume: VolumeUpload,
    pub environment: Option<EnvironmentUpload>,
    pub frames: u32,
    /// Voxel counts of the normalised density in [`HISTOGRAM_BINS`] bins (the
    /// explorer's transfer-function editor draws it).
    pub histogram: Vec<u32>,
    lut_a: TfLut,
    lut_b: Option<TfLut>,
}

fn v3(d: glam::DVec3) -> Vec3 {
    d.as_vec3()
}

/// A scene light as the path tracer's uniform block holds it.
pub fn gpu_light(l: &Light) -> GpuLight {
    match l {
        Light::Point(p) => GpuLight {
            position_kind: v3(p.position).extend(uniforms::LIGHT_POINT),
            radiance: (v3(p.colour) * p.intensity as f32).extend(0.0),
            ..Default::default()
        },
        Light::Area(a) => {
            let (u, v) = a.half_axes();
            GpuLight {
                position_kind: v3(a.position).extend(uniforms::LIGHT_AREA),
                radiance: (v3(a.colour) * a.intensity as f32).extend(0.0),
                u_axis: v3(u).extend(0.0),
                v_axis: v3(v).extend(0.0),
            }
        }
        Light::Environment(e) => {
            let k = e.intensity as f32;
            let (top, bottom, mode) = match &e.source {
                EnvSource::Constant { colour } => {
                    (v3(*colour) * k, Vec3::ZERO, uniforms::ENV_CONSTANT)
                }
                EnvSource::Gradient { top, bottom } => {
                    (v3(*top) * k, v3(*bottom) * k, uniforms::ENV_GRADIENT)
                }
                EnvSource::Map { .. } => (Vec3::ZERO, Vec3::ZERO, uniforms::ENV_MAP),
            };
            GpuLight {
                position_kind: Vec4::new(0.0, 0.0, 0.0, uniforms::LIGHT_ENV),
                radiance: top.extend(mode),
                u_axis: bottom.extend(k),
                v_axis: Vec4::ZERO,
            }
        }
    }
}

fn load_environment(lights: &[Light]) -> Result<Option<EnvironmentUpload>> {
    for l in lights {
        if let Light::Environment(e) = l {
            if let EnvSource::Map { path } = &e.source {
                let img = crate::output::read_exr(path)
                    .with_context(|| format!("environment map {}", path.display()))?;
                return Ok(Some(EnvironmentUpload {
                    width: img.width,
                    height: img.height,
                    rgba: img.data.iter().map(|c| [c[0], c[1], c[2], 1.0]).collect(),
                }));
            }
        }
    }
    Ok(None)
}

/// What the path tracer is specialised for, from a scene's render settings and lights.
pub fn path_trace_features(r: &scene::RenderSettings, lights: &[Light]) -> PathTraceFeatures {
    PathTraceFeatures {
        estimator: match r.estimator {
            scene::Estimator::Delta => Estimator::Delta,
            scene::Estimator::RayMarch => Estimator::RayMarch,
        },
        phase: match r.phase {
            scene::Phase::Isotropic => Phase::Isotropic,
            scene::Phase::Hg => Phase::Hg,
            scene::Phase::Hybrid => Phase::Hybrid,
        },
        emission: r.emission,
        environment_map: lights.iter().any(
            |l| matches!(l, Light::Environment(e) if matches!(e.source, EnvSource::Map { .. })),
        ),
    }
}

/// A scene's `[render]` settings over `base` (which keeps its size, density scale and
/// seed): the one mapping from a scene's render settings to the renderer's.
pub fn render_settings(
    r: &scene::RenderSettings,
    lights: &[Light],
    base: RenderSettings,
) -> RenderSettings {
    RenderSettings {
        spp: r.spp,
        max_bounces: r.max_bounces,
        rr_depth: r.russian_roulette_depth,
        features: path_trace_features(r, lights),
        hg_g: r.hg_g as f32,
        step_voxels: r.step_size as f32,
        ..base
    }
}

/// The renderer's inputs for one camera, light set and transfer function: the one
/// place scene state becomes [`FrameInputs`] (capture and the explorer both use it).
pub fn frame_inputs(camera: &Camera, aspect: f32, lights: &[Light], lut: &TfLut) -> FrameInputs {
    let c = camera;
    FrameInputs {
        camera: CameraMatrices::look_at(c.position, c.target, c.up, c.fov_y, aspect),
        lights: lights.iter().map(gpu_light).collect(),
        lut: LutUpload::from(lut),
    }
}

impl Setup {
    pub fn new(args: &SceneArgs) -> Result<Self> {
        let scene = Scene::open(&args.scene).with_context(|| {
            format!(
                "opening scene {:?} (built-in scenes: `dvr scenes`)",
                args.scene
            )
        })?;
        Self::from_scene(scene, args)
    }

    /// A scene already opened (and perhaps edited, e.g. given another volume); `args`
    /// supplies the size, frame count, spp and procedural volume size.
    pub fn from_scene(mut scene: Scene, args: &SceneArgs) -> Result<Self> {
        if let Some(n) = args.frames {
            scene = scene.with_frames(n)?;
        }
        let volume = match &scene.volume.source {
            VolumeSource::Builtin { dataset, size } => {
                Volume::builtin(dataset.name(), size.unwrap_or(args.volume_size))?
            }
            VolumeSource::File { path, raw } => {
                let params = raw.as_ref().map(|r| dvr_engine::volume::RawParams {
                    dims: r.dims,
                    format: match r.format {
                        scene::RawFormat::U8 => dvr_engine::volume::RawFormat::U8,
                        scene::RawFormat::U16 => dvr_engine::volume::RawFormat::U16,
                        scene::RawFormat::F32 => dvr_engine::volume::RawFormat::F32,
                    },
                    spacing: r.spacing.map(|s| s as f32),
                });
                Volume::load(path, params.as_ref())?
            }
        };
        let r = &scene.render;
        let spp = args.spp.unwrap_or(r.spp);
        if spp == 0 {
            bail!("--spp must be at least 1");
        }
        let settings = render_settings(
            &scene::RenderSettings { spp, ..*r },
            &scene.lights,
            RenderSettings {
                size: Extent {
                    width: args.size.0,
                    height: args.size.1,
                },
                density_scale: scene.volume.density_scale as f32,
                ..Default::default()
            },
        );
        let environment = load_environment(&scene.lights)?;
        let lut_a = scene.tf_a.lut();
        let lut_b = scene.tf_b.as_ref().map(|b| b.lut());
        Ok(Self {
            name: scene.name.clone(),
            frames: scene.frames,
            histogram: volume.histogram(HISTOGRAM_BINS),
            volume: VolumeUpload::from_volume(&volume),
            environment,
            settings,
            scene,
            lut_a,
            lut_b,
        })
    }

    pub fn width(&self) -> u32 {
        self.settings.size.width
    }

    pub fn height(&self) -> u32 {
        self.settings.size.height
    }

    pub fn renderer(&self, denoisers: &[&str]) -> Result<Renderer> {
        self.renderer_on(Arc::new(GpuContext::headless()?), denoisers)
    }

    /// A renderer on a context the caller keeps (the explorer's, with its surface).
    pub fn renderer_on(&self, ctx: Arc<GpuContext>, denoisers: &[&str]) -> Result<Renderer> {
        Ok(Renderer::new_shared(
            ctx,
            self.settings.clone(),
            &self.volume,
            self.environment.as_ref(),
            denoisers,
            LUT_SIZE as u32,
        )?)
    }

    /// The renderer's inputs for animation frame `f`.
    pub fn inputs(&self, f: u32) -> FrameInputs {
        let state = self.scene.frame_state(f);
        let aspect = self.width() as f32 / self.height() as f32;
        let blended;
        let lut = match &self.lut_b {
            Some(b) if state.tf_blend > 0.0 => {
                blended = TfLut::lerp(&self.lut_a, b, state.tf_blend);
                &blended
            }
            _ => &self.lut_a,
        };
        frame_inputs(&state.camera, aspect, &state.lights, lut)
    }
}

pub fn list_scenes(dump: Option<&str>) -> Result<()> {
    if let Some(name) = dump {
        let scene = Scene::open(name)?;
        print!("{}", scene.to_toml()?);
        return Ok(());
    }
    for n in Scene::builtin_names() {
        println!("{n}");
    }
    Ok(())
}

/// A small page next to a capture: the last frame of each method, a frame slider, and
/// the per-pass timing table.
pub fn write_capture_page(
    out: &Path,
    setup: &Setup,
    methods: &[String],
    passes: &[PassStats],
    total: &PassStats,
) -> Result<()> {
    let mut html = String::new();
    html.push_str("<!doctype html><meta charset=utf-8><title>dvr capture</title>");
    html.push_str("<style>body{font-family:sans-serif;background:#222;color:#eee}img{image-rendering:pixelated;width:384px}figure{display:inline-block;margin:8px}td,th{padding:2px 10px;text-align:right}</style>");
    html.push_str(&format!(
        "<h1>{}</h1><p>{}×{}, {} spp/frame, {} frames</p>",
        setup.name,
        setup.width(),
        setup.height(),
        setup.settings.spp,
        setup.frames
    ));
    html.push_str(&format!(
        "<input id=f type=range min=0 max={} value={} style='width:600px'> frame <span id=n></span><br>",
        setup.frames.saturating_sub(1),
        setup.frames.saturating_sub(1)
    ));
    for m in methods {
        html.push_str(&format!(
            "<figure><img class=seq data-m='{m}'><figcaption>{m}</figcaption></figure>"
        ));
    }
    html.push_str(
        "<h2>GPU time per pass (ms)</h2><table><tr><th>pass<th>mean<th>median<th>p95</tr>",
    );
    for p in passes.iter().chain(std::iter::once(total)) {
        html.push_str(&format!(
            "<tr><td style=text-align:left>{}<td>{:.3}<td>{:.3}<td>{:.3}</tr>",
            p.pass, p.mean_ms, p.median_ms, p.p95_ms
        ));
    }
    html.push_str(
        "</table><script>const f=document.getElementById('f'),n=document.getElementById('n');",
    );
    html.push_str("function show(){const i=String(f.value).padStart(4,'0');n.textContent=f.value;for(const im of document.querySelectorAll('img.seq'))im.src=im.dataset.m+'/'+i+'.png';}f.oninput=show;show();</script>");
    std::fs::write(out.join("index.html"), html)
        .with_context(|| format!("writing {}", out.join("index.html").display()))
}
