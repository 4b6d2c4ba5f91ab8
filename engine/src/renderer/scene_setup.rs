//! From a scene (engine/scene) to what the renderer takes: the volume as a texture
//! upload with its brick ranges, the render settings the scene asks for (what the path
//! tracer is specialised for), the environment map, and per frame the camera, the lights
//! as GPU structs and the transfer function as LUTs, from a [`View`]. The CLI, the explorer and the tests
//! all go through here.

use super::timeline::Timeline;
use super::uploads::{EnvironmentUpload, LutUpload, VolumeUpload};
use super::{CameraMatrices, FrameInputs, Renderer, RendererConfig, SeriesTime};
use crate::error::{EngineError, Result as EngineResult};
use crate::gpu::GpuContext;
use crate::graph::Extent;
use crate::image_io::ImageIoError;
use crate::scene::BuiltinVolume;
use crate::scene::{Camera, EnvSource, Light, RenderSettings, Scene, View, VolumeSource};
use crate::shaders::frame::{self, GpuLight};
use crate::transfer::{TfLut, LUT_SIZE};
use crate::volume::blocks::VoxelBlocks;
use crate::volume::sparse::Sparse;
use crate::volume::{RawParams, Volume, VolumeError};
use glam::{Vec3, Vec4};
use std::sync::Arc;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum SetupError {
    #[error(transparent)]
    Volume(#[from] VolumeError),
    #[error("environment map: {0}")]
    Environment(#[from] ImageIoError),
    #[error("scene {scene}: {problem}")]
    Invalid { scene: String, problem: String },
    #[error(transparent)]
    Setting(#[from] EngineError),
}

/// A scene made ready for rendering. Cloning it shares the loaded volume and
/// environment map.
#[derive(Clone)]
pub struct SceneSetup {
    pub scene: Scene,
    /// The scene's render settings, with the spp override applied.
    pub settings: RenderSettings,
    pub config: RendererConfig,
    pub volume: Arc<VolumeUpload>,
    pub environment: Option<Arc<EnvironmentUpload>>,
    /// The series' time points, when the volume has more than one.
    pub timeline: Option<Arc<Timeline>>,
    /// The label map beside the volume (`[labels]`).
    pub labels: Option<Arc<super::labels::SceneLabels>>,
}

impl SceneSetup {
    /// `spp` overrides the scene's samples per frame; `volume_size` is the edge of
    /// procedural volumes when the scene does not give one.
    pub fn new(
        scene: Scene,
        size: Extent,
        spp: Option<u32>,
        volume_size: u32,
    ) -> Result<Self, SetupError> {
        if let Some(channels) = super::medium::load_channels(&scene)? {
            return Self::with_channels(scene, channels, size, spp);
        }
        match on_demand(&scene, volume_size) {
            Some(v) => {
                if scene.labels.is_some() {
                    return Err(SetupError::Invalid {
                        scene: scene.name.clone(),
                        problem: format!(
                            "labels: the {} volume is made brick by brick on demand and has no grid a label map could share",
                            v.name
                        ),
                    });
                }
                Self::with_upload(scene, VolumeUpload::on_demand(v.name, v.blocks), size, spp)
            }
            None => {
                let volume = load_volume(&scene, volume_size)?;
                Self::with_volume(scene, &volume, size, spp)
            }
        }
    }

    /// [`SceneSetup::new`] for a medium of several channels: packed into one upload, each
    /// channel's view from its section and the file (see [`super::medium`]).
    pub fn with_channels(
        mut scene: Scene,
        channels: super::medium::Channels,
        size: Extent,
        spp: Option<u32>,
    ) -> Result<Self, SetupError> {
        let times = channels.series.info().times;
        for (i, k) in scene.animation.time.iter().enumerate() {
            if k.time > (times - 1) as f64 {
                return Err(SetupError::Invalid {
                    scene: scene.name.clone(),
                    problem: format!(
                        "animation.time[{i}].time = {} is past the series' last time point {} ({times} in all)",
                        k.time,
                        times - 1
                    ),
                });
            }
        }
        let upload = VolumeUpload::from_channels(&channels.volumes).map_err(|problem| {
            SetupError::Invalid {
                scene: scene.name.clone(),
                problem,
            }
        })?;
        let views = super::medium::channel_views(&scene, &channels);
        if scene.channels.len() > views.len() {
            return Err(SetupError::Invalid {
                scene: scene.name.clone(),
                problem: format!(
                    "channel: {} [[channel]] sections for a volume of {} channel(s)",
                    scene.channels.len(),
                    views.len()
                ),
            });
        }
        let one_channel_kept = views.len() == 1 && scene.channels.is_empty();
        if let Some(c0) = views.first() {
            // Channel 0's TF is the scene's `transfer.a`, over the channel's window
            // (in density now, so the data-unit mapping of `with_upload` keeps it).
            scene.tf_a = c0.density_tf();
            scene.tf_b = scene
                .tf_b
                .map(|b| crate::scene::channel::over_window(&b, c0.window, c0.data_window));
        }
        // One channel with no section of its own shows as a one-field volume does.
        if !one_channel_kept {
            scene.channel_views = views;
        }
        let mut setup = Self::with_upload(scene, upload, size, spp)?;
        setup.attach_labels(&channels.volumes[0].to_patient)?;
        if times > 1 {
            let first = setup.volume.clone();
            setup.timeline = Some(Arc::new(Timeline::new(channels.series, first)));
        }
        Ok(setup)
    }

    /// A time point of the series (`None` for a volume of one time point).
    pub fn series_time(&self, time: f64) -> Option<SeriesTime> {
        self.timeline.as_ref().map(|timeline| SeriesTime {
            timeline: timeline.clone(),
            time,
        })
    }

    /// [`SceneSetup::new`] with the volume already loaded (the explorer also draws its
    /// histogram).
    pub fn with_volume(
        scene: Scene,
        volume: &Volume,
        size: Extent,
        spp: Option<u32>,
    ) -> Result<Self, SetupError> {
        let mut setup = Self::with_upload(scene, VolumeUpload::from_volume(volume), size, spp)?;
        setup.attach_labels(&volume.to_patient)?;
        Ok(setup)
    }

    /// Loads the scene's label map onto the volume's grid (`[labels]`), its labels'
    /// views into the scene, and specialises the renderer for it.
    fn attach_labels(
        &mut self,
        to_patient: &crate::volume::PatientTransform,
    ) -> Result<(), SetupError> {
        if let Some((labels, views)) = super::labels::load(&self.scene, &self.volume, to_patient)? {
            self.config.labels = Some(labels.mode);
            self.scene.label_views = views;
            self.labels = Some(Arc::new(labels));
        }
        Ok(())
    }

    /// The renderer's inputs for `view` at `aspect` with the LUT of its TF state (passed
    /// in so a session computes it once per TF edit): [`inputs_for_view`] with the
    /// series' time point and the label map's look. Every frame, scripted or live,
    /// takes this path.
    pub fn inputs(&self, view: &View, aspect: f32, lut: &TfLut) -> FrameInputs {
        FrameInputs {
            time: self.series_time(view.time),
            labels: self
                .labels
                .as_ref()
                .map(|l| super::LabelLookRef(l.look(&view.labels, lut))),
            ..inputs_for_view(view, aspect, lut)
        }
    }

    fn with_upload(
        mut scene: Scene,
        volume: VolumeUpload,
        size: Extent,
        spp: Option<u32>,
    ) -> Result<Self, SetupError> {
        let count = scene.channel_views.len();
        if let Some((i, k)) = scene
            .animation
            .channel
            .iter()
            .enumerate()
            .find(|(_, k)| k.index >= count)
        {
            return Err(SetupError::Invalid {
                scene: scene.name.clone(),
                problem: format!(
                    "animation.channel[{i}].index = {} names no channel: the volume has {}",
                    k.index,
                    match count {
                        0 =>
                            "one field (give its channels with [volume] files or a file of several)"
                                .to_string(),
                        n => format!("{n} channels (0 to {})", n - 1),
                    }
                ),
            });
        }
        // TFs written in data units (Hounsfield…) meet the volume here, once: everything
        // after this works in normalised density.
        scene.tf_a = scene.tf_a.in_density(volume.window);
        scene.tf_b = scene.tf_b.map(|b| b.in_density(volume.window));
        let mut settings = scene.render;
        if let Some(spp) = spp {
            settings.set_spp(spp).map_err(EngineError::from)?;
        }
        let config = renderer_config(&scene, size);
        let environment = load_environment(&scene.lights)?.map(Arc::new);
        Ok(Self {
            volume: Arc::new(volume),
            settings,
            config,
            environment,
            scene,
            timeline: None,
            labels: None,
        })
    }

    /// A renderer for this scene on `ctx` (owned, or shared with the caller: see
    /// [`Renderer::new`]).
    pub fn renderer(
        &self,
        ctx: impl Into<Arc<GpuContext>>,
        denoisers: &[&str],
    ) -> EngineResult<Renderer> {
        Renderer::new(
            ctx,
            self.settings,
            self.config.clone(),
            self.volume.clone(),
            self.environment.as_deref(),
            denoisers,
            LUT_SIZE as u32,
        )
    }

    /// The renderer's inputs for animation frame `f`: the scene's view at `f`
    /// ([`Scene::view_at`]) through [`inputs_for_view`], the path a live session's view
    /// takes too.
    pub fn frame_inputs(&self, f: u32) -> FrameInputs {
        let view = self.scene.view_at(f);
        self.inputs(&view, self.config.size.aspect(), &view.lut())
    }
}

/// The renderer's inputs for a view whose TF state gives `lut` ([`crate::scene::TfState::lut`],
/// passed in so a session computes it once per TF edit), at `aspect` (width / height).
pub fn inputs_for_view(view: &View, aspect: f32, lut: &TfLut) -> FrameInputs {
    FrameInputs {
        cut: view.cut.clone(),
        ..inputs_for(&view.camera.camera(), aspect, &view.lights, lut)
    }
}

/// The renderer's inputs for a camera, lights and a TF: the one place scene state
/// becomes [`FrameInputs`].
pub fn inputs_for(camera: &Camera, aspect: f32, lights: &[Light], lut: &TfLut) -> FrameInputs {
    let c = camera;
    FrameInputs {
        camera: CameraMatrices::look_at(c.position, c.target, c.up, c.fov_y, aspect),
        lights: lights.iter().map(gpu_light).collect(),
        lut: LutUpload::from(lut),
        cut: Default::default(),
        time: None,
        labels: None,
    }
}

/// Edge length of procedural volumes (phantom, cloud) when neither the scene nor the
/// caller gives one: the CLI's `--volume-size` default and the Python package's.
pub const DEFAULT_VOLUME_SIZE: u32 = 128;

/// A scene volume made brick by brick on demand (the `sparse` dataset), which only the
/// renderer's upload holds: its dense array is never made.
pub struct OnDemand {
    pub name: &'static str,
    /// What identifies its voxels (a reference cache key): the generator and its size.
    pub identity: String,
    pub blocks: Arc<dyn VoxelBlocks>,
}

/// The scene's volume when it is made on demand (see [`OnDemand`]).
pub fn on_demand(scene: &Scene, volume_size: u32) -> Option<OnDemand> {
    match &scene.volume.source {
        VolumeSource::Builtin {
            dataset: BuiltinVolume::Sparse,
            size,
        } => {
            let n = size.unwrap_or(volume_size);
            Some(OnDemand {
                name: "sparse",
                identity: format!("sparse v1 {n}"),
                blocks: Arc::new(Sparse::new(n)),
            })
        }
        _ => None,
    }
}

/// The scene's volume: a built-in dataset or a file.
pub fn load_volume(scene: &Scene, volume_size: u32) -> Result<Volume, VolumeError> {
    match &scene.volume.source {
        VolumeSource::Builtin { dataset, size } => {
            Volume::builtin(dataset.name(), size.unwrap_or(volume_size))
        }
        VolumeSource::Files { paths } => {
            Volume::load_within(&paths[0], None, scene.render.gpu_memory())
        }
        VolumeSource::File { path, raw } => {
            let params = raw.as_ref().map(|r| RawParams {
                dims: r.dims,
                format: r.format,
                spacing: r.spacing.map(|s| s as f32),
            });
            Volume::load_within(path, params.as_ref(), scene.render.gpu_memory())
        }
    }
}

/// What a renderer for `scene` at `size` is built for (reprojecting with the first
/// collision until the caller picks otherwise).
pub fn renderer_config(scene: &Scene, size: Extent) -> RendererConfig {
    RendererConfig {
        size,
        density_scale: scene.volume.density_scale as f32,
        dataset: match &scene.volume.source {
            VolumeSource::Builtin { dataset, .. } => Some(dataset.name()),
            VolumeSource::File { .. } | VolumeSource::Files { .. } => None,
        },
        gpu_memory: scene.render.gpu_memory(),
        ..Default::default()
    }
}

fn v3(d: glam::DVec3) -> Vec3 {
    d.as_vec3()
}

/// A scene light as the path tracer's uniform struct (layout in include/frame.glsl).
pub fn gpu_light(l: &Light) -> GpuLight {
    match l {
        Light::Point(p) => GpuLight {
            position_kind: v3(p.position).extend(frame::LIGHT_POINT),
            radiance: (v3(p.colour) * p.intensity as f32).extend(0.0),
            ..Default::default()
        },
        Light::Area(a) => {
            let (u, v) = a.half_axes();
            GpuLight {
                position_kind: v3(a.position).extend(frame::LIGHT_AREA),
                radiance: (v3(a.colour) * a.intensity as f32).extend(0.0),
                u_axis: v3(u).extend(0.0),
                v_axis: v3(v).extend(0.0),
            }
        }
        Light::Environment(e) => {
            let k = e.intensity as f32;
            let (top, bottom, mode) = match &e.source {
                EnvSource::Constant { colour } => {
                    (v3(*colour) * k, Vec3::ZERO, frame::ENV_CONSTANT)
                }
                EnvSource::Gradient { top, bottom } => {
                    (v3(*top) * k, v3(*bottom) * k, frame::ENV_GRADIENT)
                }
                EnvSource::Map { .. } => (Vec3::ZERO, Vec3::ZERO, frame::ENV_MAP),
            };
            GpuLight {
                position_kind: Vec4::new(0.0, 0.0, 0.0, frame::LIGHT_ENV),
                radiance: top.extend(mode),
                u_axis: bottom.extend(k),
                v_axis: Vec4::ZERO,
            }
        }
    }
}

/// The environment map of the scene's environment light, if it uses one.
pub fn load_environment(lights: &[Light]) -> Result<Option<EnvironmentUpload>, ImageIoError> {
    for l in lights {
        if let Light::Environment(e) = l {
            if let EnvSource::Map { path } = &e.source {
                let img = crate::image_io::read_exr(path)?;
                check_radiance(path, &img)?;
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

/// An environment map holds radiance: finite and non-negative in every channel. One
/// NaN or Inf texel would turn every path that samples it into NaN (a black or
/// speckled image with no error), so it is refused, naming the first.
fn check_radiance(
    path: &std::path::Path,
    img: &crate::metrics::Rgb32Image,
) -> Result<(), ImageIoError> {
    let bad = |c: &[f32; 3]| c.iter().any(|v| !v.is_finite() || *v < 0.0);
    let count = img.data.iter().filter(|c| bad(c)).count();
    match img.data.iter().position(bad) {
        None => Ok(()),
        Some(i) => {
            let w = img.width.max(1) as usize;
            Err(ImageIoError::Exr {
                path: path.to_path_buf(),
                message: format!(
                    "{count} texel(s) are NaN, infinite or negative, the first at ({}, {}) = \
                     {:?}; an environment map holds radiance (finite, >= 0)",
                    i % w,
                    i / w,
                    img.data[i]
                ),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::Rgb32Image;
    use crate::scene::EnvironmentLight;

    #[test]
    fn environment_maps_with_nan_or_inf_are_refused_naming_the_texel() {
        let dir = tempfile::tempdir().expect("tempdir");
        let path = dir.path().join("sky.exr");
        let mut img = Rgb32Image::filled(4, 2, [0.5; 3]);
        img.data[6] = [0.5, f32::INFINITY, 0.5];
        img.data[7] = [f32::NAN, 0.5, 0.5];
        crate::image_io::write_exr(&path, &img).expect("write exr");
        let light = Light::Environment(EnvironmentLight {
            source: EnvSource::Map { path: path.clone() },
            intensity: 1.0,
        });
        // Used to load, and every path sampling the texel became NaN.
        let msg = load_environment(&[light]).unwrap_err().to_string();
        assert!(
            msg.contains("sky.exr") && msg.contains("2 texel(s)") && msg.contains("(2, 1)"),
            "{msg}"
        );
    }
}
