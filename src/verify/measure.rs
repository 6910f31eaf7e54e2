//! What the multi-pass shaders measure beyond the image: the hybrid
//! shader's reflection paths (screen space or ray) and the adaptive
//! shader's paths per pixel, against a fixed-count render and a converged one.

use crate::reference::adaptive::{self, ADAPTIVE_MAX, CONVERGED_FIRST_SAMPLE};
use crate::reference::hybrid::{self, ReflectionPath};
use crate::reference::{self, pack_rgba8, Method, Params, PixelPath, Scene, Vec3};

/// Paths of the converged image per pixel (independent of the first
/// [`ADAPTIVE_MAX`]).
pub const CONVERGED_PATHS: u32 = 64;

/// The CPU image, its edge margins, and the per-pixel counts a multi-pass
/// shader writes (hybrid: [`ReflectionPath`] codes; adaptive: paths traced).
pub fn cpu_render(
    scene: &Scene,
    params: &Params,
    method: Method,
) -> (Vec<u32>, Vec<f32>, Option<Vec<u32>>) {
    match method {
        Method::Hybrid => {
            let (paths, kinds) = hybrid::render(scene, params);
            (
                paths.iter().map(|p| pack_rgba8(p.color)).collect(),
                paths.iter().map(PixelPath::edge_margin).collect(),
                Some(kinds.iter().map(|&k| k as u32).collect()),
            )
        }
        Method::Adaptive => {
            let (mut image, mut margins, mut counts) = (Vec::new(), Vec::new(), Vec::new());
            for y in 0..params.height {
                for x in 0..params.width {
                    let (path, acc) = adaptive::trace_adaptive(scene, params, x, y);
                    image.push(pack_rgba8(path.color));
                    margins.push(path.edge_margin());
                    counts.push(acc.samples);
                }
            }
            (image, margins, Some(counts))
        }
        _ => {
            let (image, margins) = reference::render(scene, params, method);
            (image, margins, None)
        }
    }
}

/// A multi-pass case's measurements, in words, and a picture of its counts.
pub struct Measured {
    pub note: String,
    /// RGBA8: hybrid: grey none, green screen space, red ray; adaptive:
    /// brighter for more paths.
    pub picture: Option<Vec<u32>>,
}

/// `gpu` holds the GPU's per-pixel counts; `differ` how many disagree with
/// the CPU's.
pub fn measure(
    method: Method,
    scene: &Scene,
    params: &Params,
    gpu: &[u32],
    differ: usize,
) -> Measured {
    let pixels = gpu.len().max(1);
    match method {
        Method::Hybrid => {
            let count = |k: ReflectionPath| gpu.iter().filter(|&&c| c == k as u32).count();
            let (screen, ray) = (count(ReflectionPath::Screen), count(ReflectionPath::Ray));
            let reflecting = (screen + ray).max(1);
            let picture = gpu
                .iter()
                .map(|&c| match c {
                    1 => 0xFF00_C000,
                    2 => 0xFF00_00E0,
                    _ => 0xFF40_4040,
                })
                .collect();
            Measured {
                note: format!(
                    "{ray} of {} reflecting pixels traced a ray ({:.1} %; {:.1} % of all {pixels}), \
                     {screen} found their reflection on screen; paths differ from the CPU's on {differ}",
                    screen + ray,
                    100.0 * ray as f64 / reflecting as f64,
                    100.0 * ray as f64 / pixels as f64,
                ),
                picture: Some(picture),
            }
        }
        Method::Adaptive => {
            // Rays: the CPU's paths for the same counts (they agree with the
            // GPU's but for `differ` pixels); errors in linear colour.
            let (mut rays, mut fixed_rays) = (0usize, 0usize);
            let (mut err_adaptive, mut err_fixed) = (0f64, 0f64);
            for y in 0..params.height {
                for x in 0..params.width {
                    let (path, _) = adaptive::trace_adaptive(scene, params, x, y);
                    rays += path.segments.len();
                    let (fixed, n) = adaptive::fixed(scene, params, x, y, 0, ADAPTIVE_MAX);
                    fixed_rays += n;
                    let (converged, _) = adaptive::fixed(
                        scene,
                        params,
                        x,
                        y,
                        CONVERGED_FIRST_SAMPLE,
                        CONVERGED_PATHS,
                    );
                    let sq = |c: Vec3| {
                        let d = c - converged;
                        f64::from(d.dot(d)) / 3.0
                    };
                    err_adaptive += sq(path.color);
                    err_fixed += sq(fixed);
                }
            }
            let traced: u64 = gpu.iter().map(|&n| u64::from(n)).sum();
            let full = u64::from(ADAPTIVE_MAX) * pixels as u64;
            let picture = gpu
                .iter()
                .map(|&n| {
                    let v = (n.min(ADAPTIVE_MAX) * 255 / ADAPTIVE_MAX) & 0xFF;
                    v | v << 8 | v << 16 | 0xFF00_0000
                })
                .collect();
            Measured {
                note: format!(
                    "{traced} paths instead of {full} for {ADAPTIVE_MAX} fixed passes ({:.1} % saved; \
                     rays {rays} instead of {fixed_rays}, {:.1} % saved); RMSE against {CONVERGED_PATHS} \
                     independent paths: adaptive {:.4}, fixed {ADAPTIVE_MAX} {:.4}; counts differ from the CPU's on {differ}",
                    100.0 * (1.0 - traced as f64 / full as f64),
                    100.0 * (1.0 - rays as f64 / fixed_rays.max(1) as f64),
                    (err_adaptive / pixels as f64).sqrt(),
                    (err_fixed / pixels as f64).sqrt(),
                ),
                picture: Some(picture),
            }
        }
        _ => Measured {
            note: String::new(),
            picture: None,
        },
    }
}
