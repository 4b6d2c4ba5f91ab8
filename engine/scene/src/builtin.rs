//! The built-in scenes: every dataset × every scripted animation, generated from two
//! small tables (a look per dataset, a script per animation) so all 30 share one camera,
//! one lighting set-up and one look per dataset, and differ only in what moves.
//!
//! Names are `<dataset>/<animation>`; `dvr scenes --dump NAME` prints one as TOML
//! ([`Scene::to_toml`]), which is also the quickest way to start a scene file.
//!
//! | dataset   | TF `a` → `b`                              | density_scale | max_bounces | sweep        |
//! | --------- | ----------------------------------------- | ------------- | ----------- | ------------ |
//! | `phantom` | `phantom-layered` → `phantom-layered-edit` | 150          | 4           | −0.1 → 0.1   |
//! | `mri`     | `mri-opaque` → `mri-opaque-edit`           | 150          | 4           | −0.12 → 0.18 |
//! | `cloud`   | `cloud` → `cloud-edit`                     | 20           | 8           | 0 → 0.3      |
//!
//! | animation     | what changes (at 60 frames)                          | stresses                         |
//! | ------------- | ---------------------------------------------------- | -------------------------------- |
//! | `orbit`       | camera orbits 1.5°/frame (translation + rotation)    | reprojection                     |
//! | `point-light` | point light sweeps a 180° arc in front of the volume | shading change, static geometry  |
//! | `area-light`  | a 0.5 × 0.5 area light (facing the centre) sweeps a similar arc | soft shadows          |
//! | `light-color` | light colour warm white → red → green → blue → warm white (a hue cycle) | colour drift          |
//! | `tf-edit`     | TF blends `a` → `b` over the whole sequence          | appearance change, no motion     |
//! | `tf-sweep`    | TF `a` slides along density (a window sweep; the range is the look's) | surfaces move without motion |
//! | `dolly`       | camera moves straight in, to 0.8 of its distance     | slow zoom, magnification         |
//! | `tf-jump`     | TF switches `a` → `b` at the middle frame            | recovery after a sudden change   |
//! | `light-jump`  | point light jumps from upper left to lower right at the middle frame | recovery         |
//! | `fast-orbit`  | camera orbits 8°/frame                               | disocclusion, ghosting           |
//!
//! Lighting: a warm-white key light (a point light of intensity 20, upper left in front
//! of the volume; the area light of intensity 70 instead in `area-light`) plus a dim
//! gradient environment (intensity 0.25) as fill, so shadows are not black. The default
//! camera: 1.6 units out, fov 40°, +z up. The intensities are estimates aimed at a
//! radiance of order 1 on lit surfaces (not yet measured on renders): the point light
//! gives an irradiance of ~12 at ~1.3 units, and an isotropic medium returns roughly
//! `albedo × E / 8π` (~0.5) from single scattering, more with multiple scattering.

use glam::{DVec2, DVec3};

use super::animation::{
    Animation, CameraKey, Interpolation, LightKey, Orbit, TfKey, DEFAULT_FRAMES,
};
use super::camera::CameraSpec;
use super::error::{Ctx, SceneError};
use super::light::{AreaLight, EnvSource, EnvironmentLight, Facing, Light, PointLight};
use super::render::RenderSettings;
use super::transfer_ref::TransferSpec;
use super::volume::{BuiltinVolume, VolumeSource, VolumeSpec};
use super::Scene;

/// The scripted animations, in the order they are listed.
pub const ANIMATIONS: [&str; 10] = [
    "orbit",
    "point-light",
    "area-light",
    "light-color",
    "tf-edit",
    "tf-sweep",
    "dolly",
    "tf-jump",
    "light-jump",
    "fast-orbit",
];

/// How one dataset looks in every built-in scene.
struct Look {
    density_scale: f64,
    tf_a: &'static str,
    tf_b: &'static str,
    max_bounces: u32,
    /// The TF shift at the first and last frame of `tf-sweep`: the window slides over
    /// the dataset's tissues without filling empty space (density 0 stays transparent).
    sweep: (f64, f64),
}

fn look(dataset: BuiltinVolume) -> Look {
    match dataset {
        // Semi-transparent isosurfaces, like the paper's MANIX: the hard case.
        BuiltinVolume::Phantom => Look {
            density_scale: 150.0,
            tf_a: "phantom-layered",
            tf_b: "phantom-layered-edit",
            max_bounces: 4,
            sweep: (-0.1, 0.1),
        },
        // An opaque cortex, like the paper's opaque-looking datasets.
        BuiltinVolume::Mri => Look {
            density_scale: 150.0,
            tf_a: "mri-opaque",
            tf_b: "mri-opaque-edit",
            max_bounces: 4,
            sweep: (-0.12, 0.18),
        },
        // Albedo ~0.97: light survives many scattering events. (`sparse` is in no
        // built-in scene; a scene file that names it takes this look's defaults.)
        BuiltinVolume::Cloud | BuiltinVolume::Sparse => Look {
            density_scale: 20.0,
            tf_a: "cloud",
            tf_b: "cloud-edit",
            max_bounces: 8,
            sweep: (0.0, 0.3),
        },
    }
}

const WARM_WHITE: DVec3 = DVec3::new(1.0, 0.95, 0.9);
/// Upper left in front of the volume, as seen from the default camera.
const KEY_POSITION: DVec3 = DVec3::new(-0.9, 1.1, 1.0);
const KEY_INTENSITY: f64 = 20.0;
/// An area light's emitted radiance: 0.25 units² at ~1.2 units gives E ≈ 12.
const AREA_INTENSITY: f64 = 70.0;

fn key_light() -> Light {
    Light::Point(PointLight {
        position: KEY_POSITION,
        colour: WARM_WHITE,
        intensity: KEY_INTENSITY,
    })
}

fn area_light() -> Light {
    Light::Area(AreaLight {
        position: DVec3::new(-0.6, 1.0, 1.1),
        facing: Facing::Target(DVec3::ZERO),
        size: DVec2::new(0.5, 0.5),
        colour: WARM_WHITE,
        intensity: AREA_INTENSITY,
    })
}

fn fill_light() -> Light {
    Light::Environment(EnvironmentLight {
        source: EnvSource::Gradient {
            top: DVec3::new(0.55, 0.65, 0.8),
            bottom: DVec3::new(0.2, 0.18, 0.15),
        },
        intensity: 0.25,
    })
}

/// A point on an arc in front of the volume (azimuth measured from +y towards +x).
fn arc(azimuth_degrees: f64, radius: f64, height: f64) -> DVec3 {
    let a = azimuth_degrees.to_radians();
    // Rounded to millimetres so dumped scenes read cleanly.
    let r = |x: f64| (x * 1000.0).round() / 1000.0;
    DVec3::new(r(radius * a.sin()), r(radius * a.cos()), height)
}

/// Five keyframes spread over the default sequence with positions on an arc.
fn arc_keys(radius: f64, height: f64) -> Vec<LightKey> {
    let last = DEFAULT_FRAMES - 1;
    (0..5u32)
        .map(|i| LightKey {
            index: 0,
            frame: (i * last + 2) / 4,
            position: Some(arc(-90.0 + 45.0 * f64::from(i), radius, height)),
            colour: None,
            intensity: None,
            interpolation: Interpolation::Linear,
        })
        .collect()
}

fn light_key(frame: u32) -> LightKey {
    LightKey {
        index: 0,
        frame,
        position: None,
        colour: None,
        intensity: None,
        interpolation: Interpolation::Linear,
    }
}

/// Lights and animation of one animation name, at [`DEFAULT_FRAMES`], for a dataset's look.
fn script(animation: &str, look: &Look) -> Option<(Vec<Light>, Animation)> {
    let last = DEFAULT_FRAMES - 1;
    let mid = DEFAULT_FRAMES / 2;
    let mut a = Animation::default();
    let orbit = |degrees_per_frame| Orbit {
        degrees_per_frame,
        start_degrees: 0.0,
        center: None,
        radius: None,
        height: None,
    };
    let mut lights = vec![key_light(), fill_light()];
    match animation {
        "orbit" => a.orbit = Some(orbit(1.5)),
        "fast-orbit" => a.orbit = Some(orbit(8.0)),
        "point-light" | "area-light" => {
            let (radius, height) = if animation == "area-light" {
                (1.2, 0.9)
            } else {
                (1.4, 0.8)
            };
            if animation == "area-light" {
                lights[0] = area_light();
            }
            a.light = arc_keys(radius, height);
            // At rest the light sits where its path starts.
            if let Some(p) = a.light.first().and_then(|k| k.position) {
                lights[0].set_position(p);
            }
        }
        "light-color" => {
            let colours = [
                (0, WARM_WHITE),
                (last / 4, DVec3::new(1.0, 0.3, 0.2)),
                (last / 2, DVec3::new(0.3, 1.0, 0.35)),
                (3 * last / 4, DVec3::new(0.3, 0.45, 1.0)),
                (last, WARM_WHITE),
            ];
            a.light = colours
                .into_iter()
                .map(|(frame, c)| LightKey {
                    colour: Some(c),
                    ..light_key(frame)
                })
                .collect();
        }
        "light-jump" => {
            a.light = vec![
                LightKey {
                    position: Some(KEY_POSITION),
                    interpolation: Interpolation::Step,
                    ..light_key(0)
                },
                LightKey {
                    position: Some(DVec3::new(1.1, 0.7, -0.6)),
                    ..light_key(mid)
                },
            ];
        }
        "tf-edit" => {
            a.tf = vec![
                TfKey {
                    frame: 0,
                    blend: Some(0.0),
                    shift: None,
                    interpolation: Interpolation::Linear,
                },
                TfKey {
                    frame: last,
                    blend: Some(1.0),
                    shift: None,
                    interpolation: Interpolation::Linear,
                },
            ];
        }
        "tf-sweep" => {
            a.tf = [(0, look.sweep.0), (last, look.sweep.1)]
                .into_iter()
                .map(|(frame, shift)| TfKey {
                    frame,
                    blend: None,
                    shift: Some(shift),
                    interpolation: Interpolation::Linear,
                })
                .collect();
        }
        "dolly" => {
            a.camera = vec![CameraKey {
                frame: last,
                position: Some(CameraSpec::default().position * 0.8),
                target: None,
                fov_y_degrees: None,
                interpolation: Interpolation::Linear,
            }];
        }
        "tf-jump" => {
            a.tf = vec![
                TfKey {
                    frame: 0,
                    blend: Some(0.0),
                    shift: None,
                    interpolation: Interpolation::Step,
                },
                TfKey {
                    frame: mid,
                    blend: Some(1.0),
                    shift: None,
                    interpolation: Interpolation::Linear,
                },
            ];
        }
        _ => return None,
    }
    Some((lights, a))
}

/// Every built-in scene name, datasets in [`BuiltinVolume::ALL`] order, animations in
/// [`ANIMATIONS`] order.
pub(crate) fn names() -> Vec<String> {
    BuiltinVolume::ALL
        .iter()
        .flat_map(|d| ANIMATIONS.iter().map(move |a| format!("{}/{a}", d.name())))
        .collect()
}

/// The built-in scene `name`, checked, with [`DEFAULT_FRAMES`] frames.
pub(crate) fn build(name: &str) -> Result<Scene, SceneError> {
    let unknown = || SceneError::UnknownBuiltin {
        name: name.to_string(),
        available: names().join(", "),
    };
    let (dataset, animation) = name.split_once('/').ok_or_else(unknown)?;
    let dataset = BuiltinVolume::ALL
        .into_iter()
        .find(|d| d.name() == dataset)
        .ok_or_else(unknown)?;
    let look = look(dataset);
    let (lights, animation) = script(animation, &look).ok_or_else(unknown)?;
    let origin = format!("built-in scene {name}");
    let ctx = Ctx {
        origin: &origin,
        base: None,
    };
    let spec = TransferSpec {
        a: look.tf_a.to_string(),
        b: Some(look.tf_b.to_string()),
    };
    let (transfer, tf_a, tf_b) = spec.resolve(&ctx)?;
    let scene = Scene {
        name: name.to_string(),
        volume: VolumeSpec {
            source: VolumeSource::Builtin {
                dataset,
                size: None,
            },
            density_scale: look.density_scale,
            channels: None,
        },
        transfer,
        tf_a,
        tf_b,
        camera: CameraSpec::default(),
        lights,
        render: {
            let mut r = RenderSettings::default();
            r.set_max_bounces(look.max_bounces)
                .map_err(|e| ctx.invalid("render.max_bounces", e.to_string()))?;
            r
        },
        cut: Default::default(),
        frames: DEFAULT_FRAMES,
        animation,
        channels: Vec::new(),
        channel_views: Vec::new(),
        labels: None,
        label_sections: Vec::new(),
        label_views: Vec::new(),
    };
    scene.check(&ctx)?;
    Ok(scene)
}
