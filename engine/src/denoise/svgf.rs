//! `svgf`: Spatiotemporal Variance-Guided Filtering (Schied et al. 2017), with the shared
//! reprojection (include/reproject.glsl) in place of the paper's, as the TVCG paper did.
//!
//! Passes (shaders of the same names, maths shared in include/svgf.glsl):
//! - `svgf.temporal`: demodulate the noisy colour by the TF albedo (+ `demod_eps`),
//!   blend it and its luminance moments with the reprojected histories (α = 0.2, or 1/n
//!   for a history of n < 5 frames), and pack the edge-stopping features.
//! - `svgf.variance`: variance from the moments; a 7×7 depth/normal-weighted spatial
//!   estimate where the history is shorter than 4 frames.
//! - `svgf.atrous0..4`: 5×5 B3-spline à-trous with steps 1…16 and depth/normal/luminance
//!   edge-stopping; the luminance scale uses the 3×3-prefiltered variance, and variance
//!   is carried with squared weights. Iteration 0 writes the colour history; the last
//!   multiplies the albedo back in.
//!
//! Images: histories `svgf.color` (first iteration's output, demodulated rgb + variance)
//! and `svgf.moments` (m1, m2, history length); transients `svgf.geometry` (packed
//! features), `svgf.ping`/`svgf.pong` (temporal → ping, variance → pong, then the
//! iterations alternate) and the output `svgf.out`.
//!
//! Invalid features (no surface: background, rays that never reach the opacity
//! threshold) are filtered too: among themselves with depth/normal weight 1, never with
//! valid pixels (weight 0), and they are not demodulated (factor 1).
//!
//! The depth weight's gradient is floored at the surface features' depth quantum (their
//! march step, `STEP_VOXELS` voxels): that depth is terraced, and a one-step jump between
//! terraces must not read as an edge. Histories are not reset when the camera, lights or
//! transfer function change: reprojection follows motion, and shading changes are
//! followed at the moving averages' rate (the method's known lag).

use super::{Built, DenoiseFrame, Denoiser, DenoiserConfig, MotionSource, Overridable, Tunables};
use crate::error::Result;
use crate::gpu::{GpuContext, Pipeline, SpecValue};
use crate::gpu_block;
use crate::graph::ImageHandle;
use crate::passes::surface_features::STEP_VOXELS;
use glam::Vec4;

gpu_block! {
    /// `SvgfTemporalPush` in svgf_temporal.comp.
    pub struct SvgfTemporalPush {
        pub camera: Vec4,
        pub width: u32,
        pub height: u32,
        pub history_valid: u32,
        pub tolerance: f32,
        pub color_alpha: f32,
        pub moments_alpha: f32,
        pub demod_eps: f32,
        pub feature_step: f32,
    }
}

gpu_block! {
    /// `SvgfVariancePush` in svgf_variance.comp.
    pub struct SvgfVariancePush {
        pub width: u32,
        pub height: u32,
        pub min_history: f32,
        pub sigma_z: f32,
        pub sigma_n: f32,
        pub pad0: f32,
        pub pad1: f32,
        pub pad2: f32,
    }
}

gpu_block! {
    /// `SvgfAtrousPush` in svgf_atrous.comp.
    pub struct SvgfAtrousPush {
        pub width: u32,
        pub height: u32,
        pub step: i32,
        pub modulate: u32,
        pub sigma_z: f32,
        pub sigma_n: f32,
        pub sigma_l: f32,
        pub luminance_eps: f32,
        pub demod_eps: f32,
        pub pad0: f32,
        pub pad1: f32,
        pub pad2: f32,
    }
}

/// The paper's parameters, and this implementation's few extra constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SvgfParams {
    /// Weight of the new frame in the colour average (α).
    pub color_alpha: f32,
    /// Weight of the new frame in the moments average.
    pub moments_alpha: f32,
    /// History length below which variance is estimated spatially.
    pub min_history: f32,
    pub sigma_z: f32,
    pub sigma_n: f32,
    pub sigma_l: f32,
    /// Added to σl·σ so a zero-variance neighbourhood does not divide by zero.
    pub luminance_eps: f32,
    /// Added to the albedo before demodulating: a black albedo channel amplifies the
    /// colour by at most 1/eps before filtering (and is multiplied back exactly).
    pub demod_eps: f32,
    /// Disocclusion tolerance in pixels (see [`super::REPROJECTION_TOLERANCE_PX`]).
    pub tolerance: f32,
    /// À-trous iterations (steps 1, 2, 4, …).
    pub iterations: u32,
    /// The iteration (0-based) whose output becomes the colour history.
    pub feedback: u32,
}

impl SvgfParams {
    /// The paper's parameters (a const, so tests of the edge-stopping mirror use them).
    pub const DEFAULT: Self = Self {
        color_alpha: 0.2,
        moments_alpha: 0.2,
        min_history: 4.0,
        sigma_z: 1.0,
        sigma_n: 128.0,
        sigma_l: 4.0,
        luminance_eps: 1e-6,
        demod_eps: 0.01,
        tolerance: super::REPROJECTION_TOLERANCE_PX,
        iterations: 5,
        feedback: 0,
    };
}

/// `DVR_SVGF="color_alpha=0.05,sigma_l=10"` sets parameters for a study with `dvr eval`.
impl Tunables for SvgfParams {
    const VARIABLE: &'static str = "DVR_SVGF";
    const TABLE: &'static [Overridable<Self>] = OVERRIDABLE;

    fn consistent(self) -> Result<Self> {
        if self.feedback + 1 >= self.iterations {
            return Err(crate::error::EngineError::InvalidSetting {
                name: Self::VARIABLE,
                value: format!("feedback={}, iterations={}", self.feedback, self.iterations),
                allowed: "a fed-back iteration before the last (feedback < iterations - 1)".into(),
            });
        }
        Ok(self)
    }
}

/// The parameters `DVR_SVGF` may set (for parameter studies with `dvr eval`), with the
/// range each takes.
const OVERRIDABLE: &[Overridable<SvgfParams>] = &[
    ("color_alpha", 0.0, 1.0, |p, v| p.color_alpha = v),
    ("moments_alpha", 0.0, 1.0, |p, v| p.moments_alpha = v),
    ("min_history", 1.0, 1e3, |p, v| p.min_history = v),
    ("sigma_z", 0.0, 1e3, |p, v| p.sigma_z = v),
    ("sigma_n", 0.0, 1e4, |p, v| p.sigma_n = v),
    ("sigma_l", 0.0, 1e3, |p, v| p.sigma_l = v),
    ("demod_eps", 1e-6, 1e6, |p, v| p.demod_eps = v),
    ("iterations", 1.0, 8.0, |p, v| p.iterations = v as u32),
    ("feedback", 0.0, 7.0, |p, v| p.feedback = v as u32),
];

impl Default for SvgfParams {
    fn default() -> Self {
        Self::DEFAULT
    }
}

pub struct Svgf {
    /// Its registry name, which also names its passes and images (`<name>.color`, …).
    name: &'static str,
    temporal: Pipeline<SvgfTemporalPush>,
    variance: Pipeline<SvgfVariancePush>,
    atrous: Pipeline<SvgfAtrousPush>,
    pub params: SvgfParams,
    /// 0: motion from the first real collision (the paper's, as `ours`), 1: from features.
    pub motion: MotionSource,
}

impl Svgf {
    pub fn create(ctx: &GpuContext, name: &'static str, config: &DenoiserConfig) -> Built {
        let motion = config.motion;
        let params = SvgfParams::from_env()?;
        Ok(Box::new(Self {
            name,
            temporal: ctx.pipeline(
                "svgf_temporal",
                &[("MOTION_SOURCE", SpecValue::I32(motion.spec()))],
            )?,
            variance: ctx.pipeline("svgf_variance", &[])?,
            atrous: ctx.pipeline(
                "svgf_atrous",
                &[("SHARED_TILES", SpecValue::Bool(ctx.shared_tiles))],
            )?,
            params,
            motion,
        }))
    }
}

impl Denoiser for Svgf {
    fn add<'f>(&'f self, mut f: DenoiseFrame<'_, 'f>) -> Result<ImageHandle> {
        let (ctx, graph, frame, input) = f.parts();
        let size = input.size;
        let desc = input.rgba32f();
        let n = self.name;
        let color = graph.history(ctx, &format!("{n}.color"), desc)?;
        let moments = graph.history(ctx, &format!("{n}.moments"), desc)?;
        let geometry = graph.image(ctx, &format!("{n}.geometry"), desc)?;
        let ping = graph.image(ctx, &format!("{n}.ping"), desc)?;
        let pong = graph.image(ctx, &format!("{n}.pong"), desc)?;
        let out = graph.image(ctx, &format!("{n}.out"), desc)?;
        let reproj = input.reprojection(self.name, self.motion)?;
        let valid = color.valid && moments.valid && reproj.valid;
        let p = self.params;
        let noisy = input.noisy;
        let features = input.features(self.name)?;
        let (albedo, normal, position) = (features.albedo, features.normal, features.position.cur);
        // Synthetic inputs without guides demodulate by the threshold surface's albedo.
        let demod = input.guides.unwrap_or(albedo);

        let push = SvgfTemporalPush {
            camera: input.camera.extend(1.0),
            width: size.width,
            height: size.height,
            history_valid: valid as u32,
            tolerance: p.tolerance,
            color_alpha: p.color_alpha,
            moments_alpha: p.moments_alpha,
            demod_eps: p.demod_eps,
            feature_step: STEP_VOXELS,
        };
        frame.add_compute(format!("{n}.temporal"), &self.temporal, push, size, |b| {
            reproj.bind(b);
            b.read("noisy", noisy)
                .read("feature_albedo", albedo)
                .read("feature_normal", normal)
                .read("feature_position", position)
                .read("demod_albedo", demod)
                .sampled("color_prev", color.prev)
                .sampled("moments_prev", moments.prev)
                .write("integrated", ping)
                .write("moments_cur", moments.cur)
                .write("geometry", geometry);
        });

        let vpush = SvgfVariancePush {
            width: size.width,
            height: size.height,
            min_history: p.min_history,
            sigma_z: p.sigma_z,
            sigma_n: p.sigma_n,
            pad0: 0.0,
            pad1: 0.0,
            pad2: 0.0,
        };
        frame.add_compute(format!("{n}.variance"), &self.variance, vpush, size, |b| {
            b.read("integrated", ping)
                .read("moments", moments.cur)
                .read("geometry", geometry)
                .write("estimated", pong);
        });

        // pong → … → out, the output of iteration `feedback` into the colour history
        // (with the paper's 5 and 0: pong → colour history → ping → pong → ping → out).
        let mut src = pong;
        for i in 0..p.iterations {
            let last = i + 1 == p.iterations;
            let dst = if last {
                out
            } else if i == p.feedback {
                color.cur
            } else if src == ping {
                pong
            } else {
                ping
            };
            let apush = SvgfAtrousPush {
                width: size.width,
                height: size.height,
                step: 1 << i,
                modulate: last as u32,
                sigma_z: p.sigma_z,
                sigma_n: p.sigma_n,
                sigma_l: p.sigma_l,
                luminance_eps: p.luminance_eps,
                demod_eps: p.demod_eps,
                pad0: 0.0,
                pad1: 0.0,
                pad2: 0.0,
            };
            let name = format!("{n}.atrous{i}");
            frame.add_compute(name, &self.atrous, apush, size, |b| {
                b.read("color_in", src)
                    .read("geometry", geometry)
                    .read("demod_albedo", demod)
                    .write("color_out", dst);
            });
            src = dst;
        }
        Ok(out)
    }
}

/// CPU mirror of the edge-stopping maths in shaders/glsl/include/svgf.glsl (the functions
/// marked `[mirror]` there), for tests and CPU references. The GLSL is what runs: CHANGE
/// BOTH TOGETHER. `tests/svgf.rs` compares a CPU filter built from these functions with
/// the GPU passes, so a one-sided change fails a test.
pub mod edge {
    use glam::Vec3;

    /// The 1D B3-spline kernel [1/16, 1/4, 3/8, 1/4, 1/16], indexed by |offset|.
    pub const B3: [f32; 3] = [3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0];

    /// `svgf_depth_slope`: the depth gradient floored at the features' depth quantum.
    pub fn depth_slope(gradient: f32, quantum: f32) -> f32 {
        gradient.max(quantum)
    }

    /// `svgf_phi_z`: depth scale for a tap `dist` pixels away.
    pub fn phi_z(sigma_z: f32, slope: f32, dist: f32) -> f32 {
        sigma_z * slope * dist
    }

    /// `svgf_phi_l`: luminance scale from the (prefiltered) variance.
    pub fn phi_l(sigma_l: f32, variance: f32, eps: f32) -> f32 {
        sigma_l * variance.max(0.0).sqrt() + eps
    }

    /// `z` of a pixel without a threshold surface whose ray meets nothing
    /// (`SVGF_BACKGROUND`) or still meets the medium (`SVGF_MEDIUM`).
    pub const BACKGROUND: f32 = -1.0;
    pub const MEDIUM: f32 = -2.0;

    /// `svgf_geometry_weight`: depth × normal weight between two surface pixels; the
    /// background mixes only with itself; the medium with the medium and with surfaces
    /// (weight 1).
    #[allow(clippy::too_many_arguments)]
    pub fn geometry_weight(
        valid_p: bool,
        valid_q: bool,
        z_p: f32,
        z_q: f32,
        phi_z: f32,
        n_p: Vec3,
        n_q: Vec3,
        sigma_n: f32,
    ) -> f32 {
        if !valid_p || !valid_q {
            return if (z_p == BACKGROUND) == (z_q == BACKGROUND) {
                1.0
            } else {
                0.0
            };
        }
        let w_n = n_p.dot(n_q).max(0.0).powf(sigma_n);
        let e_z = (z_p - z_q).abs() / phi_z.max(1e-20);
        (-e_z).exp() * w_n
    }

    /// `svgf_luminance_weight`.
    pub fn luminance_weight(l_p: f32, l_q: f32, phi_l: f32) -> f32 {
        (-(l_p - l_q).abs() / phi_l).exp()
    }

    /// `luminance` in include/common.glsl.
    pub fn luminance(c: [f32; 3]) -> f32 {
        0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
    }

    #[cfg(test)]
    mod tests {
        use super::*;
        use crate::denoise::svgf::SvgfParams;

        const P: SvgfParams = SvgfParams::DEFAULT;

        #[test]
        fn test_params_are_the_defaults() {
            assert_eq!(P, SvgfParams::default());
        }

        /// The full weight of a tap on the same flat surface, luminance `l_q` against
        /// `l_p`, with standard deviation `sigma` of luminance at the centre.
        fn flat_weight(l_p: f32, l_q: f32, sigma: f32) -> f32 {
            let z = 2.0;
            let phi = phi_z(P.sigma_z, 0.01, 1.0);
            geometry_weight(true, true, z, z, phi, Vec3::Z, Vec3::Z, P.sigma_n)
                * luminance_weight(l_p, l_q, phi_l(P.sigma_l, sigma * sigma, P.luminance_eps))
        }

        #[test]
        fn luminance_step_of_ten_edge_scales_stops_the_filter() {
            // A step of 10 σl·σ (ten luminance scales): weight e^-10.
            for sigma in [1e-3f32, 0.1, 1.0, 30.0] {
                let w = flat_weight(1.0, 1.0 + 10.0 * P.sigma_l * sigma, sigma);
                assert!(w < 1e-3, "σ {sigma}: weight {w}");
                let w_down = flat_weight(1.0 + 10.0 * P.sigma_l * sigma, 1.0, sigma);
                assert!(w_down < 1e-3, "σ {sigma}: weight {w_down}");
            }
        }

        #[test]
        fn luminance_step_of_ten_sigma_is_attenuated_per_iteration() {
            // A step of 10σ is 10/σl = 2.5 luminance scales: e^-2.5 ≈ 0.082 per iteration
            // with the paper's σl = 4 (the step has to be 4× larger to reach 1e-3).
            let sigma = 0.5;
            let w = flat_weight(1.0, 1.0 + 10.0 * sigma, sigma);
            assert!((w - (-2.5f32).exp()).abs() < 1e-4, "weight {w}");
            assert!(w < 0.1);
        }

        #[test]
        fn flat_region_keeps_weight_near_one() {
            // σ-normalised differences near 0 (|Δl| ≤ 0.1 σ) on the same surface.
            for sigma in [1e-3f32, 0.1, 1.0, 30.0] {
                for d in [0.0f32, 0.01, 0.05, 0.1] {
                    let w = flat_weight(1.0, 1.0 + d * sigma, sigma);
                    assert!(w > 0.9, "σ {sigma}, Δ {d}σ: weight {w}");
                }
            }
            // Depth that changes along the surface at its own gradient, a tap 2 px away.
            let (z, dz) = (2.0, 0.01);
            let phi = phi_z(P.sigma_z, dz, 2.0);
            let w = geometry_weight(true, true, z, z + 2.0 * dz, phi, Vec3::Z, Vec3::Z, 128.0);
            assert!((w - (-1.0f32).exp()).abs() < 1e-6, "depth weight {w}");
        }

        #[test]
        fn normal_weight() {
            let phi = phi_z(P.sigma_z, 0.01, 1.0);
            let w = |n: Vec3| geometry_weight(true, true, 1.0, 1.0, phi, Vec3::Z, n, P.sigma_n);
            assert_eq!(w(-Vec3::Z), 0.0, "opposite normals");
            assert_eq!(w(Vec3::X), 0.0, "perpendicular normals");
            assert!((w(Vec3::Z) - 1.0).abs() < 1e-6);
            // 10° apart: cos^128 ≈ 0.14; 2° apart: ≈ 0.92.
            let tilt = |deg: f32| Vec3::new(deg.to_radians().sin(), 0.0, deg.to_radians().cos());
            assert!(w(tilt(10.0)) < 0.2);
            assert!(w(tilt(2.0)) > 0.9);
        }

        #[test]
        fn depth_discontinuity_stops_the_filter() {
            let (z, quantum) = (2.0, 0.002);
            let phi = phi_z(P.sigma_z, depth_slope(0.002, quantum), 1.0);
            let w = geometry_weight(true, true, z, z + 0.1, phi, Vec3::Z, Vec3::Z, P.sigma_n);
            assert!(w < 1e-6, "weight {w}");
            // Inside a terrace (gradient 0) the quantum floor keeps a one-step jump from
            // cutting the surface apart: e^-1 for the next pixel, more further out.
            let slope = depth_slope(0.0, quantum);
            assert_eq!(slope, quantum);
            for dist in [1.0f32, 2.0, 4.0] {
                let phi = phi_z(P.sigma_z, slope, dist);
                let w = geometry_weight(true, true, z, z + quantum, phi, Vec3::Z, Vec3::Z, 128.0);
                // (z + quantum) − z is not exactly the quantum in f32.
                assert!(
                    (w - (-1.0 / dist).exp()).abs() < 1e-4,
                    "weight {w} at {dist} px"
                );
            }
        }

        #[test]
        fn background_mixes_only_with_itself_and_medium_with_all_but_background() {
            let phi = phi_z(P.sigma_z, 0.01, 1.0);
            let g = |vp, zp, vq, zq| geometry_weight(vp, vq, zp, zq, phi, Vec3::Z, Vec3::Z, 128.0);
            // Surface (z 1) and background.
            assert_eq!(g(true, 1.0, false, BACKGROUND), 0.0);
            assert_eq!(g(false, BACKGROUND, true, 1.0), 0.0);
            assert_eq!(g(false, BACKGROUND, false, BACKGROUND), 1.0);
            // Medium with surface and medium, not with background.
            assert_eq!(g(true, 1.0, false, MEDIUM), 1.0);
            assert_eq!(g(false, MEDIUM, true, 1.0), 1.0);
            assert_eq!(g(false, MEDIUM, false, MEDIUM), 1.0);
            assert_eq!(g(false, MEDIUM, false, BACKGROUND), 0.0);
        }

        #[test]
        fn zero_variance_does_not_divide_by_zero() {
            let phi = phi_l(P.sigma_l, 0.0, P.luminance_eps);
            assert!(phi > 0.0);
            assert_eq!(luminance_weight(0.5, 0.5, phi), 1.0);
            assert!(luminance_weight(0.5, 0.6, phi) < 1e-6);
            assert_eq!(phi_l(P.sigma_l, -1.0, P.luminance_eps), P.luminance_eps);
        }

        #[test]
        fn b3_kernel_sums_to_one() {
            let k = [B3[2], B3[1], B3[0], B3[1], B3[2]];
            let s1: f32 = k.iter().sum();
            assert!((s1 - 1.0).abs() < 1e-7);
            let s2: f32 = k.iter().flat_map(|a| k.iter().map(move |b| a * b)).sum();
            assert!((s2 - 1.0).abs() < 1e-6);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{SvgfParams, Tunables};

    #[test]
    fn overrides_are_named_range_checked_and_consistent() {
        let p = SvgfParams::default()
            .with_overrides(Some(
                "color_alpha=0.05, sigma_l=10, iterations=4, feedback=1",
            ))
            .expect("valid overrides");
        assert_eq!(
            (p.color_alpha, p.sigma_l, p.iterations, p.feedback),
            (0.05, 10.0, 4, 1)
        );
        crate::denoise::assert_overrides_refused(
            |spec| SvgfParams::default().with_overrides(spec),
            "DVR_SVGF",
            &[
                ("color_alpha=2", "color_alpha must be in"),
                ("iterations=0", "iterations must be in"),
                ("feedback=4", "before the last"),
                ("iterations=1", "before the last"),
                ("alpha=0.1", "parameters: color_alpha"),
            ],
        );
    }
}
