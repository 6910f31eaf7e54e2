//! What the multi-pass shaders measure beyond the image: the hybrid
//! shader's reflection paths (screen space or ray) and the adaptive
//! shader's paths per pixel, against a fixed-count render and a converged one.

use crate::reference::adaptive::{self, CONVERGED_FIRST_SAMPLE};
use crate::reference::hybrid::{self, ReflectionPath};
use crate::reference::{self, pack_rgba8, Method, Params, PixelPath, Scene, Vec3};
use rayon::prelude::*;

/// Paths of the converged image per pixel (independent of the adaptive
/// ones).
pub const CONVERGED_PATHS: u32 = 64;

/// What the CPU renders for a case.
pub struct CpuRender {
    pub image: Vec<u32>,
    /// Each pixel's edge margin ([`reference::Segment::edge_margin`]).
    pub margins: Vec<f32>,
    /// The per-pixel counts a multi-pass shader writes (hybrid:
    /// [`ReflectionPath`] codes; adaptive: paths traced).
    pub counts: Option<Vec<u32>>,
    /// Adaptive sampling against fixed passes and a converged image.
    pub adaptive: Option<AdaptiveStats>,
}

/// The adaptive render's rays and error next to the fixed-count render's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AdaptiveStats {
    /// The most paths per pixel: the fixed-count render traces this many.
    pub max_paths: u32,
    pub rays: usize,
    pub fixed_rays: usize,
    /// Root mean square difference per channel against the converged image.
    pub rmse: f64,
    pub fixed_rmse: f64,
}

/// Renders `method`'s image on the CPU, rows in parallel.
pub fn cpu_render(scene: &Scene, params: &Params, method: Method) -> CpuRender {
    match method {
        Method::Hybrid => {
            let (paths, kinds) = hybrid::render(scene, params);
            CpuRender {
                image: paths.iter().map(|p| pack_rgba8(p.color)).collect(),
                margins: paths.iter().map(PixelPath::edge_margin).collect(),
                counts: Some(kinds.iter().map(|&k| k as u32).collect()),
                adaptive: None,
            }
        }
        Method::Adaptive => {
            let pixels: Vec<(u32, u32)> = (0..params.height)
                .flat_map(|y| (0..params.width).map(move |x| (x, y)))
                .collect();
            // Per pixel: the adaptive path, the maximum's fixed paths, the converged
            // paths (sample numbers of their own).
            let per_pixel: Vec<_> = pixels
                .par_iter()
                .map(|&(x, y)| {
                    let (path, acc) = adaptive::trace_adaptive(scene, params, x, y);
                    let (fixed, fixed_rays) =
                        adaptive::fixed(scene, params, x, y, 0, params.adaptive_max);
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
                    let errors = (sq(path.color), sq(fixed));
                    (path, acc, fixed_rays, errors.0, errors.1)
                })
                .collect();
            let n = per_pixel.len().max(1) as f64;
            let mut stats = AdaptiveStats {
                max_paths: params.adaptive_max,
                ..AdaptiveStats::default()
            };
            let (mut e, mut f) = (0.0, 0.0);
            for (path, _, fixed_rays, ea, ef) in &per_pixel {
                stats.rays += path.segments.len();
                stats.fixed_rays += fixed_rays;
                e += ea;
                f += ef;
            }
            stats.rmse = (e / n).sqrt();
            stats.fixed_rmse = (f / n).sqrt();
            CpuRender {
                image: per_pixel.iter().map(|p| pack_rgba8(p.0.color)).collect(),
                margins: per_pixel.iter().map(|p| p.0.edge_margin()).collect(),
                counts: Some(per_pixel.iter().map(|p| p.1.samples).collect()),
                adaptive: Some(stats),
            }
        }
        _ => {
            let (image, margins) = reference::render(scene, params, method);
            CpuRender {
                image,
                margins,
                counts: None,
                adaptive: None,
            }
        }
    }
}

/// A multi-pass case's measurements, in words, and a picture of its counts.
pub struct Measured {
    /// Ends with the picture's legend ([`HYBRID_LEGEND`], [`ADAPTIVE_LEGEND`]).
    pub note: String,
    /// RGBA8: hybrid: [`HYBRID_COLOURS`]; adaptive: brighter for more paths.
    pub picture: Option<Vec<u32>>,
}

/// The hybrid shader's `CASE-paths.png`: each reflection path's colour
/// (RGBA8 packed little-endian: red in the low byte).
pub const HYBRID_COLOURS: [(ReflectionPath, u32); 3] = [
    (ReflectionPath::None, 0xFF40_4040),
    (ReflectionPath::Screen, 0xFF00_C000),
    (ReflectionPath::Ray, 0xFF00_00E0),
];

/// The legends the notes end with (and docs/verify.md quotes).
pub const HYBRID_LEGEND: &str =
    "paths.png: grey no reflection, green found on screen, red traced a ray";
pub const ADAPTIVE_LEGEND: &str =
    "paths.png: grey level = paths traced, black none, white the most";

/// `gpu` holds the GPU's per-pixel counts; `differ` how many disagree with
/// the CPU's.
pub fn measure(cpu: &CpuRender, gpu: &[u32], differ: usize) -> Measured {
    let pixels = gpu.len().max(1);
    if let Some(stats) = cpu.adaptive {
        // Rays: the CPU's paths for the same counts (they agree with the
        // GPU's but for `differ` pixels); errors in linear colour.
        let traced: u64 = gpu.iter().map(|&n| u64::from(n)).sum();
        let max = stats.max_paths.max(1);
        let full = u64::from(max) * pixels as u64;
        let picture = gpu
            .iter()
            .map(|&n| {
                let v = (n.min(max) * 255 / max) & 0xFF;
                v | v << 8 | v << 16 | 0xFF00_0000
            })
            .collect();
        return Measured {
            note: format!(
                "{traced} paths instead of {full} for {max} fixed passes ({:.1} % saved; \
                 rays {} instead of {}, {:.1} % saved); RMSE against {CONVERGED_PATHS} \
                 independent paths: adaptive {:.4}, fixed {max} {:.4}; counts differ from the CPU's on {differ} \
                 ({ADAPTIVE_LEGEND})",
                100.0 * (1.0 - traced as f64 / full as f64),
                stats.rays,
                stats.fixed_rays,
                100.0 * (1.0 - stats.rays as f64 / stats.fixed_rays.max(1) as f64),
                stats.rmse,
                stats.fixed_rmse,
            ),
            picture: Some(picture),
        };
    }
    let count = |k: ReflectionPath| gpu.iter().filter(|&&c| c == k as u32).count();
    let (screen, ray) = (count(ReflectionPath::Screen), count(ReflectionPath::Ray));
    let reflecting = (screen + ray).max(1);
    let picture = gpu
        .iter()
        .map(|&c| {
            HYBRID_COLOURS
                .iter()
                .find(|(k, _)| *k as u32 == c)
                .map_or(HYBRID_COLOURS[0].1, |(_, colour)| *colour)
        })
        .collect();
    Measured {
        note: format!(
            "{ray} of {} reflecting pixels traced a ray ({:.1} %; {:.1} % of all {pixels}), \
             {screen} found their reflection on screen; paths differ from the CPU's on {differ} \
             ({HYBRID_LEGEND})",
            screen + ray,
            100.0 * ray as f64 / reflecting as f64,
            100.0 * ray as f64 / pixels as f64,
        ),
        picture: Some(picture),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The legend says each colour the picture uses, by the channel that
    /// dominates it, and docs/verify.md quotes both legends.
    #[test]
    fn the_path_pictures_have_their_legend() {
        for (path, colour) in HYBRID_COLOURS {
            let [r, g, b, _] = colour.to_le_bytes().map(u32::from);
            let word = if r > 2 * g.max(b) {
                "red"
            } else if g > 2 * r.max(b) {
                "green"
            } else {
                "grey"
            };
            let meaning = match path {
                ReflectionPath::None => "no reflection",
                ReflectionPath::Screen => "found on screen",
                ReflectionPath::Ray => "traced a ray",
            };
            assert!(
                HYBRID_LEGEND.contains(&format!("{word} {meaning}")),
                "{word} {meaning}"
            );
        }
        let docs = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/verify.md"))
            .unwrap()
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        assert!(docs.contains(HYBRID_LEGEND) && docs.contains(ADAPTIVE_LEGEND));
        let m = measure(
            &CpuRender {
                image: Vec::new(),
                margins: Vec::new(),
                counts: None,
                adaptive: None,
            },
            &[0, 1, 2],
            0,
        );
        assert!(
            m.note.ends_with(&format!("({HYBRID_LEGEND})")),
            "{}",
            m.note
        );
    }
}
