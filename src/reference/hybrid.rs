//! The hybrid shader's math (`shaders/reflect_hybrid.*`): a G-buffer pass
//! of primary rays, then screen-space reflections marched over its depth
//! with a thickness test and a confidence value; pixels whose march misses,
//! leaves the screen or has low confidence trace one reflection ray.

use std::cmp::Ordering;

use super::{camera_dir, record, reflect, shade, sky, Params, PixelPath, Scene, Segment, Vec3};

/// March steps, each this far along the reflection (world units).
pub const SSR_STEPS: u32 = 64;
pub const SSR_STEP: f32 = 0.1;
/// A step counts as a hit when it is behind the depth buffer by less than this.
pub const SSR_THICKNESS: f32 = 0.25;
/// Hits with less confidence fall back to a ray.
pub const SSR_MIN_CONFIDENCE: f32 = 0.5;

/// How a pixel got its reflection (the shader's `paths` buffer).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReflectionPath {
    /// Sky, or a surface that does not reflect: nothing to trace.
    None = 0,
    /// Found in the G-buffer by the screen-space march.
    Screen = 1,
    /// The march failed: one traced ray.
    Ray = 2,
}

/// One texel of the G-buffer (the shader's 64-byte `GTexel`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GTexel {
    /// Where the primary ray hit.
    pub position: Vec3,
    /// View-space depth (distance in front of the camera along −z);
    /// negative where the primary ray missed.
    pub depth: f32,
    /// The geometric normal facing the camera.
    pub normal: Vec3,
    pub reflectivity: f32,
    /// The primary hit's own light (shadow ray included); the sky on a miss.
    pub local: Vec3,
    pub roughness: f32,
    pub albedo: Vec3,
}

/// The first pass for pixel `(x, y)`, its rays appended to `segments`.
pub fn gbuffer_texel(
    scene: &Scene,
    params: &Params,
    x: u32,
    y: u32,
    segments: &mut Vec<Segment>,
) -> GTexel {
    let origin = params.camera;
    let dir = camera_dir(params, x, y);
    let hit = record(
        scene,
        origin,
        dir,
        params.t_min,
        params.t_max,
        false,
        segments,
    );
    let Some(hit) = hit else {
        return GTexel {
            position: Vec3::ZERO,
            depth: -1.0,
            normal: Vec3::ZERO,
            reflectivity: 0.0,
            local: sky(dir),
            roughness: 0.0,
            albedo: Vec3::ZERO,
        };
    };
    let surface = scene.surfaces[hit.triangle as usize];
    let position = origin + dir * hit.t;
    let s = shade(scene, params, origin, dir, hit, None, segments);
    GTexel {
        position,
        depth: -(position - params.camera).z,
        normal: s.normal,
        reflectivity: s.reflectivity,
        local: s.local,
        roughness: surface.roughness,
        albedo: surface.albedo,
    }
}

/// The whole first pass, row by row.
pub fn gbuffer(scene: &Scene, params: &Params) -> Vec<GTexel> {
    let mut scratch = Vec::new();
    (0..params.height)
        .flat_map(|y| (0..params.width).map(move |x| (x, y)))
        .map(|(x, y)| {
            scratch.clear();
            gbuffer_texel(scene, params, x, y, &mut scratch)
        })
        .collect()
}

/// The screen-space march from texel `g` along `r`: the light of the texel
/// it finds, or `None` when it misses, leaves the screen or is not confident.
pub fn march(params: &Params, gbuf: &[GTexel], g: &GTexel, r: Vec3) -> Option<Vec3> {
    let (w, h) = (params.width as f32, params.height as f32);
    for i in 1..=SSR_STEPS {
        let q = g.position + r * (i as f32 * SSR_STEP);
        let rel = q - params.camera;
        let z = -rel.z;
        // Behind the camera: off the screen.
        if z.partial_cmp(&1e-3) != Some(Ordering::Greater) {
            return None;
        }
        // The camera's projection: direction (u, -v, -1.5) through pixel
        // ((u + 1) / 2 · width, (v + 1) / 2 · height).
        let u = 1.5 * rel.x / z;
        let v = -1.5 * rel.y / z;
        let px = (u + 1.0) * 0.5 * w;
        let py = (v + 1.0) * 0.5 * h;
        if !(px >= 0.0 && px < w && py >= 0.0 && py < h) {
            return None;
        }
        let t = &gbuf[(py as u32 * params.width + px as u32) as usize];
        if t.depth < 0.0 {
            continue;
        }
        let behind = z - t.depth;
        if behind > 0.0 && behind < SSR_THICKNESS {
            // Confidence: fades towards the screen's edge and for surfaces
            // the ray meets from behind or edge-on.
            let edge = ((1.0 - u.abs().max(v.abs())) * 8.0).clamp(0.0, 1.0);
            let facing = (t.normal.dot(-r) * 4.0).clamp(0.0, 1.0);
            return (edge.min(facing) >= SSR_MIN_CONFIDENCE).then_some(t.local);
        }
    }
    None
}

/// The second pass for pixel `(x, y)`: its colour, how it got its
/// reflection, and the fallback ray (if any) in the path.
pub fn resolve(
    scene: &Scene,
    params: &Params,
    gbuf: &[GTexel],
    x: u32,
    y: u32,
    segments: &mut Vec<Segment>,
) -> (Vec3, ReflectionPath) {
    let g = &gbuf[(y * params.width + x) as usize];
    // The shader's `!(reflectivity > cutoff)`: NaN does not reflect either.
    if g.depth < 0.0 || g.reflectivity.partial_cmp(&params.cutoff) != Some(Ordering::Greater) {
        return (g.local, ReflectionPath::None);
    }
    let r = reflect(camera_dir(params, x, y), g.normal);
    if !params.ray_only {
        if let Some(found) = march(params, gbuf, g, r) {
            return (g.local + g.reflectivity * found, ReflectionPath::Screen);
        }
    }
    let from = params.next_origin(g.position, g.normal);
    let hit = record(scene, from, r, params.t_min, params.t_max, false, segments);
    let reflected = match hit {
        None => sky(r),
        Some(hit) => shade(scene, params, from, r, hit, None, segments).local,
    };
    (g.local + g.reflectivity * reflected, ReflectionPath::Ray)
}

/// Pixel `(x, y)` on its own (the G-buffer is rendered for it: slow; the
/// image goes through [`render`]).
pub fn trace_hybrid(scene: &Scene, params: &Params, x: u32, y: u32) -> PixelPath {
    let gbuf = gbuffer(scene, params);
    let mut segments = Vec::new();
    gbuffer_texel(scene, params, x, y, &mut segments);
    let (color, _) = resolve(scene, params, &gbuf, x, y, &mut segments);
    PixelPath { color, segments }
}

/// Both passes over the image: every pixel's path (colour and rays) and how
/// it got its reflection.
pub fn render(scene: &Scene, params: &Params) -> (Vec<PixelPath>, Vec<ReflectionPath>) {
    let mut paths = Vec::new();
    let mut texels = Vec::new();
    for y in 0..params.height {
        for x in 0..params.width {
            let mut segments = Vec::new();
            texels.push(gbuffer_texel(scene, params, x, y, &mut segments));
            paths.push(PixelPath {
                color: Vec3::ZERO,
                segments,
            });
        }
    }
    let mut kinds = Vec::with_capacity(paths.len());
    for y in 0..params.height {
        for x in 0..params.width {
            let path = &mut paths[(y * params.width + x) as usize];
            let (color, kind) = resolve(scene, params, &texels, x, y, &mut path.segments);
            path.color = color;
            kinds.push(kind);
        }
    }
    (paths, kinds)
}

#[cfg(test)]
mod tests {
    use super::super::intersect;
    use super::*;

    fn scene(name: &str) -> Scene {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("shaders/scenes")
            .join(format!("{name}.toml"));
        Scene::load(&path).unwrap()
    }

    #[test]
    fn screen_space_hits_agree_with_the_traced_ray_and_misses_fall_back() {
        let s = scene("showcase");
        let p = Params::for_scene(&s, 64, 64, 1);
        let (paths, kinds) = render(&s, &p);
        let count = |k| kinds.iter().filter(|&&x| x == k).count();
        let (none, screen, ray) = (
            count(ReflectionPath::None),
            count(ReflectionPath::Screen),
            count(ReflectionPath::Ray),
        );
        eprintln!("none {none} screen {screen} ray {ray}");
        assert!(
            none > 200 && screen > 100 && ray > 100,
            "{none} {screen} {ray}"
        );
        // Where the march found a texel, the ray it saved mostly sees the
        // same surface's light: the colours stay close.
        let gbuf = gbuffer(&s, &p);
        let mut close = 0;
        for (i, k) in kinds.iter().enumerate() {
            if *k != ReflectionPath::Screen {
                continue;
            }
            let (x, y) = (i as u32 % p.width, i as u32 / p.width);
            let g = &gbuf[i];
            let r = reflect(camera_dir(&p, x, y), g.normal);
            let from = p.next_origin(g.position, g.normal);
            let mut seg = Vec::new();
            let traced = match intersect(&s, from, r, p.t_min, p.t_max).0 {
                None => sky(r),
                Some(h) => shade(&s, &p, from, r, h, None, &mut seg).local,
            };
            let screen_color = (paths[i].color - g.local) / g.reflectivity;
            close += usize::from((screen_color - traced).abs().max_element() < 0.1);
        }
        assert!(close * 10 >= screen * 8, "{close} of {screen}");
    }
}
