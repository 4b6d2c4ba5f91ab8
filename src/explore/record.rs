//! `--record DIR`: the session as frames and as a scene that replays it.
//!
//! Writes `DIR/frames/NNNN.png` (the displayed denoiser's frame, tone-mapped like
//! `dvr capture`'s PNGs), `DIR/state.jsonl` (one line per frame: camera, lights, the TF
//! file in effect, the denoiser shown), every distinct TF as `DIR/tf/NNN.toml`, and
//! `DIR/session.toml`, a scene whose animation replays the camera, lights, cut, a
//! series' time point, the channels' visibility and colour and the labels' looks frame
//! by frame (step keyframes at each change, so values are exact), which
//! `dvr capture --scene DIR/session.toml --size WxH` renders again.
//!
//! What a scene file cannot animate is replayed approximately and said so in the
//! scene's comment: TF edits become one blend from the first TF to the last, spread
//! over the frames between the first and the last edit (exact for a single edit); light
//! kinds and counts are locked while recording; area-light sizes and gradient
//! environment colours keep their first-frame values; render settings are the last ones;
//! a channel's TF and window keep the scene's (`state.jsonl` has each frame's window).

use anyhow::{Context, Result};
use dvr_engine::files::{write_atomic, Durability::Renamed};
use dvr_engine::scene::{
    self, BuiltinVolume, CameraKey, CameraSpec, ChannelKey, ChannelView, ClipKey, CropKey, Cut,
    Interpolation, LabelKey, LabelView, Light, LightKey, Scene, TfKey, TimeKey, TransferSpec, View,
    VolumeSource,
};
use dvr_engine::transfer::TransferFunction;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The state of one recorded frame.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameState {
    pub camera: CameraSpec,
    pub lights: Vec<Light>,
    pub cut: Cut,
    /// Index into the recorder's distinct TFs.
    pub tf: usize,
    /// A series' time point.
    pub time: f64,
    /// The labels' looks (empty without a label map).
    pub labels: Vec<LabelView>,
    /// The channels of a multi-channel medium (empty for one field).
    pub channels: Vec<ChannelView>,
}

pub struct Recorder {
    dir: PathBuf,
    frames: Vec<FrameState>,
    tfs: Vec<TransferFunction>,
    log: std::fs::File,
}

impl Recorder {
    pub fn new(dir: &Path) -> Result<Self> {
        for d in [dir.to_path_buf(), dir.join("frames"), dir.join("tf")] {
            std::fs::create_dir_all(&d).with_context(|| format!("creating {}", d.display()))?;
        }
        let path = dir.join("state.jsonl");
        let target = dvr_engine::files::output_target(&path)
            .with_context(|| format!("creating {}", path.display()))?;
        let log = std::fs::File::create(&target)
            .with_context(|| format!("creating {}", path.display()))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            frames: Vec::new(),
            tfs: Vec::new(),
            log,
        })
    }

    pub fn frame_path(&self, index: u64) -> PathBuf {
        self.dir.join("frames").join(format!("{index:04}.png"))
    }

    fn tf_name(i: usize) -> String {
        format!("tf/{i:03}.toml")
    }

    /// Records the state of the next frame: `view` (the TF in effect is its `tf.a`) with
    /// `denoiser` shown.
    pub fn push(&mut self, view: &View, denoiser: &str) -> Result<()> {
        let (camera, lights, cut, tf) = (view.camera, &view.lights, &view.cut, &view.tf.a);
        if self.tfs.last() != Some(tf) {
            let path = self.dir.join(Self::tf_name(self.tfs.len()));
            write_atomic(&path, tf.to_toml().as_bytes(), Renamed)
                .with_context(|| format!("writing {}", path.display()))?;
            self.tfs.push(tf.clone());
        }
        let index = self.frames.len();
        let tf_index = self.tfs.len() - 1;
        let light_json: Vec<_> = lights
            .iter()
            .map(|l| {
                serde_json::json!({
                    "kind": format!("{:?}", l.kind()).to_lowercase(),
                    "position": l.position().map(|p| p.to_array()),
                    "colour": l.colour().map(|c| c.to_array()),
                    "intensity": l.intensity(),
                })
            })
            .collect();
        let line = serde_json::json!({
            "frame": index,
            "camera": {
                "position": camera.position.to_array(),
                "target": camera.target.to_array(),
                "up": camera.up.to_array(),
                "fov_y_degrees": camera.fov_y_degrees,
            },
            "lights": light_json,
            "clip": cut.planes.iter().map(|p| serde_json::json!({
                "point": p.point.to_array(),
                "normal": p.normal.to_array(),
                "enabled": p.enabled,
            })).collect::<Vec<_>>(),
            "crop": cut.crop.map(|c| serde_json::json!({
                "min": c.min.to_array(),
                "max": c.max.to_array(),
                "enabled": c.enabled,
            })),
            "tf": Self::tf_name(tf_index),
            "denoiser": denoiser,
            "time": view.time,
            "channels": view.channels.iter().map(|c| serde_json::json!({
                "visible": c.visible,
                "colour": c.colour,
                "window": c.window,
            })).collect::<Vec<_>>(),
            "labels": view.labels.iter().map(|l| serde_json::json!({
                "value": l.value,
                "colour": l.colour,
                "opacity": l.opacity,
                "visible": l.visible,
            })).collect::<Vec<_>>(),
        });
        writeln!(self.log, "{line}").context("writing state.jsonl")?;
        self.frames.push(FrameState {
            camera,
            lights: lights.to_vec(),
            cut: cut.clone(),
            tf: tf_index,
            time: view.time,
            labels: view.labels.clone(),
            channels: view.channels.clone(),
        });
        Ok(())
    }

    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }

    /// Writes `session.toml` from `base` (volume, render settings; procedural volumes
    /// at `volume_size`); returns its path.
    pub fn finish(&self, base: &Scene, volume_size: u32) -> Result<Option<PathBuf>> {
        if self.frames.is_empty() {
            return Ok(None);
        }
        let scene = session_scene(base, &self.frames, &self.tfs, Self::tf_name, volume_size)?;
        let path = self.dir.join("session.toml");
        let text = scene.to_toml().context("writing the session scene")?;
        let note = "# Recorded by `dvr explore --record`: camera, light, cut, time, channel and \
                    label keyframes\n# replay the session exactly; TF edits are one blend from \
                    the first TF to the last (see src/explore/record.rs).\n";
        write_atomic(&path, format!("{note}{text}").as_bytes(), Renamed)
            .with_context(|| format!("writing {}", path.display()))?;
        Ok(Some(path))
    }
}

/// The scene that replays `frames` (see the module docs). `tf_file(i)` is the file
/// (relative to the scene) holding `tfs[i]`; procedural volumes get `volume_size` unless
/// the scene pins one.
pub fn session_scene(
    base: &Scene,
    frames: &[FrameState],
    tfs: &[TransferFunction],
    tf_file: impl Fn(usize) -> String,
    volume_size: u32,
) -> Result<Scene> {
    let first = frames.first().context("no frames recorded")?;
    let mut s = base.clone();
    s.name = "session".into();
    s.frames = frames.len() as u32;
    s.camera = first.camera;
    s.lights = first.lights.clone();
    // A crop box that appears during the session is there from the start, switched off
    // (a scene cannot add one); the plane count is locked while recording.
    s.cut = first.cut.clone();
    if s.cut.crop.is_none() {
        s.cut.crop = frames
            .iter()
            .find_map(|f| f.cut.crop)
            .map(|c| scene::CropBox {
                enabled: false,
                ..c
            });
    }
    // Pin what the replay must not take from elsewhere: the procedural size and
    // absolute volume paths (the scene lives in another folder).
    if let VolumeSource::Builtin { dataset, size } = &mut s.volume.source {
        if size.is_none() && *dataset != BuiltinVolume::Mri {
            *size = Some(volume_size);
        }
    }
    if let VolumeSource::File { path, .. } = &mut s.volume.source {
        if let Ok(abs) = std::fs::canonicalize(&*path) {
            *path = abs;
        }
    }
    let last_tf = frames.last().map_or(0, |f| f.tf);
    s.transfer = TransferSpec {
        a: tf_file(first.tf),
        b: (last_tf != first.tf).then(|| tf_file(last_tf)),
    };
    s.tf_a = tfs[first.tf].clone();
    s.tf_b = (last_tf != first.tf).then(|| tfs[last_tf].clone());
    let mut animation = scene::Animation::default();
    let step = Interpolation::Step;
    // Step keys at frame 0 too: the value at rest is otherwise an implicit *linear* key
    // there, and the replay would glide towards the first change.
    animation.camera.push(CameraKey {
        frame: 0,
        position: Some(first.camera.position),
        target: Some(first.camera.target),
        fov_y_degrees: Some(first.camera.fov_y_degrees),
        interpolation: step,
    });
    for (index, p) in s.cut.planes.iter().enumerate() {
        animation.clip.push(ClipKey {
            index,
            frame: 0,
            point: Some(p.point),
            normal: Some(p.normal),
            enabled: Some(p.enabled),
            interpolation: step,
        });
    }
    if let Some(c) = s.cut.crop {
        animation.crop.push(CropKey {
            frame: 0,
            min: Some(c.min),
            max: Some(c.max),
            enabled: Some(c.enabled),
            interpolation: step,
        });
    }
    if frames.iter().any(|f| f.time != 0.0) {
        animation.time.push(TimeKey {
            frame: 0,
            time: first.time,
            interpolation: step,
        });
    }
    let label_key = |frame: u32, l: &LabelView| LabelKey {
        value: l.value,
        frame,
        visible: Some(l.visible),
        opacity: Some(f64::from(l.opacity)),
        colour: Some(glam::Vec3::from(l.colour).as_dvec3()),
        interpolation: step,
    };
    animation
        .label
        .extend(first.labels.iter().map(|l| label_key(0, l)));
    let channel_key = |frame: u32, index: usize, c: &ChannelView| ChannelKey {
        index,
        frame,
        visible: Some(c.visible),
        colour: Some(glam::Vec3::from(c.colour).as_dvec3()),
        interpolation: step,
    };
    animation.channel.extend(
        first
            .channels
            .iter()
            .enumerate()
            .map(|(i, c)| channel_key(0, i, c)),
    );
    for (index, l) in first.lights.iter().enumerate() {
        animation.light.push(LightKey {
            index,
            frame: 0,
            position: l.position(),
            colour: l.colour(),
            intensity: Some(l.intensity()),
            interpolation: step,
        });
    }
    for (f, w) in frames.windows(2).enumerate() {
        let frame = f as u32 + 1;
        let (prev, cur) = (&w[0], &w[1]);
        if cur.camera != prev.camera {
            animation.camera.push(CameraKey {
                frame,
                position: Some(cur.camera.position),
                target: Some(cur.camera.target),
                fov_y_degrees: Some(cur.camera.fov_y_degrees),
                interpolation: step,
            });
        }
        for (index, (a, b)) in prev.lights.iter().zip(&cur.lights).enumerate() {
            let changed =
                |x: Option<glam::DVec3>, y: Option<glam::DVec3>| (x != y).then_some(y).flatten();
            let key = LightKey {
                index,
                frame,
                position: changed(a.position(), b.position()),
                colour: changed(a.colour(), b.colour()),
                intensity: (a.intensity() != b.intensity()).then_some(b.intensity()),
                interpolation: step,
            };
            if key.position.is_some() || key.colour.is_some() || key.intensity.is_some() {
                animation.light.push(key);
            }
        }
        for (index, (a, b)) in prev.cut.planes.iter().zip(&cur.cut.planes).enumerate() {
            if a != b {
                animation.clip.push(ClipKey {
                    index,
                    frame,
                    point: Some(b.point),
                    normal: Some(b.normal),
                    enabled: Some(b.enabled),
                    interpolation: step,
                });
            }
        }
        if cur.time != prev.time {
            animation.time.push(TimeKey {
                frame,
                time: cur.time,
                interpolation: step,
            });
        }
        for (a, b) in prev.labels.iter().zip(&cur.labels) {
            if a != b {
                animation.label.push(label_key(frame, b));
            }
        }
        for (index, (a, b)) in prev.channels.iter().zip(&cur.channels).enumerate() {
            if (a.visible, a.colour) != (b.visible, b.colour) {
                animation.channel.push(channel_key(frame, index, b));
            }
        }
        if let (Some(b), true) = (cur.cut.crop, prev.cut.crop != cur.cut.crop) {
            animation.crop.push(CropKey {
                frame,
                min: Some(b.min),
                max: Some(b.max),
                enabled: Some(b.enabled),
                interpolation: step,
            });
        }
    }
    // TF: blend 0 until the first edit, 1 from the last.
    let edits: Vec<u32> = frames
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[0].tf != w[1].tf)
        .map(|(f, _)| f as u32 + 1)
        .collect();
    if let (Some(&a), Some(&b), true) = (edits.first(), edits.last(), s.tf_b.is_some()) {
        animation.tf.push(TfKey {
            frame: a - 1,
            blend: Some(0.0),
            shift: None,
            interpolation: Interpolation::Linear,
        });
        animation.tf.push(TfKey {
            frame: b,
            blend: Some(1.0),
            shift: None,
            interpolation: Interpolation::Linear,
        });
    }
    s.animation = animation;
    s.validate()
        .context("the recorded session is not a valid scene")?;
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn base() -> Scene {
        Scene::builtin("phantom/orbit").expect("built-in scene")
    }

    #[test]
    fn replays_camera_and_lights_exactly_at_every_frame() {
        let b = base();
        let cam0 = b.camera;
        let mut frames = Vec::new();
        let mut cam = cam0;
        let mut lights = b.lights.clone();
        let mut cut = Cut {
            planes: vec![scene::ClipPlane {
                point: DVec3::ZERO,
                normal: DVec3::Z,
                enabled: false,
            }],
            crop: None,
        };
        for f in 0..12 {
            if f == 7 {
                cut.planes[0].enabled = true;
            }
            if f == 8 {
                cut.planes[0].point.z = 0.1;
                cut.crop = Some(scene::CropBox {
                    min: DVec3::splat(-0.4),
                    max: DVec3::splat(0.3),
                    units: scene::CropUnits::Box,
                    enabled: true,
                });
            }
            if f == 3 || f == 4 || f == 9 {
                cam.position += DVec3::new(0.013, -0.02, 0.007);
                cam.target += DVec3::new(0.001, 0.0, 0.0);
            }
            if f == 6 {
                lights[0].set_position(DVec3::new(0.3, 0.4, 0.5));
                lights[0].set_intensity(7.5);
            }
            frames.push(FrameState {
                camera: cam,
                lights: lights.clone(),
                cut: cut.clone(),
                tf: 0,
                time: 0.0,
                labels: Vec::new(),
                channels: Vec::new(),
            });
        }
        let s = session_scene(
            &b,
            &frames,
            std::slice::from_ref(&b.tf_a),
            |i| format!("tf/{i:03}.toml"),
            64,
        )
        .expect("scene");
        assert_eq!(s.frames, 12);
        assert!(s.animation.orbit.is_none());
        assert_eq!(s.animation.camera.len(), 4, "frame 0 and three changes");
        for (f, want) in frames.iter().enumerate() {
            let got = s.frame_state(f as u32);
            assert_eq!(got.camera, want.camera.camera(), "camera at frame {f}");
            assert_eq!(got.lights, want.lights, "lights at frame {f}");
            let cut = s.cut_at(f as u32);
            assert_eq!(cut.planes, want.cut.planes, "planes at frame {f}");
            // The crop box appears at frame 8: before, it is there switched off.
            assert_eq!(
                cut.crop.filter(|c| c.enabled),
                want.cut.crop,
                "crop at frame {f}"
            );
        }
    }

    #[test]
    fn a_tf_edit_becomes_a_jump_to_the_new_tf_and_the_scene_file_loads() {
        let b = base();
        let dir = tempfile::tempdir().expect("temp dir");
        let mut edited = b.tf_a.clone();
        edited.points[1].opacity = 0.05;
        let mut rec = Recorder::new(dir.path()).expect("recorder");
        for f in 0..6 {
            let mut view = b.view_at(0);
            view.tf = scene::TfState::single(if f < 4 {
                b.tf_a.clone()
            } else {
                edited.clone()
            });
            rec.push(&view, "ours").expect("push");
        }
        let path = rec.finish(&b, 64).expect("finish").expect("a scene");
        let loaded = Scene::load(&path).expect("session.toml loads");
        assert_eq!(loaded.frames, 6);
        assert_eq!(loaded.tf_a, b.tf_a);
        assert_eq!(loaded.tf_b.as_ref(), Some(&edited));
        let blend = |f| loaded.frame_state(f).tf_blend;
        assert_eq!((blend(3), blend(4), blend(5)), (0.0, 1.0, 1.0));
        let lines = std::fs::read_to_string(dir.path().join("state.jsonl")).expect("log");
        assert_eq!(lines.lines().count(), 6);
        let last: serde_json::Value =
            serde_json::from_str(lines.lines().last().expect("a line")).expect("json");
        assert_eq!(last["tf"], "tf/001.toml");
        assert_eq!(last["denoiser"], "ours");
    }

    #[test]
    fn label_and_time_edits_replay_exactly_at_every_frame() {
        let text = "[volume]\nbuiltin = \"phantom\"\nsize = 16\n[transfer]\na = \"ct-bone\"\n\
                    [labels]\nbuiltin = \"phantom\"\n[[light]]\nkind = \"environment\"\nintensity = 1.0\n";
        let mut b = Scene::from_toml_str(text, "labels.toml").expect("scene");
        b.label_views = (1..=3)
            .map(|value| LabelView {
                value,
                name: format!("label {value}"),
                colour: [0.5, 0.5, 0.5],
                opacity: 1.0,
                visible: true,
            })
            .collect();
        let dir = tempfile::tempdir().expect("temp dir");
        let mut rec = Recorder::new(dir.path()).expect("recorder");
        let mut want = Vec::new();
        for f in 0..8 {
            let mut view = b.view_at(0);
            if f >= 3 {
                view.labels[1].visible = false;
            }
            if f >= 5 {
                view.labels[2].colour = [1.0, 0.0, 0.0];
                view.labels[0].opacity = 0.25;
            }
            // A series' time point scrubbed and held.
            view.time = [0.0, 0.0, 1.5, 1.5, 1.5, 3.25, 3.25, 0.5][f];
            rec.push(&view, "ours").expect("push");
            want.push((view.labels, view.time));
        }
        let s = session_scene(&b, &rec.frames, &rec.tfs, Recorder::tf_name, 16).expect("scene");
        for (f, (labels, time)) in want.iter().enumerate() {
            assert_eq!(&s.labels_at(f as u32), labels, "labels at frame {f}");
            assert_eq!(s.time_at(f as u32), *time, "time at frame {f}");
        }
    }

    #[test]
    fn channel_edits_replay_exactly_at_every_frame() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/assets/scenes/development/microscopy-orbit.toml"
        );
        let mut b = Scene::load(std::path::Path::new(path)).expect("scene");
        b.animation.channel.clear();
        b.channel_views = ["nuclei", "membranes", "marker"]
            .iter()
            .map(|name| ChannelView {
                name: name.to_string(),
                tf: b.tf_a.clone(),
                window: [0.0, 1.0],
                data_window: [0.0, 1.0],
                colour: [0.2, 0.8, 0.4],
                visible: true,
            })
            .collect();
        let dir = tempfile::tempdir().expect("temp dir");
        let mut rec = Recorder::new(dir.path()).expect("recorder");
        let mut want = Vec::new();
        for f in 0..7 {
            let mut view = b.view_at(0);
            if (2..5).contains(&f) {
                view.channels[1].visible = false;
            }
            if f >= 4 {
                view.channels[2].colour = [1.0, 0.1, 0.3];
            }
            rec.push(&view, "ours").expect("push");
            want.push(view.channels);
        }
        let s = session_scene(&b, &rec.frames, &rec.tfs, Recorder::tf_name, 16).expect("scene");
        assert_eq!(
            s.animation.channel.len(),
            3 + 3,
            "frame 0 and three changes"
        );
        for (f, channels) in want.iter().enumerate() {
            assert_eq!(&s.channels_at(f as u32), channels, "channels at frame {f}");
        }
        let lines = std::fs::read_to_string(dir.path().join("state.jsonl")).expect("log");
        let third: serde_json::Value =
            serde_json::from_str(lines.lines().nth(2).expect("a line")).expect("json");
        assert_eq!(third["channels"][1]["visible"], false);
    }
}
