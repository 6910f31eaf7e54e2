//! Per-pixel comparison of two RGBA8 images, and the PNGs written when a
//! case fails.

use crate::reference::unpack_rgba8;
use std::path::Path;

/// A pixel whose CPU path passes closer than this (world units) to an open
/// triangle edge may be a hit on one implementation and a miss on the other:
/// the CPU uses Möller–Trumbore, drivers their own watertight test, and they
/// differ by a few ulps of the coordinates. Such pixels are counted; they
/// are not excused from the tolerance.
pub const EDGE_EPSILON: f32 = 1e-4;

/// How a GPU image compares with the CPU reference (RGB channels).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Comparison {
    pub pixels: usize,
    /// Largest difference of one channel, in 8-bit steps.
    pub max_diff: u8,
    /// Mean absolute difference per channel, in 8-bit steps.
    pub mean_diff: f64,
    /// Pixels with a channel differing by more than the tolerance.
    pub above: usize,
    /// Pixels whose path passes within [`EDGE_EPSILON`] of an open edge.
    pub near_edge: usize,
    /// Peak signal-to-noise ratio in dB (infinite for identical images).
    pub psnr: f64,
}

impl Comparison {
    /// Within `tolerance` on at least 99.9 % of the pixels.
    pub fn passes(&self) -> bool {
        self.above * 1000 <= self.pixels
    }
}

/// Compares `gpu` with `cpu`; `margins` (one per pixel, may be empty) are
/// the CPU paths' edge margins.
pub fn compare(gpu: &[u32], cpu: &[u32], margins: &[f32], tolerance: u8) -> Comparison {
    let mut c = Comparison {
        pixels: gpu.len().min(cpu.len()),
        ..Comparison::default()
    };
    let (mut sum, mut sq) = (0u64, 0u64);
    for (i, (&g, &r)) in gpu.iter().zip(cpu).enumerate() {
        let (g, r) = (unpack_rgba8(g), unpack_rgba8(r));
        let mut worst = 0u8;
        for k in 0..3 {
            let d = g[k].abs_diff(r[k]);
            worst = worst.max(d);
            sum += u64::from(d);
            sq += u64::from(d) * u64::from(d);
        }
        c.max_diff = c.max_diff.max(worst);
        c.above += usize::from(worst > tolerance);
        c.near_edge += usize::from(margins.get(i).is_some_and(|&m| m < EDGE_EPSILON));
    }
    let n = (c.pixels * 3).max(1) as f64;
    c.mean_diff = sum as f64 / n;
    let mse = sq as f64 / n;
    c.psnr = if mse == 0.0 {
        f64::INFINITY
    } else {
        10.0 * (255.0 * 255.0 / mse).log10()
    };
    c
}

/// Writes a packed RGBA8 image as a PNG.
pub fn write_png(path: &Path, image: &[u32], width: u32, height: u32) -> Result<(), String> {
    let file =
        std::fs::File::create(path).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), width, height);
    encoder.set_color(png::ColorType::Rgba);
    encoder.set_depth(png::BitDepth::Eight);
    let bytes: Vec<u8> = image.iter().flat_map(|&p| unpack_rgba8(p)).collect();
    encoder
        .write_header()
        .and_then(|mut w| w.write_image_data(&bytes))
        .map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// The per-channel difference, scaled by 32 so one 8-bit step shows.
pub fn difference(a: &[u32], b: &[u32]) -> Vec<u32> {
    a.iter()
        .zip(b)
        .map(|(&a, &b)| {
            let (a, b) = (unpack_rgba8(a), unpack_rgba8(b));
            let d = |k: usize| (u32::from(a[k].abs_diff(b[k])) * 32).min(255);
            d(0) | (d(1) << 8) | (d(2) << 16) | (255 << 24)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_a_small_difference() {
        let a = vec![0xFF00_0000u32; 1000];
        let mut b = a.clone();
        b[3] = 0xFF00_0001; // red one step up
        b[7] = 0xFF00_0300; // green three steps up
        let c = compare(&a, &b, &[], 1);
        assert_eq!((c.max_diff, c.above, c.pixels), (3, 1, 1000));
        assert!((c.mean_diff - 4.0 / 3000.0).abs() < 1e-12);
        assert!(c.psnr > 60.0 && c.psnr.is_finite());
        assert!(c.passes(), "1 pixel in 1000 is within the 99.9 % target");
        b[8] = 0xFF00_0300;
        assert!(!compare(&a, &b, &[], 1).passes());
        assert_eq!(compare(&a, &a, &[], 0).psnr, f64::INFINITY);
    }

    #[test]
    fn pngs_are_written() {
        let dir = std::env::temp_dir().join(format!("rtlint-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("x.png");
        write_png(&path, &[0xFF00_00FF; 6], 3, 2).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
