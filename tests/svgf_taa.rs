//! `svgf` and `taa` on the device.
//!
//! On synthetic frames (a static scene of two planes and a background, exact features):
//! SVGF's frame 0 is a pure spatial filter (it equals a CPU reference of the spatial
//! passes built from `svgf::edge`, the mirror of the GLSL weights, and does not change
//! when the histories hold garbage or were reset after other frames); accumulation lowers
//! the error; edges between surfaces are kept. With the path tracer on a static constant
//! volume: 50 frames of finite, bounded output from both, validation clean.

mod common;

use common::*;
use dvr_engine::denoise::svgf::{edge, SvgfParams};
use dvr_engine::denoise::Changes;
use dvr_engine::passes::surface_features::STEP_VOXELS;
use dvr_engine::renderer::FrameRequest;
use dvr_engine::shaders::frame::FrameBlock;
use glam::{IVec4, Vec3, Vec4};

const W: usize = 32;
const H: usize = 24;
/// Voxels of the (pretend) volume along each axis of a unit box: sets the depth quantum.
const DIMS: i32 = 64;

type Px = [f32; 4];

// ---------------------------------------------------------------------------------------
// A synthetic static scene with exact features.

/// Region A (x < 12): a plane facing the camera, depth 1 + 0.002 x. Region B (x ≥ 12,
/// y < 16): a plane tilted 45°, depth 1.5 + 0.01 (x − 12). Region C (x ≥ 12, y ≥ 16):
/// background, no surface.
struct Scene {
    albedo: Vec<Px>,
    normal: Vec<Px>,
    position: Vec<Px>,
    /// Noise-free radiance.
    truth: Vec<[f32; 3]>,
}

fn region(x: usize, y: usize) -> u8 {
    if x < 12 {
        b'A'
    } else if y < 16 {
        b'B'
    } else {
        b'C'
    }
}

fn scene() -> Scene {
    let mut s = Scene {
        albedo: Vec::new(),
        normal: Vec::new(),
        position: Vec::new(),
        truth: Vec::new(),
    };
    let tilted = Vec3::new(1.0, 0.0, 1.0).normalize();
    for y in 0..H {
        for x in 0..W {
            let (a, n, z, light) = match region(x, y) {
                b'A' => ([0.8, 0.6, 0.5], Vec3::Z, 1.0 + 0.002 * x as f32, 1.0),
                b'B' => ([0.3, 0.7, 0.9], tilted, 1.5 + 0.01 * (x - 12) as f32, 0.5),
                _ => ([0.0; 3], Vec3::ZERO, 0.0, 0.3),
            };
            let valid = region(x, y) != b'C';
            s.albedo.push([a[0], a[1], a[2], valid as u32 as f32]);
            s.normal.push([n.x, n.y, n.z, z]);
            let pos = [x as f32 / W as f32, y as f32 / H as f32, -z, 1.0];
            s.position.push(if valid { pos } else { [0.0; 4] });
            let m = if valid { a } else { [1.0; 3] };
            s.truth.push(m.map(|c| c * light));
        }
    }
    s
}

/// Deterministic noisy radiance: the truth times a per-pixel factor uniform in [0, 2).
fn noisy(s: &Scene, seed: u64) -> Vec<Px> {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    s.truth
        .iter()
        .map(|t| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let f = 2.0 * ((state >> 40) as f32 / (1u64 << 24) as f32);
            [t[0] * f, t[1] * f, t[2] * f, 1.0]
        })
        .collect()
}

// ---------------------------------------------------------------------------------------
// One denoiser on the scene's frames, outside the renderer.

struct Harness {
    harness: harness::Harness,
    scene: Scene,
}

impl Harness {
    fn new(name: &str) -> Self {
        Self {
            harness: harness::Harness::new(name, W as u32, H as u32),
            scene: scene(),
        }
    }

    /// Feeds one noisy frame of the static scene; returns the denoiser's output.
    fn step(&mut self, noisy: &[Px]) -> Vec<Px> {
        let mut u: FrameBlock = bytemuck::Zeroable::zeroed();
        u.box_min = Vec4::new(-0.5, -0.5, -0.5, 1.0);
        u.box_max = Vec4::new(0.5, 0.5, 0.5, 1.0);
        u.dims = IVec4::new(DIMS, DIMS, DIMS, 8);
        // The scene's positions are (x/W, y/H, −z): a camera that projects them back onto
        // their pixel centres, so the reprojection round trip holds for a still camera.
        u.view_proj = glam::Mat4::from_cols(
            Vec4::new(2.0, 0.0, 0.0, 0.0),
            Vec4::new(0.0, 2.0, 0.0, 0.0),
            Vec4::ZERO,
            Vec4::new(1.0 / W as f32 - 1.0, 1.0 / H as f32 - 1.0, 0.0, 1.0),
        );
        u.prev_view_proj = u.view_proj;
        self.harness.step_with(&harness::Synthetic {
            noisy,
            moments: &vec![[0.0; 4]; W * H],
            position: &self.scene.position,
            normal: &self.scene.normal,
            albedo: &self.scene.albedo,
            uniforms: u,
            camera: Vec3::new(0.5, 0.5, 0.0),
            spp: 2,
            changes: Changes::default(),
        })
    }
}

// ---------------------------------------------------------------------------------------
// CPU reference of SVGF's frame 0 (no history): demodulate, spatial variance estimate,
// five à-trous iterations, remodulate, from the weight functions in `svgf::edge`.

struct Geo {
    valid: bool,
    n: Vec3,
    z: f32,
    slope: f32,
}

fn cpu_svgf_frame0(s: &Scene, noisy: &[Px], p: &SvgfParams) -> Vec<[f32; 3]> {
    let idx = |x: i32, y: i32| y as usize * W + x as usize;
    let inside = |x: i32, y: i32| x >= 0 && y >= 0 && x < W as i32 && y < H as i32;
    let valid = |i: usize| s.albedo[i][3] > 0.0;
    let factor = |i: usize| -> [f32; 3] {
        let a = s.albedo[i];
        if valid(i) {
            [a[0] + p.demod_eps, a[1] + p.demod_eps, a[2] + p.demod_eps]
        } else {
            [1.0; 3]
        }
    };
    let quantum = (1.0 / DIMS as f32) * STEP_VOXELS;
    let mut geo = Vec::new();
    for y in 0..H as i32 {
        for x in 0..W as i32 {
            let i = idx(x, y);
            let z = s.normal[i][3];
            let axis = |ax: i32, ay: i32| {
                let mut g = f32::INFINITY;
                for sgn in [-1, 1] {
                    let (qx, qy) = (x + sgn * ax, y + sgn * ay);
                    if inside(qx, qy) && valid(idx(qx, qy)) {
                        g = g.min((s.normal[idx(qx, qy)][3] - z).abs());
                    }
                }
                if g.is_finite() {
                    g
                } else {
                    0.0
                }
            };
            let n = s.normal[i];
            // As svgf_temporal packs it: no threshold surface is the medium where the
            // ray meets any (an expected collision), else the background.
            let class = match (valid(i), s.position[i][3] > 0.0) {
                (true, _) => z,
                (false, true) => edge::MEDIUM,
                (false, false) => edge::BACKGROUND,
            };
            geo.push(Geo {
                valid: valid(i),
                n: Vec3::new(n[0], n[1], n[2]),
                z: class,
                slope: edge::depth_slope(axis(1, 0).max(axis(0, 1)), quantum),
            });
        }
    }
    let gw = |a: &Geo, b: &Geo, dist: f32| {
        let phi = edge::phi_z(p.sigma_z, a.slope, dist);
        edge::geometry_weight(a.valid, b.valid, a.z, b.z, phi, a.n, b.n, p.sigma_n)
    };
    // Demodulated colour; moments of its luminance.
    let demod: Vec<[f32; 3]> = (0..W * H)
        .map(|i| {
            let f = factor(i);
            [0, 1, 2].map(|c| noisy[i][c] / f[c])
        })
        .collect();
    let lum: Vec<f32> = demod.iter().map(|d| edge::luminance(*d)).collect();
    // Spatial variance (history length 1 < min_history), boosted by min_history / 1.
    let mut color: Vec<[f32; 4]> = Vec::new();
    for y in 0..H as i32 {
        for x in 0..W as i32 {
            let i = idx(x, y);
            let (mut m1, mut m2, mut ws) = (lum[i], lum[i] * lum[i], 1.0f32);
            for dy in -3..=3i32 {
                for dx in -3..=3i32 {
                    let (qx, qy) = (x + dx, y + dy);
                    if (dx == 0 && dy == 0) || !inside(qx, qy) {
                        continue;
                    }
                    let q = idx(qx, qy);
                    let w = gw(&geo[i], &geo[q], ((dx * dx + dy * dy) as f32).sqrt());
                    m1 += w * lum[q];
                    m2 += w * lum[q] * lum[q];
                    ws += w;
                }
            }
            let (m1, m2) = (m1 / ws, m2 / ws);
            let var = (m2 - m1 * m1).max(0.0) * p.min_history;
            color.push([demod[i][0], demod[i][1], demod[i][2], var]);
        }
    }
    // À-trous iterations.
    for it in 0..p.iterations {
        let step = 1i32 << it;
        let mut next = Vec::with_capacity(W * H);
        for y in 0..H as i32 {
            for x in 0..W as i32 {
                let i = idx(x, y);
                let c = color[i];
                let lp = edge::luminance([c[0], c[1], c[2]]);
                let k = [0.5f32, 0.25];
                let mut var_g = 0.0;
                for dy in -1..=1i32 {
                    for dx in -1..=1i32 {
                        let qx = (x + dx).clamp(0, W as i32 - 1);
                        let qy = (y + dy).clamp(0, H as i32 - 1);
                        var_g += k[dx.unsigned_abs() as usize]
                            * k[dy.unsigned_abs() as usize]
                            * color[idx(qx, qy)][3];
                    }
                }
                let phi_l = edge::phi_l(p.sigma_l, var_g, p.luminance_eps);
                let k0 = edge::B3[0] * edge::B3[0];
                let mut sum = [c[0] * k0, c[1] * k0, c[2] * k0];
                let mut var_sum = k0 * k0 * c[3];
                let mut ws = k0;
                for dy in -2..=2i32 {
                    for dx in -2..=2i32 {
                        let (qx, qy) = (x + dx * step, y + dy * step);
                        if (dx == 0 && dy == 0) || !inside(qx, qy) {
                            continue;
                        }
                        let q = idx(qx, qy);
                        let cq = color[q];
                        let dist = step as f32 * ((dx * dx + dy * dy) as f32).sqrt();
                        let w = edge::B3[dx.unsigned_abs() as usize]
                            * edge::B3[dy.unsigned_abs() as usize]
                            * gw(&geo[i], &geo[q], dist)
                            * edge::luminance_weight(
                                lp,
                                edge::luminance([cq[0], cq[1], cq[2]]),
                                phi_l,
                            );
                        for ch in 0..3 {
                            sum[ch] += w * cq[ch];
                        }
                        var_sum += w * w * cq[3];
                        ws += w;
                    }
                }
                next.push([sum[0] / ws, sum[1] / ws, sum[2] / ws, var_sum / (ws * ws)]);
            }
        }
        color = next;
    }
    (0..W * H)
        .map(|i| {
            let f = factor(i);
            [0, 1, 2].map(|c| color[i][c] * f[c])
        })
        .collect()
}

fn rmse(out: &[Px], truth: &[[f32; 3]]) -> f32 {
    let s: f32 = out
        .iter()
        .zip(truth)
        .map(|(o, t)| (0..3).map(|c| (o[c] - t[c]).powi(2)).sum::<f32>())
        .sum();
    (s / (3 * out.len()) as f32).sqrt()
}

fn max_abs_diff(a: &[Px], b: &[Px]) -> f32 {
    a.iter()
        .zip(b)
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs()))
        .fold(0.0, f32::max)
}

// ---------------------------------------------------------------------------------------

#[test]
fn svgf_frame0_equals_the_cpu_spatial_reference() {
    let mut h = Harness::new("svgf");
    let input = noisy(&h.scene, 7);
    let gpu = h.step(&input);
    let cpu = cpu_svgf_frame0(&h.scene, &input, &SvgfParams::default());
    let mut worst = 0.0f32;
    for (i, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
        for ch in 0..3 {
            let err = (g[ch] - c[ch]).abs() / (c[ch].abs() + 0.05);
            assert!(
                err < 2e-3,
                "pixel ({}, {}) channel {ch}: gpu {} cpu {}",
                i % W,
                i / W,
                g[ch],
                c[ch]
            );
            worst = worst.max(err);
        }
    }
    println!("frame 0: worst relative GPU/CPU difference {worst:.2e}");
    // The spatial filter does filter: much closer to the truth than its input.
    let (e_in, e_out) = (rmse(&input, &h.scene.truth), rmse(&gpu, &h.scene.truth));
    println!("frame 0 RMSE: input {e_in:.4}, svgf {e_out:.4}");
    assert!(e_out < 0.5 * e_in);
    drop(h);
    assert_validation_clean();
}

#[test]
fn svgf_frame0_ignores_garbage_and_reset_histories() {
    let s = scene();
    let input = noisy(&s, 11);
    let clean = Harness::new("svgf").step(&input);

    // Histories full of NaN and huge values: frame 0 must not read them.
    let mut poisoned = Harness::new("svgf");
    let garbage: Vec<Px> = (0..W * H)
        .map(|i| match i % 3 {
            0 => [f32::NAN; 4],
            1 => [1e30, -1e30, 1e30, 1e30],
            _ => [5.0, 0.0, 5.0, 2.0],
        })
        .collect();
    poisoned.harness.poison_history("svgf.color", &garbage);
    poisoned.harness.poison_history("svgf.moments", &garbage);
    let out = poisoned.step(&input);
    assert_eq!(
        max_abs_diff(&out, &clean),
        0.0,
        "garbage history changed frame 0"
    );

    // Several frames of other noise, then a reset: the same result as a fresh start.
    let mut reset = Harness::new("svgf");
    for k in 0..4 {
        reset.step(&noisy(&s, 100 + k));
    }
    reset.harness.reset("svgf.");
    let out = reset.step(&input);
    assert_eq!(
        max_abs_diff(&out, &clean),
        0.0,
        "reset history changed frame 0"
    );
    drop((poisoned, reset));
    assert_validation_clean();
}

#[test]
fn svgf_accumulates_and_keeps_edges() {
    let mut h = Harness::new("svgf");
    let first = h.step(&noisy(&h.scene, 0));
    let mut out = first.clone();
    for k in 1..20 {
        out = h.step(&noisy(&h.scene, k));
    }
    let truth = h.scene.truth.clone();
    let (e0, e19) = (rmse(&first, &truth), rmse(&out, &truth));
    println!("svgf RMSE: frame 0 {e0:.4}, frame 19 {e19:.4}");
    assert!(e19 < 0.7 * e0, "accumulation did not reduce the error");
    // Pixels next to an edge stay close to their own surface's value (A's boundary
    // column x = 11 next to B and C; B's last row y = 15 above the background C).
    let rel = |x: usize, y: usize| {
        let i = y * W + x;
        (0..3)
            .map(|c| (out[i][c] - truth[i][c]).abs() / truth[i][c])
            .fold(0.0f32, f32::max)
    };
    let worst_a = (0..H).map(|y| rel(11, y)).fold(0.0f32, f32::max);
    let worst_b = (12..W).map(|x| rel(x, 15)).fold(0.0f32, f32::max);
    println!("worst relative error at edges: A {worst_a:.3}, B {worst_b:.3}");
    assert!(worst_a < 0.25 && worst_b < 0.25, "an edge was blurred");
    drop(h);
    assert_validation_clean();
}

#[test]
fn taa_converges_on_a_static_input_and_restarts_after_reset() {
    let mut h = Harness::new("taa");
    let input0 = noisy(&h.scene, 0);
    let first = h.step(&input0);
    assert_eq!(max_abs_diff(&first, &input0), 0.0, "frame 0 is the input");
    let mut out = first;
    for k in 1..40 {
        out = h.step(&noisy(&h.scene, k));
    }
    let truth = h.scene.truth.clone();
    let (e_in, e_out) = (rmse(&input0, &truth), rmse(&out, &truth));
    println!("taa RMSE after 40 frames: {e_out:.4} (input {e_in:.4})");
    assert!(e_out < 0.6 * e_in);
    h.harness.reset("taa.");
    let input = noisy(&h.scene, 99);
    assert_eq!(max_abs_diff(&h.step(&input), &input), 0.0, "reset restarts");
    drop(h);
    assert_validation_clean();
}

// ---------------------------------------------------------------------------------------
// With the path tracer.

#[test]
fn svgf_and_taa_stay_finite_and_bounded_for_50_frames() {
    let volume = constant_volume(16, 0.5);
    let mut r = renderer(
        context(),
        settings(32, 2),
        &volume,
        &["none", "taa", "svgf"],
    );
    let lights = vec![point_light(Vec3::new(1.0, 1.0, 2.0), 6.0), environment(0.3)];
    let lut = constant_lut(0.3, 0.8);
    let request = FrameRequest {
        readback: true,
        reset: false,
        aux: false,
        features: false,
    };
    let mut results = Vec::new();
    for k in 0..60 {
        // 50 static frames, then 10 with the camera orbiting (reprojection in use).
        let angle = (k.max(50) - 50) as f32 * 2f32.to_radians();
        let eye = Vec3::new(2.5 * angle.sin(), 0.0, 2.5 * angle.cos());
        let camera = dvr_engine::renderer::CameraMatrices::look_at(
            eye,
            Vec3::ZERO,
            Vec3::Y,
            40f32.to_radians(),
            1.0,
        );
        let frame = inputs(camera, lights.clone(), lut.clone());
        results.extend(r.frame(&frame, &request).expect("frame"));
    }
    results.extend(r.flush().expect("flush"));
    assert_eq!(results.len(), 60);
    for res in &results {
        let image = |name: &str| {
            &res.images
                .iter()
                .find(|(n, _)| n == name)
                .unwrap_or_else(|| panic!("no {name} readback"))
                .1
        };
        let input_max = image("none")
            .iter()
            .flat_map(|p| p[..3].iter().copied())
            .filter(|v| v.is_finite())
            .fold(0.0f32, f32::max);
        assert!(input_max > 0.0, "frame {}: black input", res.index);
        for name in ["taa", "svgf"] {
            for (i, p) in image(name).iter().enumerate() {
                for &v in &p[..3] {
                    assert!(
                        v.is_finite() && v >= 0.0 && v < 100.0 * input_max,
                        "{name} frame {} pixel {i}: {v} (input max {input_max})",
                        res.index
                    );
                }
            }
        }
    }
    drop(r);
    assert_validation_clean();
}

/// The surface features come from the surface pass where no method reads the guides and
/// from the guides' march where one does (`--aux` here): the two passes find the same
/// surface, so the features and what reprojects by them are bit-identical either way.
#[test]
fn the_guides_march_writes_the_surface_pass_features() {
    const FRAMES: u32 = 4;
    let run = |aux: bool| {
        let setup = builtin_setup("phantom/orbit", FRAMES, 24);
        let mut r = setup.renderer(context(), &["taa"]).expect("renderer");
        let request = FrameRequest {
            readback: true,
            features: true,
            aux,
            ..Default::default()
        };
        let mut frames = Vec::new();
        for f in 0..FRAMES {
            frames.extend(r.frame(&setup.frame_inputs(f), &request).expect("frame"));
        }
        frames.extend(r.flush().expect("flush"));
        drop(r);
        assert_validation_clean();
        frames
    };
    let (alone, fused) = (run(false), run(true));
    assert_eq!(
        (alone.len(), fused.len()),
        (FRAMES as usize, FRAMES as usize)
    );
    for (a, b) in alone.iter().zip(&fused) {
        let ran = |res: &dvr_engine::renderer::FrameResult, pass: &str| {
            res.timings.iter().any(|t| t.pass == pass)
        };
        assert!(ran(a, "surface_features") && !ran(a, "aux_features"));
        assert!(ran(b, "aux_features") && !ran(b, "surface_features"));
        let image = |res: &dvr_engine::renderer::FrameResult, name: &str| {
            res.images
                .iter()
                .find(|(n, _)| n == name)
                .unwrap_or_else(|| panic!("frame {}: no {name} readback", res.index))
                .1
                .clone()
        };
        let mut met = 0;
        for name in dvr_engine::renderer::FEATURE_IMAGES
            .iter()
            .copied()
            .chain(["taa"])
        {
            let (x, y) = (image(a, name), image(b, name));
            assert!(
                x.iter()
                    .zip(&y)
                    .all(|(p, q)| p.map(f32::to_bits) == q.map(f32::to_bits)),
                "frame {}: {name} differs between the two passes",
                a.index
            );
            if name == "features.position" {
                met = x.iter().filter(|p| p[3] > 0.0).count();
            }
        }
        assert!(
            met > 24 * 24 / 10,
            "frame {}: the rays met too little ({met})",
            a.index
        );
    }
}
