//! The adaptive shader's math (`shaders/reflect_adaptive.*`): glossy paths
//! accumulated pass by pass; a pixel traces one more path per pass until,
//! after `Params::adaptive_min` paths ([`ADAPTIVE_MIN`] by default), its
//! variance estimate is within the tolerance, or it has
//! `Params::adaptive_max` ([`ADAPTIVE_MAX`]).

use super::{glossy_sample, Params, PixelPath, Scene, Vec3};

pub const ADAPTIVE_MIN: u32 = 4;
pub const ADAPTIVE_MAX: u32 = 16;
/// The default variance tolerance (of the mean's luminance).
pub const ADAPTIVE_TOLERANCE: f32 = 1e-3;
/// Rec. 709 luminance weights.
pub const LUMINANCE: Vec3 = Vec3::new(0.2126, 0.7152, 0.0722);
/// The converged image's paths start at this sample number, so that they
/// share no random numbers with the adaptive ones (at most `0xFFFF`).
pub const CONVERGED_FIRST_SAMPLE: u32 = 1 << 16;

/// What the shader keeps per pixel between passes.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Accumulator {
    pub sum: Vec3,
    pub samples: u32,
    pub lum_sum: f32,
    pub lum_sq_sum: f32,
}

impl Accumulator {
    /// Whether the next pass traces another path: below the minimum, or
    /// below the maximum with the variance of the mean above the tolerance.
    pub fn wants_more(&self, params: &Params) -> bool {
        if self.samples < params.adaptive_min {
            return true;
        }
        if self.samples >= params.adaptive_max {
            return false;
        }
        let n = self.samples as f32;
        let mean = self.lum_sum / n;
        let variance = (self.lum_sq_sum / n - mean * mean).max(0.0);
        variance / n > params.tolerance
    }

    pub fn add(&mut self, c: Vec3) {
        let l = c.dot(LUMINANCE);
        self.sum += c;
        self.samples += 1;
        self.lum_sum += l;
        self.lum_sq_sum += l * l;
    }

    pub fn mean(&self) -> Vec3 {
        self.sum / self.samples.max(1) as f32
    }
}

/// Pixel `(x, y)` through all passes: its mean colour with the paths traced.
pub fn trace_adaptive(scene: &Scene, params: &Params, x: u32, y: u32) -> (PixelPath, Accumulator) {
    let mut acc = Accumulator::default();
    let mut segments = Vec::new();
    while acc.wants_more(params) {
        let mut c = Vec3::ZERO;
        glossy_sample(scene, params, x, y, acc.samples, &mut c, &mut segments);
        acc.add(c);
    }
    (
        PixelPath {
            color: acc.mean(),
            segments,
        },
        acc,
    )
}

/// The mean of `count` glossy paths starting at sample number `first`, and
/// how many rays they traced: the fixed-count render and the converged one.
pub fn fixed(
    scene: &Scene,
    params: &Params,
    x: u32,
    y: u32,
    first: u32,
    count: u32,
) -> (Vec3, usize) {
    let mut sum = Vec3::ZERO;
    let mut segments = Vec::new();
    for s in first..first + count {
        let mut c = Vec3::ZERO;
        glossy_sample(scene, params, x, y, s, &mut c, &mut segments);
        sum += c;
    }
    (sum / count as f32, segments.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reference::Method;

    fn scene(name: &str) -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("shaders/scenes")
            .join(format!("{name}.toml"));
        Scene::load(&path).unwrap()
    }

    #[test]
    fn smooth_pixels_stop_at_the_minimum_and_noisy_ones_go_on() {
        // No rough surface: every path of a pixel is the same.
        let s = scene("mirror");
        let p = Params::for_scene(&s, 16, 16, 3);
        for i in 0..256 {
            let (_, acc) = trace_adaptive(&s, &p, i % 16, i / 16);
            assert_eq!(acc.samples, ADAPTIVE_MIN);
        }
        let s = scene("showcase");
        let p = Params::for_scene(&s, 32, 32, 3);
        let counts: Vec<u32> = (0..32 * 32)
            .map(|i| trace_adaptive(&s, &p, i % 32, i / 32).1.samples)
            .collect();
        let more = counts.iter().filter(|&&n| n > ADAPTIVE_MIN).count();
        let max = counts.iter().filter(|&&n| n == ADAPTIVE_MAX).count();
        eprintln!("more {more} max {max}");
        assert!(more > 20 && max > 0 && more < 32 * 32 / 2, "{more} {max}");
        assert!(counts
            .iter()
            .all(|&n| (ADAPTIVE_MIN..=ADAPTIVE_MAX).contains(&n)));
    }

    #[test]
    fn the_passes_bound_the_paths_per_pixel() {
        let s = scene("mirror");
        let mut p = Params::for_scene(&s, 8, 8, 3);
        p.adaptive_min = 2;
        p.adaptive_max = 8;
        assert_eq!(Method::Adaptive.passes(&p), 8);
        // Noise-free pixels stop at the minimum, whatever it is.
        assert_eq!(trace_adaptive(&s, &p, 3, 3).1.samples, 2);
        let s = scene("showcase");
        let mut p = Params::for_scene(&s, 32, 32, 3);
        p.tolerance = 0.0;
        let counts = |p: &Params| -> Vec<u32> {
            (0..32 * 32)
                .map(|i| trace_adaptive(&s, p, i % 32, i / 32).1.samples)
                .collect()
        };
        for (min, max) in [(2, 8), (4, 32)] {
            p.adaptive_min = min;
            p.adaptive_max = max;
            let counts = counts(&p);
            assert!(counts.iter().all(|&n| (min..=max).contains(&n)));
            // A tolerance of 0 sends every noisy pixel to the maximum.
            assert!(counts.contains(&max), "{min} {max}");
        }
        // One path has no variance to estimate: a minimum of 1 stops every
        // pixel there, whatever the tolerance.
        p.adaptive_min = 1;
        assert!(counts(&p).iter().all(|&n| n == 1));
    }
}
