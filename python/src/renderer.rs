//! `dvr.Renderer`: a live session of the engine (`dvr_engine::session::Session`, the
//! type the explorer and `dvr capture` drive too) behind a lock. Its view (camera,
//! lights, TF, render settings, denoisers) is edited between renders and the next
//! render reprojects the change; `render(frame=k)` plays the scene's animation at frame
//! k first, so frames 0..n in order are the animation `dvr eval` renders.

use crate::convert::{image_out, runtime_error, to_toml, value_error};
use crate::scene::{scene_from_dict, tf_from_dict, toml_dict};
use crate::volume::Volume;
use dvr_engine::error::EngineError;
use dvr_engine::gpu::timestamps::PassTiming;
use dvr_engine::gpu::{ContextOptions, GpuContext};
use dvr_engine::graph::Extent;
use dvr_engine::passes::aux_features::{ALBEDO, NORMAL};
use dvr_engine::renderer::medium::{load_channels, Channels};
use dvr_engine::renderer::scene_setup::{load_volume, SceneSetup, DEFAULT_VOLUME_SIZE};
use dvr_engine::renderer::{FrameRequest, FrameResult, FEATURE_IMAGES};
use dvr_engine::scene::{parse_memory_size, TfState, ViewSections};
use dvr_engine::session::{ChannelEdit, Edit, LabelEdit, Session, SessionError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::{Mutex, PoisonError};

/// The registry's pass-through method, whose output `render()` returns as `"noisy"`.
const NOISY_METHOD: &str = "none";

/// Bins of the density histogram `histogram()` returns (the viewer's TF editor draws
/// it).
const HISTOGRAM_BINS: usize = 256;

/// Most samples per pixel a reference takes from Python (2^20: hours on lavapipe at
/// 256², seconds on a GPU).
const MAX_REFERENCE_SPP: i64 = 1 << 20;

/// Engine errors as Python sees them: what the caller asked for is a `ValueError`,
/// what the device did is a `RuntimeError`.
fn engine_error(e: EngineError) -> PyErr {
    match e {
        EngineError::UnknownDenoiser { .. } | EngineError::InvalidSetting { .. } => value_error(e),
        other => runtime_error(other),
    }
}

fn session_error(e: SessionError) -> PyErr {
    match e {
        SessionError::Engine(e) => engine_error(e),
        SessionError::Invalid(_) | SessionError::Setup(_) => value_error(e),
        SessionError::NoRenderer(_) => runtime_error(e),
    }
}

/// Lets the session be used from any Python thread and with the GIL released. It holds
/// Vulkan handles (raw pointers, so the compiler cannot call it `Send`); Vulkan allows a
/// handle on any thread as long as uses are externally synchronised, and they are:
/// every use goes through the renderer's mutex.
struct OnThisThread<T>(T);
unsafe impl<T> Send for OnThisThread<T> {}

#[pyclass(module = "dvr._native", frozen, weakref)]
pub struct Renderer {
    /// `None` once closed. Locked only with the GIL released (see [`Renderer::locked`]),
    /// so a thread waiting for it never holds the GIL another thread needs.
    state: Mutex<Option<OnThisThread<Inner>>>,
}

struct Inner {
    session: Session,
    last_timings: Vec<PassTiming>,
    /// Counts of the volume's normalised densities in [`HISTOGRAM_BINS`] bins.
    histogram: Vec<u32>,
}

impl Renderer {
    /// Runs `f` on the session under the lock, with the GIL released: calls from several
    /// threads serialise here, and Python threads run meanwhile.
    fn locked<R: Send>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&mut Inner) -> PyResult<R> + Send,
    ) -> PyResult<R> {
        py.detach(|| {
            let mut guard = self.state.lock().unwrap_or_else(PoisonError::into_inner);
            match guard.as_mut() {
                Some(inner) => f(&mut inner.0),
                None => Err(runtime_error(
                    "this renderer is closed (close() released its device memory)",
                )),
            }
        })
    }
}

/// An integer argument in `lo..=hi`, or a `ValueError` naming it and the range.
fn in_range(name: &str, value: i64, lo: i64, hi: i64) -> PyResult<u32> {
    if (lo..=hi).contains(&value) {
        Ok(value as u32)
    } else {
        Err(value_error(format!("{name}={value}: must be {lo} to {hi}")))
    }
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
        size: (i64, i64),
        denoisers: Vec<String>,
        volume: Option<PyRef<'_, Volume>>,
        tf: Option<&Bound<'_, PyDict>>,
        spp: Option<i64>,
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
                "size=({w}, {h}): width and height must be 1 to 8192"
            )));
        }
        let (w, h) = (w as u32, h as u32);
        let spp = spp
            .map(|n| in_range("spp", n, 1, i64::from(u32::MAX)))
            .transpose()?;
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
        let given = volume
            .as_ref()
            .map(|v| OnThisThread((&v.inner, v.series.clone())));
        let inner = py.detach(move || -> PyResult<_> {
            let extent = Extent {
                width: w,
                height: h,
            };
            // A file or an array of several channels or time points is a series.
            let channels = match &given {
                Some(v) => match &v.0 .1 {
                    Some(series) => Some(Channels::of(series.clone()).map_err(value_error)?),
                    None => None,
                },
                None => load_channels(&scene).map_err(value_error)?,
            };
            let (mut setup, histogram, custom) = match channels {
                Some(channels) => {
                    let histogram = channels.volumes[0].histogram(HISTOGRAM_BINS);
                    let setup = SceneSetup::with_channels(scene, channels, extent, spp)
                        .map_err(value_error)?;
                    (setup, histogram, true)
                }
                None => {
                    let loaded;
                    let volume = match given {
                        Some(v) => v.0 .0,
                        None => {
                            loaded =
                                load_volume(&scene, DEFAULT_VOLUME_SIZE).map_err(value_error)?;
                            &loaded
                        }
                    };
                    let custom = given_is_custom(&scene, volume);
                    let histogram = volume.histogram(HISTOGRAM_BINS);
                    let setup =
                        SceneSetup::with_volume(scene, volume, extent, spp).map_err(value_error)?;
                    (setup, histogram, custom)
                }
            };
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
            let session = Session::new(setup, ctx, &names).map_err(session_error)?;
            Ok(OnThisThread(Inner {
                session,
                last_timings: Vec::new(),
                histogram,
            }))
        })?;
        Ok(Self {
            state: Mutex::new(Some(inner)),
        })
    }

    /// Renders the current view and returns a dict of `(h, w, 3)` float32 linear
    /// images: `"noisy"` and one per denoiser, plus `"albedo"` and `"normal"` (the
    /// single-frame denoisers' guides) with `aux=True`. With `frame`, the view is first
    /// set to the scene's animation at that frame. `reset=True` restarts every history
    /// first (a cut). `features=True` adds `"features"`: `{"position", "normal",
    /// "albedo"}`, each `(h, w, 4)` float32 (see `FEATURE_IMAGES`).
    #[pyo3(signature = (frame = None, reset = false, aux = false, features = false))]
    fn render<'py>(
        &self,
        py: Python<'py>,
        frame: Option<i64>,
        reset: bool,
        aux: bool,
        features: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let request = FrameRequest {
            readback: true,
            reset,
            aux,
            features,
        };
        let (size, result) = self.locked(py, |me| {
            if let Some(f) = frame {
                let frames = i64::from(me.session.scene().frames);
                let f = in_range("frame", f, 0, frames - 1)?;
                me.session.play(f).map_err(session_error)?;
            }
            let mut out: Vec<FrameResult> = me
                .session
                .frame(&request, None)
                .map_err(session_error)?
                .into_iter()
                .collect();
            out.extend(me.session.flush().map_err(session_error)?);
            let result = out
                .into_iter()
                .max_by_key(|r| r.index)
                .ok_or_else(|| runtime_error("the renderer returned no frame"))?;
            me.last_timings = result.timings.clone();
            Ok((me.session.setup().config.size, result))
        })?;
        frame_dict(py, size, &result, features)
    }

    /// A high-sample reference with `spp` samples per pixel, from a sample stream of its
    /// own: of the current view, or with `frame` of the scene's animation at that frame
    /// (the image `dvr reference` writes for it), leaving the view as it is.
    #[pyo3(signature = (frame = None, spp = 1024))]
    fn reference<'py>(
        &self,
        py: Python<'py>,
        frame: Option<i64>,
        spp: i64,
    ) -> PyResult<Bound<'py, numpy::PyArray3<f32>>> {
        let spp = in_range("spp", spp, 1, MAX_REFERENCE_SPP)?;
        let (size, pixels) = self.locked(py, |me| {
            let s = &mut me.session;
            let batch = s.renderer().map_err(session_error)?.samples_per_dispatch();
            let pixels = match frame {
                Some(f) => {
                    let f = in_range("frame", f, 0, i64::from(s.scene().frames) - 1)?;
                    s.reference_at(f, spp, batch)
                }
                None => s.reference(spp, batch),
            }
            .map_err(session_error)?;
            Ok((s.setup().config.size, pixels))
        })?;
        Ok(image_out(py, size.width, size.height, &pixels, 3))
    }

    /// The view's camera, lights, render settings and cut as the dict a scene file's
    /// `[camera]`, `[[light]]`, `[render]`, `[[clip]]` and `[crop]` sections hold
    /// (`camera`, `light`, `render`, `clip`, `crop`).
    fn view<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text = self.locked(py, |me| {
            let s = &me.session;
            let sections = ViewSections {
                camera: s.view().camera,
                lights: s.view().lights.clone(),
                render: *s.settings(),
                cut: s.view().cut.clone(),
            };
            sections.to_toml().map_err(value_error)
        })?;
        toml_dict(py, &text)
    }

    /// Edits the view: `view` is a dict like [`Renderer::view`]'s (all three sections),
    /// checked as a scene file's sections are; each section that differs from the
    /// current one is an edit, settings first. Raises `ValueError` naming the field.
    fn set_view(&self, py: Python<'_>, view: &Bound<'_, PyDict>) -> PyResult<()> {
        let value = to_toml(view.as_any(), "view")?;
        let text = toml::to_string(&value).map_err(value_error)?;
        self.locked(py, |me| {
            let new = ViewSections::from_toml_str(&text, "view").map_err(value_error)?;
            let s = &mut me.session;
            if new.render != *s.settings() {
                s.edit(Edit::Settings(new.render)).map_err(session_error)?;
            }
            if new.lights != s.view().lights {
                s.edit(Edit::Lights(new.lights)).map_err(session_error)?;
            }
            if new.camera != s.view().camera {
                s.edit(Edit::Camera(new.camera)).map_err(session_error)?;
            }
            if new.cut != s.view().cut {
                s.edit(Edit::Cut(new.cut)).map_err(session_error)?;
            }
            Ok(())
        })
    }

    /// The time point shown (fractional: two interpolated) and the series' count.
    fn time(&self, py: Python<'_>) -> PyResult<(f64, usize)> {
        self.locked(py, |me| {
            let s = &me.session;
            let times = s.setup().timeline.as_ref().map_or(1, |t| t.times());
            Ok((s.view().time, times))
        })
    }

    /// Shows time point `time` (fractional: the two around it interpolated); raises
    /// `ValueError` naming the range.
    fn set_time(&self, py: Python<'_>, time: f64) -> PyResult<()> {
        self.edit(py, Edit::Time(time))
    }

    /// Each channel of a multi-channel medium: `{"name", "tf" (a TF file's dict),
    /// "window", "data_window", "colour", "visible"}`; empty for one field.
    fn channels<'py>(&self, py: Python<'py>) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let views = self.locked(py, |me| Ok(me.session.view().channels.clone()))?;
        views
            .iter()
            .map(|c| {
                let d = PyDict::new(py);
                d.set_item("name", &c.name)?;
                d.set_item("tf", toml_dict(py, &c.tf.to_toml())?)?;
                d.set_item("window", c.window.to_vec())?;
                d.set_item("data_window", c.data_window.to_vec())?;
                d.set_item("colour", c.colour.to_vec())?;
                d.set_item("visible", c.visible)?;
                Ok(d)
            })
            .collect()
    }

    /// Edits channel `index`: what is given changes. Raises `ValueError` naming the
    /// field.
    #[pyo3(signature = (index, tf = None, window = None, colour = None, visible = None))]
    fn edit_channel(
        &self,
        py: Python<'_>,
        index: usize,
        tf: Option<&Bound<'_, PyDict>>,
        window: Option<(f32, f32)>,
        colour: Option<(f32, f32, f32)>,
        visible: Option<bool>,
    ) -> PyResult<()> {
        let edit = ChannelEdit {
            index,
            tf: tf.map(tf_from_dict).transpose()?,
            window: window.map(|(a, b)| [a, b]),
            colour: colour.map(|(r, g, b)| [r, g, b]),
            visible,
        };
        self.edit(py, Edit::Channel(edit))
    }

    /// The label map's mode (`"tint"` or `"solid"`; `None` without a label map) and
    /// each of its labels: `{"value", "name", "colour", "opacity", "visible"}` by value.
    fn labels<'py>(&self, py: Python<'py>) -> PyResult<(Option<String>, Vec<Bound<'py, PyDict>>)> {
        let (mode, views) = self.locked(py, |me| {
            let s = &me.session;
            let mode = s.setup().labels.as_ref().map(|l| l.mode);
            Ok((mode, s.view().labels.clone()))
        })?;
        let mode = mode.map(|m| match m {
            dvr_engine::scene::LabelMode::Tint => "tint".to_string(),
            dvr_engine::scene::LabelMode::Solid => "solid".to_string(),
        });
        let views = views
            .iter()
            .map(|l| {
                let d = PyDict::new(py);
                d.set_item("value", l.value)?;
                d.set_item("name", &l.name)?;
                d.set_item("colour", l.colour.to_vec())?;
                d.set_item("opacity", l.opacity)?;
                d.set_item("visible", l.visible)?;
                Ok(d)
            })
            .collect::<PyResult<Vec<_>>>()?;
        Ok((mode, views))
    }

    /// Edits label `value` (`None`: every label): what is given changes. Raises
    /// `ValueError` naming the field.
    #[pyo3(signature = (value, colour = None, opacity = None, visible = None))]
    fn edit_label(
        &self,
        py: Python<'_>,
        value: Option<u16>,
        colour: Option<(f32, f32, f32)>,
        opacity: Option<f32>,
        visible: Option<bool>,
    ) -> PyResult<()> {
        let edit = LabelEdit {
            value,
            colour: colour.map(|(r, g, b)| [r, g, b]),
            opacity,
            visible,
        };
        self.edit(py, Edit::Label(edit))
    }

    /// What lies under pixel (x, y) (row 0 at the top): `{"position", "voxel",
    /// "intensity", "label", "label_name"}`, or `None` where the ray meets nothing.
    /// Renders one frame of the current view.
    fn pick<'py>(&self, py: Python<'py>, x: i64, y: i64) -> PyResult<Option<Bound<'py, PyDict>>> {
        if x < 0 || y < 0 || x > i64::from(u32::MAX) || y > i64::from(u32::MAX) {
            return Err(value_error(format!(
                "pick({x}, {y}): pixel coordinates must be >= 0"
            )));
        }
        let pick = self.locked(py, |me| {
            me.session.pick(x as u32, y as u32).map_err(session_error)
        })?;
        pick.map(|p| {
            let d = PyDict::new(py);
            d.set_item("position", p.position.to_vec())?;
            d.set_item("voxel", p.voxel.to_vec())?;
            d.set_item("intensity", p.intensity)?;
            d.set_item("label", p.label)?;
            d.set_item("label_name", p.label_name)?;
            Ok(d)
        })
        .transpose()
    }

    /// The transfer function in effect: `{"a": tf, "b": tf or None, "blend": x,
    /// "shift": y}` (tf as a TF file's dict).
    fn tf<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (a, b, blend, shift) = self.locked(py, |me| {
            let tf = &me.session.view().tf;
            Ok((
                tf.a.to_toml(),
                tf.b.as_ref().map(|b| b.to_toml()),
                tf.blend,
                tf.shift,
            ))
        })?;
        let out = PyDict::new(py);
        out.set_item("a", toml_dict(py, &a)?)?;
        out.set_item("b", b.map(|b| toml_dict(py, &b)).transpose()?)?;
        out.set_item("blend", blend)?;
        out.set_item("shift", shift)?;
        Ok(out)
    }

    /// Sets the transfer function (a TF dict: `{"name": ..., "point": [...]}`).
    fn set_tf(&self, py: Python<'_>, tf: &Bound<'_, PyDict>) -> PyResult<()> {
        let tf = tf_from_dict(tf)?;
        self.edit(py, Edit::Tf(TfState::single(tf)))
    }

    /// Runs `denoisers` (registry names) from the next render on, with fresh histories.
    fn set_denoisers(&self, py: Python<'_>, denoisers: Vec<String>) -> PyResult<()> {
        let mut names = vec![NOISY_METHOD.to_string()];
        names.extend(denoisers.into_iter().filter(|n| n != NOISY_METHOD));
        self.edit(py, Edit::Denoisers(names))
    }

    /// A left-drag of (dx, dy) pixels in the explorer: orbits the camera about its
    /// target.
    fn orbit(&self, py: Python<'_>, dx: f64, dy: f64) -> PyResult<()> {
        self.edit(py, Edit::Orbit { dx, dy })
    }

    /// A right-drag of (dx, dy) pixels: the point under the cursor follows it.
    fn pan(&self, py: Python<'_>, dx: f64, dy: f64) -> PyResult<()> {
        self.edit(py, Edit::Pan { dx, dy })
    }

    /// Wheel steps; positive zooms in.
    fn zoom(&self, py: Python<'_>, steps: f64) -> PyResult<()> {
        self.edit(py, Edit::Zoom { steps })
    }

    /// Back to the camera the renderer started with.
    fn reset_camera(&self, py: Python<'_>) -> PyResult<()> {
        self.edit(py, Edit::ResetCamera)
    }

    /// Flies to fit the volume, keeping the viewing direction.
    fn fit(&self, py: Python<'_>) -> PyResult<()> {
        self.edit(py, Edit::FitCamera)
    }

    /// Renders at (width, height) from the next render on (histories restart).
    fn resize(&self, py: Python<'_>, width: i64, height: i64) -> PyResult<()> {
        let size = Extent {
            width: in_range("width", width, 1, 8192)?,
            height: in_range("height", height, 1, 8192)?,
        };
        self.locked(py, |me| {
            me.session.resize(size, size).map_err(session_error)?;
            Ok(())
        })
    }

    /// Releases the device memory now (the renderer is unusable after).
    fn close(&self, py: Python<'_>) {
        let taken = py.detach(|| {
            self.state
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .take()
        });
        py.detach(move || drop(taken));
    }

    /// Whether [`Renderer::close`] was called.
    #[getter]
    fn closed(&self, py: Python<'_>) -> bool {
        py.detach(|| {
            self.state
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .is_none()
        })
    }

    /// GPU milliseconds per pass of the last rendered frame (`{pass: ms}`).
    fn timings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let timings = self.locked(py, |me| Ok(me.last_timings.clone()))?;
        let out = PyDict::new(py);
        for t in &timings {
            let before: f64 = out
                .get_item(&t.pass)?
                .map(|v| v.extract())
                .transpose()?
                .unwrap_or(0.0);
            out.set_item(&t.pass, before + t.ms)?;
        }
        Ok(out)
    }

    /// Device memory the renderer's context holds, bytes: `(allocated, reserved)` (live
    /// allocations; memory blocks, free room included).
    fn gpu_memory(&self, py: Python<'_>) -> PyResult<(u64, u64)> {
        self.locked(py, |me| {
            let m = me.session.ctx().memory_in_use();
            Ok((m.allocated, m.reserved))
        })
    }

    /// Counts of the volume's normalised densities in 256 equal bins over [0, 1].
    fn histogram(&self, py: Python<'_>) -> PyResult<Vec<u32>> {
        self.locked(py, |me| Ok(me.histogram.clone()))
    }

    /// Frames in the scene's animation (what `render(frame=k)` plays).
    #[getter]
    fn frames(&self, py: Python<'_>) -> PyResult<u32> {
        self.locked(py, |me| Ok(me.session.scene().frames))
    }

    /// Frames rendered so far.
    #[getter]
    fn frames_rendered(&self, py: Python<'_>) -> PyResult<u64> {
        self.locked(py, |me| Ok(me.session.frames()))
    }

    /// The denoisers this renderer runs, in order (the noisy input not counted).
    #[getter]
    fn denoisers(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        self.locked(py, |me| {
            Ok(me
                .session
                .denoisers()
                .iter()
                .filter(|n| *n != NOISY_METHOD)
                .cloned()
                .collect())
        })
    }

    /// The Vulkan device's name.
    #[getter]
    fn device(&self, py: Python<'_>) -> PyResult<String> {
        self.locked(py, |me| Ok(me.session.ctx().info.name.clone()))
    }

    /// How the volume is held on the device: "dense volume", or the brick pool's
    /// residency ("brick pool: R of V visible bricks resident …").
    #[getter]
    fn volume_residency(&self, py: Python<'_>) -> PyResult<String> {
        self.locked(py, |me| {
            let r = me.session.renderer().map_err(session_error)?;
            Ok(r.volume_residency().to_string())
        })
    }

    /// Samples per pixel per frame.
    #[getter]
    fn spp(&self, py: Python<'_>) -> PyResult<u32> {
        self.locked(py, |me| Ok(me.session.settings().spp()))
    }

    /// (width, height).
    #[getter]
    fn size(&self, py: Python<'_>) -> PyResult<(u32, u32)> {
        self.locked(py, |me| {
            let s = me.session.view_size();
            Ok((s.width, s.height))
        })
    }
}

impl Renderer {
    fn edit(&self, py: Python<'_>, edit: Edit) -> PyResult<()> {
        self.locked(py, |me| {
            me.session.edit(edit).map_err(session_error)?;
            Ok(())
        })
    }
}

/// A finished frame as `render()`'s dict.
fn frame_dict<'py>(
    py: Python<'py>,
    size: Extent,
    result: &FrameResult,
    features: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (w, h) = (size.width, size.height);
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
    Ok(out)
}

/// A sentence for each parameter override (`DVR_OURS`, `DVR_WRLS`, `DVR_SVGF`) set in
/// the environment that none of `running` reads.
#[pyfunction]
pub fn unused_overrides(running: Vec<String>) -> Vec<String> {
    let names: Vec<&str> = running.iter().map(String::as_str).collect();
    dvr_engine::denoise::unused_overrides(&names)
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
        dvr_engine::scene::VolumeSource::File { .. }
        | dvr_engine::scene::VolumeSource::Files { .. } => true,
    }
}
