//! `dvr.Renderer`: one scene at one size with its denoisers on one device. The temporal
//! state lives here, so rendering frames 0..n in order is the animation `dvr eval`
//! renders (same noisy input, same denoisers, same references).

use crate::convert::{image_out, runtime_error, value_error};
use crate::scene::{scene_from_dict, tf_from_dict};
use crate::volume::Volume;
use dvr_engine::error::EngineError;
use dvr_engine::gpu::timestamps::PassTiming;
use dvr_engine::gpu::{ContextOptions, GpuContext};
use dvr_engine::graph::Extent;
use dvr_engine::passes::aux_features::{ALBEDO, NORMAL};
use dvr_engine::renderer::scene_setup::{load_volume, SceneSetup, DEFAULT_VOLUME_SIZE};
use dvr_engine::renderer::{FrameRequest, FrameResult, Renderer as EngineRenderer, FEATURE_IMAGES};
use dvr_engine::scene::parse_memory_size;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The registry's pass-through method, whose output `render()` returns as `"noisy"`.
const NOISY_METHOD: &str = "none";

/// Engine errors as Python sees them: what the caller asked for is a `ValueError`,
/// what the device did is a `RuntimeError`.
fn engine_error(e: EngineError) -> PyErr {
    match e {
        EngineError::UnknownDenoiser { .. } | EngineError::InvalidSetting { .. } => value_error(e),
        other => runtime_error(other),
    }
}

/// Lets the renderer be used from any Python thread and with the GIL released. It
/// holds Vulkan handles (raw pointers, so the compiler cannot call it `Send`); Vulkan
/// allows a handle on any thread as long as uses are externally synchronised, and
/// they are: every method that renders takes `&mut self`, which pyo3's borrow flag
/// makes exclusive (a second thread gets "Already borrowed"), and the `&self` getters
/// only read plain values.
struct OnThisThread<T>(T);
unsafe impl<T> Send for OnThisThread<T> {}
unsafe impl<T> Sync for OnThisThread<T> {}

impl<T> OnThisThread<T> {
    /// Through a method, so a closure captures the wrapper (which is `Send`), not the
    /// field it reaches (closures capture disjoint fields).
    fn get(&mut self) -> &mut T {
        &mut self.0
    }
}

#[pyclass(module = "dvr._native")]
pub struct Renderer {
    inner: OnThisThread<Inner>,
}

struct Inner {
    setup: SceneSetup,
    renderer: EngineRenderer,
    /// The animation frame `render()` renders when not told.
    next_frame: u32,
    last_frame: Option<u32>,
    last_timings: Vec<PassTiming>,
}

#[pymethods]
impl Renderer {
    /// A renderer for `scene` (a scene dict, see `dvr.Scene`) at `size` = (width,
    /// height). `volume` replaces the scene's `[volume]` source (its density scale
    /// stays), `tf` its `transfer.a`; `spp` overrides the scene's samples per frame;
    /// `device` picks the Vulkan device by a substring of its name; `gpu_memory` ("512M",
    /// "2G", a byte count) is the volume's budget on it, past which it is paged.
    #[new]
    #[pyo3(signature = (scene, size, denoisers, volume = None, tf = None, spp = None, motion = "features", device = None, gpu_memory = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        scene: &Bound<'_, PyDict>,
        size: (u32, u32),
        denoisers: Vec<String>,
        volume: Option<PyRef<'_, Volume>>,
        tf: Option<&Bound<'_, PyDict>>,
        spp: Option<u32>,
        motion: &str,
        device: Option<String>,
        gpu_memory: Option<String>,
    ) -> PyResult<Self> {
        let mut scene = scene_from_dict(scene, "scene")?;
        if let Some(tf) = tf {
            scene.tf_a = tf_from_dict(tf)?;
        }
        let (w, h) = size;
        if !(1..=8192).contains(&w) || !(1..=8192).contains(&h) {
            return Err(value_error(format!(
                "size {w}×{h}: width and height must be 1 to 8192"
            )));
        }
        let motion = motion.parse().map_err(value_error)?;
        if let Some(s) = gpu_memory {
            let bytes =
                parse_memory_size(&s).map_err(|e| value_error(format!("gpu_memory: {e}")))?;
            scene
                .render
                .set_gpu_memory(Some(bytes))
                .map_err(value_error)?;
        }
        // The noisy input comes back through the pass-through method, first.
        let mut names: Vec<&str> = vec![NOISY_METHOD];
        names.extend(
            denoisers
                .iter()
                .map(String::as_str)
                .filter(|n| *n != NOISY_METHOD),
        );
        let given = volume.as_ref().map(|v| OnThisThread(&v.inner));
        let built = py.detach(move || -> PyResult<_> {
            let loaded;
            let volume = match given {
                Some(v) => v.0,
                None => {
                    loaded = load_volume(&scene, DEFAULT_VOLUME_SIZE).map_err(value_error)?;
                    &loaded
                }
            };
            let custom = given_is_custom(&scene, volume);
            let mut setup = SceneSetup::with_volume(
                scene,
                volume,
                Extent {
                    width: w,
                    height: h,
                },
                spp,
            )
            .map_err(value_error)?;
            setup.config.motion_source = motion;
            if custom {
                // The trained RAE networks are per dataset; an array is none of them.
                setup.config.dataset = None;
            }
            // `device` (a substring of the name) as `DVR_DEVICE` does; None: the same
            // choice as the CLI's.
            let options = ContextOptions {
                device,
                ..Default::default()
            };
            let ctx = GpuContext::new(options).map_err(runtime_error)?;
            let renderer = setup.renderer(ctx, &names).map_err(engine_error)?;
            Ok(OnThisThread((setup, renderer)))
        })?;
        let (setup, renderer) = built.0;
        Ok(Self {
            inner: OnThisThread(Inner {
                setup,
                renderer,
                next_frame: 0,
                last_frame: None,
                last_timings: Vec::new(),
            }),
        })
    }

    /// Renders animation frame `frame` (default: the one after the last) and returns a
    /// dict of `(h, w, 3)` float32 linear images: `"noisy"` and one per denoiser, plus
    /// `"albedo"` and `"normal"` (the single-frame denoisers' guides) with `aux=True`.
    /// `reset=True` restarts every history first (a cut). `features=True` adds
    /// `"features"`: `{"position", "normal", "albedo"}`, each `(h, w, 4)` float32 (the
    /// surface features the temporal denoisers reproject with; see `FEATURE_IMAGES`).
    #[pyo3(signature = (frame = None, reset = false, aux = false, features = false))]
    fn render<'py>(
        &mut self,
        py: Python<'py>,
        frame: Option<u32>,
        reset: bool,
        aux: bool,
        features: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let me = &mut self.inner;
        let f = frame.unwrap_or(me.0.next_frame);
        if f >= me.0.setup.scene.frames {
            return Err(value_error(format!(
                "frame {f}: the scene has {} frame(s) (0 to {})",
                me.0.setup.scene.frames,
                me.0.setup.scene.frames - 1
            )));
        }
        let request = FrameRequest {
            readback: true,
            reset,
            aux,
            features,
        };
        let inputs = me.0.setup.frame_inputs(f);
        let results = py
            .detach(|| -> Result<Vec<FrameResult>, EngineError> {
                let renderer = &mut me.get().renderer;
                let mut out: Vec<FrameResult> =
                    renderer.frame(&inputs, &request)?.into_iter().collect();
                out.extend(renderer.flush()?);
                Ok(out)
            })
            .map_err(engine_error)?;
        let result = results
            .into_iter()
            .max_by_key(|r| r.index)
            .ok_or_else(|| runtime_error("the renderer returned no frame"))?;
        me.0.next_frame = f + 1;
        me.0.last_frame = Some(f);
        let (w, h) = (me.0.setup.config.size.width, me.0.setup.config.size.height);
        let out = PyDict::new(py);
        let surface = PyDict::new(py);
        for (name, pixels) in &result.images {
            if let Some(i) = FEATURE_IMAGES.iter().position(|n| n == name) {
                let key = ["position", "normal", "albedo"][i];
                surface.set_item(key, image_out(py, w, h, pixels, 4))?;
                continue;
            }
            let key = match name.as_str() {
                NOISY_METHOD => "noisy",
                n if n == ALBEDO => "albedo",
                n if n == NORMAL => "normal",
                n => n,
            };
            out.set_item(key, image_out(py, w, h, pixels, 3))?;
        }
        if features {
            out.set_item("features", surface)?;
        }
        me.0.last_timings = result.timings;
        Ok(out)
    }

    /// A high-sample reference of animation frame `frame` (default: the last rendered,
    /// else 0) with `spp` samples per pixel, from a sample stream of its own: the image
    /// `dvr reference` writes for that frame.
    #[pyo3(signature = (frame = None, spp = 1024))]
    fn reference<'py>(
        &mut self,
        py: Python<'py>,
        frame: Option<u32>,
        spp: u32,
    ) -> PyResult<Bound<'py, numpy::PyArray3<f32>>> {
        let me = &mut self.inner;
        let f = frame.or(me.0.last_frame).unwrap_or(0);
        if f >= me.0.setup.scene.frames {
            return Err(value_error(format!(
                "frame {f}: the scene has {} frame(s)",
                me.0.setup.scene.frames
            )));
        }
        let inputs = me.0.setup.frame_inputs(f);
        let pixels = py
            .detach(|| me.get().renderer.reference(&inputs, spp, spp))
            .map_err(engine_error)?;
        let (w, h) = (me.0.setup.config.size.width, me.0.setup.config.size.height);
        Ok(image_out(py, w, h, &pixels, 3))
    }

    /// GPU milliseconds per pass of the last rendered frame (`{pass: ms}`).
    fn timings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        for t in &self.inner.0.last_timings {
            let before: f64 = out
                .get_item(&t.pass)?
                .map(|v| v.extract())
                .transpose()?
                .unwrap_or(0.0);
            out.set_item(&t.pass, before + t.ms)?;
        }
        Ok(out)
    }

    /// Frames in the scene's animation.
    #[getter]
    fn frames(&self) -> u32 {
        self.inner.0.setup.scene.frames
    }

    /// The denoisers this renderer runs, in order (the noisy input not counted).
    #[getter]
    fn denoisers(&self) -> Vec<String> {
        let mut names = self.inner.0.renderer.denoiser_names();
        names.retain(|n| n != NOISY_METHOD);
        names
    }

    /// The Vulkan device's name.
    #[getter]
    fn device(&self) -> String {
        self.inner.0.renderer.ctx().info.name.clone()
    }

    /// How the volume is held on the device: "dense volume", or the brick pool's
    /// residency ("brick pool: R of V visible bricks resident …").
    #[getter]
    fn volume_residency(&self) -> String {
        self.inner.0.renderer.volume_residency().to_string()
    }

    /// Samples per pixel per frame.
    #[getter]
    fn spp(&self) -> u32 {
        self.inner.0.setup.settings.spp()
    }

    /// (width, height).
    #[getter]
    fn size(&self) -> (u32, u32) {
        (
            self.inner.0.setup.config.size.width,
            self.inner.0.setup.config.size.height,
        )
    }
}

/// Every denoiser name the registry knows, with its one-line description.
#[pyfunction]
pub fn denoiser_names() -> Vec<(String, String)> {
    dvr_engine::denoise::registry::DENOISERS
        .iter()
        .map(|d| (d.name.to_string(), d.description.to_string()))
        .collect()
}

/// Whether `volume` is not the scene's own built-in dataset (then no dataset-specific
/// network applies).
fn given_is_custom(scene: &dvr_engine::scene::Scene, volume: &dvr_engine::volume::Volume) -> bool {
    match &scene.volume.source {
        dvr_engine::scene::VolumeSource::Builtin { dataset, .. } => dataset.name() != volume.name,
        dvr_engine::scene::VolumeSource::File { .. } => true,
    }
}
