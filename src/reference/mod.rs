//! CPU reference renderer for the reflection reference shaders
//! (`shaders/reflect_iterative.*`, `shaders/reflect_recursive.*`), over
//! scenes described in data ([`scene`]).
//!
//! Everything is `f32` and follows the shaders operation by operation
//! (camera, bounce loop or recursion, shadow rays, sky, shading, robust ray
//! origins, packing) so that a GPU image should match to within one 8-bit
//! step; ray/triangle tests use the shaders' `t` range, and a cut-out
//! material's triangle counts only where its alpha texel keeps it (what the
//! any-hit shaders and the ray queries' candidate loops do). Triangles are found
//! through a BVH ([`bvh`]).

pub mod adaptive;
pub mod bvh;
pub mod hybrid;
pub mod math;
pub mod scene;

pub use adaptive::ADAPTIVE_TOLERANCE;
pub use glam::Vec3;
pub use math::{mix, offset_ray, reflect};
pub use scene::{Light, Scene, Surface};

/// `Params.flags`: the scene has a light (shadow rays are traced).
pub const FLAG_LIGHT: u32 = 1;
/// `Params.flags`: ray origins use the robust offset, not the fixed epsilon.
pub const FLAG_ROBUST: u32 = 2;
/// `Params.flags`: the hybrid shader traces every reflection, marching none.
pub const FLAG_RAY_ONLY: u32 = 4;

/// The shaders' uniform block (`Params`, 80 bytes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params {
    pub width: u32,
    pub height: u32,
    pub max_bounces: u32,
    /// Robust origins (Wächter & Binder) instead of `p + n · epsilon`.
    pub robust: bool,
    pub camera: Vec3,
    pub light: Option<Light>,
    pub t_min: f32,
    pub t_max: f32,
    /// A path goes on while its throughput is above this.
    pub cutoff: f32,
    /// The fixed offset along the normal when `robust` is off.
    pub epsilon: f32,
    /// Rays per pixel of the glossy shader (1–16).
    pub samples: u32,
    /// The adaptive shader's variance tolerance (`camera.w`).
    pub tolerance: f32,
    /// The adaptive shader's fewest and most paths per pixel (`knobs.w`:
    /// `min | max << 16`); it runs `adaptive_max` passes.
    pub adaptive_min: u32,
    pub adaptive_max: u32,
    /// `t_max` of the glossy shader's reflection rays (before its
    /// shortening with roughness); primary and shadow rays keep `t_max`.
    pub reflect_t_max: f32,
    /// The glossy shader replaces the reflection ray off a surface rougher
    /// than this with the environment in the sampled direction.
    pub rough_cutoff: f32,
    /// Half-resolution reflections: a pixel whose first hit is rougher than
    /// this (and as rough as its 2×2 block's top-left pixel's) takes that
    /// pixel's light beyond the first hit instead of tracing on. Off above 1.
    pub half_res: f32,
    /// The hybrid shader traces every reflection instead of marching the
    /// screen first.
    pub ray_only: bool,
}

impl Params {
    /// The defaults the reference shaders are verified with: robust origins
    /// with `t_min` 0, `t_max` 1e4, cut-off 1/256.
    pub fn for_scene(scene: &Scene, width: u32, height: u32, max_bounces: u32) -> Params {
        Params {
            width,
            height,
            max_bounces,
            robust: true,
            camera: scene.camera,
            light: scene.light,
            t_min: 0.0,
            t_max: 1e4,
            cutoff: 1.0 / 256.0,
            epsilon: 1e-3,
            samples: 4,
            tolerance: ADAPTIVE_TOLERANCE,
            adaptive_min: adaptive::ADAPTIVE_MIN,
            adaptive_max: adaptive::ADAPTIVE_MAX,
            reflect_t_max: 1e4,
            rough_cutoff: f32::INFINITY,
            half_res: f32::INFINITY,
            ray_only: false,
        }
    }

    /// The uniform buffer contents:
    /// `width, height, max_bounces, flags; camera.xyz, tolerance; light.xyz, ambient;
    /// t_min, t_max, cutoff, epsilon; reflect_t_max, rough_cutoff, half_res,
    /// adaptive_min | adaptive_max << 16`.
    pub fn to_words(&self) -> [u32; 20] {
        let f = |x: f32| x.to_bits();
        let flags = if self.light.is_some() { FLAG_LIGHT } else { 0 }
            | if self.robust { FLAG_ROBUST } else { 0 }
            | if self.ray_only { FLAG_RAY_ONLY } else { 0 }
            | (self.samples.min(255) << 8);
        let (l, ambient) = self
            .light
            .map(|l| (l.direction, l.ambient))
            .unwrap_or((Vec3::ZERO, 0.0));
        let c = self.camera;
        [
            self.width,
            self.height,
            self.max_bounces,
            flags,
            f(c.x),
            f(c.y),
            f(c.z),
            f(self.tolerance),
            f(l.x),
            f(l.y),
            f(l.z),
            f(ambient),
            f(self.t_min),
            f(self.t_max),
            f(self.cutoff),
            f(self.epsilon),
            f(self.reflect_t_max),
            f(self.rough_cutoff),
            f(self.half_res),
            (self.adaptive_min & 0xFFFF) | (self.adaptive_max.min(0xFFFF) << 16),
        ]
    }

    /// Where the next ray starts from the surface point `p` with normal `n`
    /// (facing the side the ray leaves from).
    pub fn next_origin(&self, p: Vec3, n: Vec3) -> Vec3 {
        if self.robust {
            offset_ray(p, n)
        } else {
            p + n * self.epsilon
        }
    }
}

/// The closest hit of a ray, as the closest-hit shader sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    /// The triangle's index in the scene: `instance_custom_index + primitive_index`.
    pub triangle: u32,
}

/// One traced ray of a pixel's path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub origin: Vec3,
    pub dir: Vec3,
    pub hit: Option<Hit>,
    /// A shadow ray (any hit ends it) rather than a primary or reflection ray.
    pub shadow: bool,
    /// World-space distance from where the ray crosses a triangle's plane
    /// (within the `t` range) to that triangle's nearest open edge, minimised
    /// over all triangles near the ray: how close this ray came to a
    /// different decision. Infinite when it crossed no triangle's plane near
    /// an open edge.
    pub edge_margin: f32,
}

/// A pixel's colour and the rays that produced it.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelPath {
    pub color: Vec3,
    pub segments: Vec<Segment>,
}

impl PixelPath {
    /// Rays that left a triangle and hit that same (planar) triangle again:
    /// self-intersections. Returns (such rays, rays that left a surface).
    pub fn self_hits(&self) -> (usize, usize) {
        let (mut own, mut secondary) = (0, 0);
        let camera = self.segments.first().map(|s| s.origin);
        let mut from: Option<u32> = None;
        for s in &self.segments {
            if !s.shadow && Some(s.origin) == camera {
                // A primary ray (each sample of the glossy shader has one).
                from = s.hit.map(|h| h.triangle);
                continue;
            }
            secondary += 1;
            own += usize::from(from.is_some() && s.hit.map(|h| h.triangle) == from);
            if !s.shadow {
                from = s.hit.map(|h| h.triangle);
            }
        }
        (own, secondary)
    }

    /// The smallest edge margin of any of its rays.
    pub fn edge_margin(&self) -> f32 {
        self.segments
            .iter()
            .map(|s| s.edge_margin)
            .fold(f32::INFINITY, f32::min)
    }
}

/// The sky the miss shader returns: white at the horizon blending to blue upwards.
pub fn sky(dir: Vec3) -> Vec3 {
    let k = 0.5 * (dir.y + 1.0);
    mix(Vec3::new(1.0, 1.0, 1.0), Vec3::new(0.5, 0.7, 1.0), k)
}

/// Packs a colour as the shaders do: clamp, scale to 255, round half up,
/// RGBA8 with alpha 255 in the top byte; 0 for a non-finite colour.
pub fn pack_rgba8(c: Vec3) -> u32 {
    // An infinite or NaN channel is written as 0 (alpha 0).
    if !c.is_finite() {
        return 0;
    }
    let ch = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u32;
    ch(c.x) | (ch(c.y) << 8) | (ch(c.z) << 16) | (255 << 24)
}

/// The four channels of a packed pixel, red first.
pub fn unpack_rgba8(p: u32) -> [u8; 4] {
    p.to_le_bytes()
}

/// The primary ray direction through pixel `(x, y)`.
pub fn camera_dir(params: &Params, x: u32, y: u32) -> Vec3 {
    let size = [params.width as f32, params.height as f32];
    let uv = [
        (x as f32 + 0.5) / size[0] * 2.0 - 1.0,
        (y as f32 + 0.5) / size[1] * 2.0 - 1.0,
    ];
    Vec3::new(uv[0], -uv[1], -1.5).normalize()
}

/// [`intersect`], with the ray recorded in `segments` (what `verify` reads
/// decision margins and self-hits from); the hit.
pub(crate) fn record(
    scene: &Scene,
    origin: Vec3,
    dir: Vec3,
    t_min: f32,
    t_max: f32,
    shadow: bool,
    segments: &mut Vec<Segment>,
) -> Option<Hit> {
    let (hit, edge_margin) = intersect(scene, origin, dir, t_min, t_max);
    segments.push(Segment {
        origin,
        dir,
        hit,
        shadow,
        edge_margin,
    });
    hit
}

/// The closest triangle hit with `t` in `[t_min, t_max]` that is opaque or
/// whose alpha texel keeps it (with
/// `any`, the first found, as `ACCEPT_FIRST_HIT_AND_END_SEARCH` allows: only
/// hit-or-miss matters then), and the ray's edge margin.
pub fn intersect(
    scene: &Scene,
    origin: Vec3,
    dir: Vec3,
    t_min: f32,
    t_max: f32,
) -> (Option<Hit>, f32) {
    let mut best: Option<Hit> = None;
    let mut margin = f32::INFINITY;
    scene.bvh.candidates(origin, dir, t_min, t_max, |tri| {
        let t = &scene.triangles[tri];
        let [a, b, c] = t.corners;
        let Some((th, bary)) = math::ray_triangle(origin, dir, a, b, c) else {
            return;
        };
        if !(t_min..=t_max).contains(&th) {
            return;
        }
        margin = margin.min(math::edge_distance(t.corners, bary, t.open));
        let better = match best {
            None => true,
            Some(h) => th < h.t || (th == h.t && (tri as u32) < h.triangle),
        };
        // A cut-out's candidate counts only where its texel keeps the
        // surface: the any-hit shaders' `IgnoreHit` and the ray queries'
        // alpha test before committing.
        if bary.iter().all(|&w| w >= 0.0) && better && scene.keeps(tri, bary) {
            best = Some(Hit {
                t: th,
                triangle: tri as u32,
            });
        }
    });
    (best, margin)
}

/// What a hit adds, as both shaders compute it: the normal facing the
/// incoming ray, where the next rays start (`from`), and the surface's own
/// colour per unit of `weight` (the iterative shader's throughput; 1 in the
/// recursive one), tracing the shadow ray when there is a light.
pub(crate) struct Shading {
    pub normal: Vec3,
    pub from: Vec3,
    pub local: Vec3,
    pub reflectivity: f32,
}

pub(crate) fn shade(
    scene: &Scene,
    params: &Params,
    origin: Vec3,
    dir: Vec3,
    hit: Hit,
    weight: Option<f32>,
    segments: &mut Vec<Segment>,
) -> Shading {
    let surface = scene.surfaces[hit.triangle as usize];
    let n = if surface.normal.dot(dir) < 0.0 {
        surface.normal
    } else {
        -surface.normal
    };
    let r = surface.reflectivity;
    // Iterative: `throughput * (1 - r) * albedo`; recursive: `(1 - r) * albedo`.
    let base = match weight {
        Some(w) => w * (1.0 - r) * surface.albedo,
        None => (1.0 - r) * surface.albedo,
    };
    let from = params.next_origin(origin + dir * hit.t, n);
    let local = match params.light {
        Some(light) => {
            let ndl = n.dot(light.direction);
            let mut c = base * light.ambient;
            if ndl > 0.0 {
                let blocker = record(
                    scene,
                    from,
                    light.direction,
                    params.t_min,
                    params.t_max,
                    true,
                    segments,
                );
                if blocker.is_none() {
                    c += base * ndl;
                }
            }
            c
        }
        None => base * n.dot(-dir).max(0.0),
    };
    Shading {
        normal: n,
        from,
        local,
        reflectivity: r,
    }
}

/// Follows `reflect_iterative`'s bounce loop for one pixel.
pub fn trace_iterative(scene: &Scene, params: &Params, x: u32, y: u32) -> PixelPath {
    let mut origin = params.camera;
    let mut dir = camera_dir(params, x, y);
    let mut color = Vec3::ZERO;
    let mut throughput = 1.0f32;
    let mut segments = Vec::new();
    for _bounce in 0..=params.max_bounces {
        let hit = record(
            scene,
            origin,
            dir,
            params.t_min,
            params.t_max,
            false,
            &mut segments,
        );
        let Some(hit) = hit else {
            color += throughput * sky(dir);
            break;
        };
        let s = shade(
            scene,
            params,
            origin,
            dir,
            hit,
            Some(throughput),
            &mut segments,
        );
        color += s.local;
        throughput *= s.reflectivity;
        origin = s.from;
        // The shaders' `!(throughput > cutoff)`: a NaN throughput stops too.
        if throughput.partial_cmp(&params.cutoff) != Some(std::cmp::Ordering::Greater) {
            break;
        }
        dir = reflect(dir, s.normal);
    }
    PixelPath { color, segments }
}

/// Follows `reflect_recursive`: the closest-hit shader shades, then traces
/// the reflection itself and adds `reflectivity ×` what it returns.
pub fn trace_recursive(scene: &Scene, params: &Params, x: u32, y: u32) -> PixelPath {
    let mut segments = Vec::new();
    let color = radiance(
        scene,
        params,
        params.camera,
        camera_dir(params, x, y),
        0,
        1.0,
        &mut segments,
    );
    PixelPath { color, segments }
}

fn radiance(
    scene: &Scene,
    params: &Params,
    origin: Vec3,
    dir: Vec3,
    depth: u32,
    throughput: f32,
    segments: &mut Vec<Segment>,
) -> Vec3 {
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
        return sky(dir);
    };
    let s = shade(scene, params, origin, dir, hit, None, segments);
    let r = s.reflectivity;
    let mut color = s.local;
    let next = throughput * r;
    if next > params.cutoff && depth < params.max_bounces {
        let child = radiance(
            scene,
            params,
            s.from,
            reflect(dir, s.normal),
            depth + 1,
            next,
            segments,
        );
        color += r * child;
    }
    color
}

/// The PCG hash the glossy shader draws its numbers from (Jarzynski & Olano 2020).
pub fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// A uniform number in [0, 1) with 24 bits, advancing the seed.
pub fn rand(seed: &mut u32) -> f32 {
    *seed = pcg(*seed);
    (*seed >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The glossy shader's `sample_vndf`: a GGX visible normal (Heitz 2018) for
/// the tangent-space view `ve` and roughness `alpha`.
pub fn sample_vndf(ve: Vec3, alpha: f32, u1: f32, u2: f32) -> Vec3 {
    // A grazing view (ve.z = 0) with alpha = 0 would normalise zero.
    let vh = Vec3::new(alpha * ve.x, alpha * ve.y, ve.z.max(1e-7)).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 {
        Vec3::new(-vh.y, vh.x, 0.0) * (1.0 / lensq.sqrt())
    } else {
        Vec3::X
    };
    let t2 = vh.cross(t1);
    let r = u1.sqrt();
    let phi = 6.283_185_5 * u2;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).sqrt() + s * (r * phi.sin());
    let nh = p1 * t1 + p2 * t2 + (0.0f32).max(1.0 - p1 * p1 - p2 * p2).sqrt() * vh;
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(0.0)).normalize()
}

/// Follows `reflect_glossy`: the iterative loop with GGX-sampled reflections
/// off rough surfaces, `params.samples` paths per pixel averaged.
/// In half-resolution mode, the block's top-left pixel is traced first as
/// the shader's block pass does; its rays count as that pixel's.
pub fn trace_glossy(scene: &Scene, params: &Params, x: u32, y: u32) -> PixelPath {
    let samples = params.samples.clamp(1, 16);
    let mut sum = Vec3::ZERO;
    let mut segments = Vec::new();
    let mut half = Half::off();
    if params.half_res <= 1.0 {
        let (bx, by) = (x & !1, y & !1);
        let mut block = Half {
            block_pass: true,
            ..Half::off()
        };
        let mut block_sum = Vec3::ZERO;
        let mut block_segments = Vec::new();
        for sample in 0..samples {
            glossy_path(
                scene,
                params,
                (bx, by),
                sample,
                &mut block_sum,
                &mut block_segments,
                &mut block,
            );
            if block.first_roughness <= params.half_res {
                break;
            }
        }
        let w = if block.first_roughness > params.half_res {
            block.first_roughness
        } else {
            -1.0
        };
        half.shared = (block_sum / samples as f32, w);
        if (x, y) == (bx, by) {
            segments = block_segments;
        }
    }
    for sample in 0..samples {
        glossy_path(
            scene,
            params,
            (x, y),
            sample,
            &mut sum,
            &mut segments,
            &mut half,
        );
    }
    PixelPath {
        color: sum / samples as f32,
        segments,
    }
}

/// The mean of the glossy shader's paths `0..samples` of pixel `(x, y)`,
/// for any number of them (the shader stops at 16): the converged image
/// the tradeoff sweep measures against. Not clamped or packed.
pub fn glossy_mean(scene: &Scene, params: &Params, x: u32, y: u32, samples: u32) -> Vec3 {
    let mut sum = Vec3::ZERO;
    let mut segments = Vec::new();
    for sample in 0..samples.max(1) {
        segments.clear();
        glossy_sample(scene, params, x, y, sample, &mut sum, &mut segments);
    }
    sum / samples.max(1) as f32
}

/// One path of the glossy shaders (and of the adaptive one): sample number
/// `sample` of pixel `(x, y)`, its light added into `sum` term by term (as
/// the shaders do: the rounding depends on it), its rays appended to
/// `segments`.
pub fn glossy_sample(
    scene: &Scene,
    params: &Params,
    x: u32,
    y: u32,
    sample: u32,
    sum: &mut Vec3,
    segments: &mut Vec<Segment>,
) {
    glossy_path(
        scene,
        params,
        (x, y),
        sample,
        sum,
        segments,
        &mut Half::off(),
    );
}

/// The glossy shader's half-resolution state for one pixel's paths.
#[derive(Clone, Copy, Debug)]
struct Half {
    /// The block pass: the block's top-left pixel traced in full.
    block_pass: bool,
    /// What the block pass left for the pixel's block: light beyond the
    /// first hit, and that hit's roughness (-1: nothing to share).
    shared: (Vec3, f32),
    first_roughness: f32,
}

impl Half {
    fn off() -> Half {
        Half {
            block_pass: false,
            shared: (Vec3::ZERO, -1.0),
            first_roughness: -1.0,
        }
    }
}

fn glossy_path(
    scene: &Scene,
    params: &Params,
    (x, y): (u32, u32),
    sample: u32,
    sum: &mut Vec3,
    segments: &mut Vec<Segment>,
    half: &mut Half,
) {
    let mut seed = pcg(y * params.width + x) ^ pcg(sample.wrapping_add(0x9E37_79B9));
    let mut origin = params.camera;
    let mut dir = camera_dir(params, x, y);
    let mut t_max = params.t_max;
    let mut throughput = 1.0f32;
    for bounce in 0..=params.max_bounces {
        let hit = record(scene, origin, dir, params.t_min, t_max, false, segments);
        let Some(hit) = hit else {
            *sum += throughput * sky(dir);
            break;
        };
        let surface = scene.surfaces[hit.triangle as usize];
        let n = if surface.normal.dot(dir) < 0.0 {
            surface.normal
        } else {
            -surface.normal
        };
        let base = throughput * (1.0 - surface.reflectivity) * surface.albedo;
        throughput *= surface.reflectivity;
        let roughness = surface.roughness;
        origin = params.next_origin(origin + dir * hit.t, n);
        let light = params.light.unwrap_or(Light {
            direction: Vec3::ZERO,
            ambient: 0.0,
        });
        let ndl = n.dot(light.direction);
        let headlight = n.dot(-dir).max(0.0);
        if roughness > 0.0 {
            let sgn = if n.z >= 0.0 { 1.0f32 } else { -1.0 };
            let a = -1.0 / (sgn + n.z);
            let b = n.x * n.y * a;
            let tx = Vec3::new(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
            let ty = Vec3::new(b, sgn + n.y * n.y * a, -n.y);
            let alpha = roughness * roughness;
            let ve = Vec3::new((-dir).dot(tx), (-dir).dot(ty), (-dir).dot(n));
            let u1 = rand(&mut seed);
            let u2 = rand(&mut seed);
            let m = sample_vndf(ve, alpha, u1, u2);
            dir = reflect(dir, tx * m.x + ty * m.y + n * m.z);
            let nl = n.dot(dir);
            if nl > 0.0 {
                let a2 = alpha * alpha;
                throughput *= 2.0 * nl / (nl + (a2 + (1.0 - a2) * nl * nl).sqrt());
            } else {
                throughput = 0.0;
            }
            t_max = params.reflect_t_max / (1.0 + 64.0 * roughness);
        } else {
            dir = reflect(dir, n);
            t_max = params.reflect_t_max;
        }
        if bounce == 0 {
            half.first_roughness = roughness;
            // The block pass shares only rough first hits' reflections.
            if half.block_pass && roughness <= params.half_res {
                break;
            }
        }
        // The block pass's light starts beyond the first hit.
        let local = !(half.block_pass && bounce == 0);
        if local && params.light.is_some() {
            *sum += base * light.ambient;
            if ndl > 0.0 {
                let lit = base * ndl;
                let blocker = record(
                    scene,
                    origin,
                    light.direction,
                    params.t_min,
                    params.t_max,
                    true,
                    segments,
                );
                if blocker.is_none() {
                    *sum += lit;
                }
            }
        } else if local {
            *sum += base * headlight;
        }
        if bounce == 0
            && !half.block_pass
            && half.shared.1 == roughness
            && roughness > params.half_res
        {
            *sum += half.shared.0;
            break;
        }
        // Too rough to be worth a ray: the environment answers instead of
        // the reflection ray the next bounce would trace.
        if roughness > params.rough_cutoff && bounce < params.max_bounces {
            *sum += throughput * sky(dir);
            break;
        }
        if throughput.partial_cmp(&params.cutoff) != Some(std::cmp::Ordering::Greater) {
            break;
        }
    }
}

/// Which shader's math to follow.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    Iterative,
    Recursive,
    Glossy,
    /// G-buffer, screen-space march, ray fallback ([`hybrid`]).
    Hybrid,
    /// Glossy paths accumulated until the variance is low ([`adaptive`]).
    Adaptive,
}

impl Method {
    /// How many times the GPU runs the pipeline's ray generation shaders
    /// (each in turn) over the image.
    pub fn passes(self, params: &Params) -> u32 {
        match self {
            Method::Adaptive => params.adaptive_max,
            _ => 1,
        }
    }

    /// Whether the shaders keep per-pixel state between passes (the
    /// `scratch` buffer) and write a per-pixel count (`counts`).
    pub fn scratch(self) -> bool {
        matches!(self, Method::Hybrid | Method::Adaptive)
    }
}

/// One pixel's path by `method`.
pub fn trace_pixel(scene: &Scene, params: &Params, method: Method, x: u32, y: u32) -> PixelPath {
    match method {
        Method::Iterative => trace_iterative(scene, params, x, y),
        Method::Recursive => trace_recursive(scene, params, x, y),
        Method::Glossy => trace_glossy(scene, params, x, y),
        Method::Hybrid => hybrid::trace_hybrid(scene, params, x, y),
        Method::Adaptive => adaptive::trace_adaptive(scene, params, x, y).0,
    }
}

/// The image a shader writes: `width × height` packed RGBA8, row by row,
/// with each pixel's edge margin (see [`Segment::edge_margin`]).
pub fn render(scene: &Scene, params: &Params, method: Method) -> (Vec<u32>, Vec<f32>) {
    let n = (params.width * params.height) as usize;
    if method == Method::Hybrid {
        let (paths, _) = hybrid::render(scene, params);
        return (
            paths.iter().map(|p| pack_rgba8(p.color)).collect(),
            paths.iter().map(PixelPath::edge_margin).collect(),
        );
    }
    let (mut image, mut margins) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for y in 0..params.height {
        for x in 0..params.width {
            let path = trace_pixel(scene, params, method, x, y);
            image.push(pack_rgba8(path.color));
            margins.push(path.edge_margin());
        }
    }
    (image, margins)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mirror() -> Scene {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders/scenes/mirror.toml");
        Scene::load(&path).unwrap()
    }

    fn showcase() -> Scene {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders/scenes/showcase.toml");
        Scene::load(&path).unwrap()
    }

    #[test]
    fn packing_rounds_and_clamps() {
        assert_eq!(pack_rgba8(Vec3::new(0.0, 1.0, 2.0)), 0xFFFF_FF00);
        assert_eq!(pack_rgba8(Vec3::new(0.0, f32::NAN, 0.0)), 0);
        assert_eq!(pack_rgba8(Vec3::new(f32::INFINITY, 0.0, 0.0)), 0);
        // 0.5 * 255 + 0.5 = 128.0 → 128; just below rounds down.
        assert_eq!(
            unpack_rgba8(pack_rgba8(Vec3::new(0.5, 0.498, -1.0))),
            [128, 127, 0, 255]
        );
    }

    #[test]
    fn sky_is_white_at_horizon_and_blue_straight_up() {
        assert_eq!(sky(Vec3::new(0.0, -1.0, 0.0)), Vec3::ONE);
        assert_eq!(sky(Vec3::Y), Vec3::new(0.5, 0.7, 1.0));
    }

    #[test]
    fn params_words_are_the_uniform_layout() {
        let s = showcase();
        let p = Params::for_scene(&s, 64, 32, 3);
        let w = p.to_words();
        assert_eq!(&w[..4], &[64, 32, 3, FLAG_LIGHT | FLAG_ROBUST | 4 << 8]);
        assert_eq!(f32::from_bits(w[4]), s.camera.x);
        assert_eq!(f32::from_bits(w[13]), 1e4);
        assert_eq!(w[19], 4 | 16 << 16, "the adaptive shader's passes");
    }

    #[test]
    fn t_range_excludes_hits_behind_the_minimum() {
        let scene = mirror();
        let down = Vec3::new(0.0, -1.0, 0.0);
        let (hit, _) = intersect(&scene, Vec3::new(0.5, 0.0005, 0.5), down, 0.001, 100.0);
        assert_eq!(hit, None, "a hit at t = 0.0005 is below t_min");
        let (hit, _) = intersect(&scene, Vec3::new(0.5, 0.5, 0.5), down, 0.001, 100.0);
        let hit = hit.expect("the floor is below");
        assert!((hit.t - 0.5).abs() < 1e-6);
        assert_eq!(scene.surfaces[hit.triangle as usize].reflectivity, 0.0);
        let (hit, _) = intersect(&scene, Vec3::new(0.5, 0.5, 0.5), down, 0.001, 0.4);
        assert_eq!(hit, None, "the floor is beyond t_max");
    }

    #[test]
    fn iterative_and_recursive_agree_and_show_every_path_kind() {
        for scene in [mirror(), showcase()] {
            let p = Params::for_scene(&scene, 48, 48, 3);
            let mut kinds = [0usize; 3];
            for y in 0..p.height {
                for x in 0..p.width {
                    let a = trace_iterative(&scene, &p, x, y);
                    let b = trace_recursive(&scene, &p, x, y);
                    assert_eq!(pack_rgba8(a.color), pack_rgba8(b.color), "({x}, {y})");
                    let first = a.segments[0]
                        .hit
                        .map(|h| scene.surfaces[h.triangle as usize]);
                    match first {
                        None => kinds[0] += 1,
                        Some(s) if s.reflectivity == 0.0 => kinds[1] += 1,
                        Some(_) => kinds[2] += 1,
                    }
                }
            }
            assert!(kinds.iter().all(|&k| k > 100), "{}: {kinds:?}", scene.name);
        }
    }

    #[test]
    fn vndf_samples_are_finite_at_the_extremes() {
        // alpha = 0 gives the normal; grazing and head-on views stay finite.
        let n = sample_vndf(Vec3::new(0.6, 0.0, 0.8), 0.0, 0.3, 0.7);
        assert_eq!(n, Vec3::Z);
        for ve in [
            Vec3::Z,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 0.999_999, 0.001),
        ] {
            for alpha in [0.0, 1e-8, 0.25, 1.0] {
                for (u1, u2) in [(0.0, 0.0), (0.999_999_9, 0.999_999_9), (0.5, 0.25)] {
                    let m = sample_vndf(ve, alpha, u1, u2);
                    assert!(m.is_finite() && m.z >= 0.0, "{ve} {alpha} {u1} {u2}: {m}");
                }
            }
        }
        // The hash and the numbers drawn from it are reproducible.
        let mut seed = 7;
        let (a, b) = (rand(&mut seed), rand(&mut seed));
        assert!(a != b && (0.0..1.0).contains(&a) && (0.0..1.0).contains(&b));
        assert_eq!(pcg(0), 129708002);
    }

    #[test]
    fn glossy_without_roughness_is_the_mirror_image() {
        let scene = mirror();
        let p = Params::for_scene(&scene, 32, 32, 3);
        for i in 0..32 * 32 {
            let (x, y) = (i % 32, i / 32);
            assert_eq!(
                pack_rgba8(trace_glossy(&scene, &p, x, y).color),
                pack_rgba8(trace_iterative(&scene, &p, x, y).color),
                "({x}, {y})"
            );
        }
    }

    #[test]
    fn cutouts_let_primary_reflection_and_shadow_rays_through() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders/scenes/cutout.toml");
        let scene = Scene::load(&path).unwrap();
        assert!(scene.has_cutouts());
        let mut solid = scene.clone();
        for s in &mut solid.surfaces {
            s.cutout = false;
        }
        let p = Params::for_scene(&scene, 48, 48, 3);
        // Per ray kind: rays whose hit changes when the holes are filled.
        let mut through = [0usize; 3];
        for y in 0..p.height {
            for x in 0..p.width {
                let a = trace_iterative(&scene, &p, x, y);
                let b = trace_iterative(&solid, &p, x, y);
                for (k, (sa, sb)) in a.segments.iter().zip(&b.segments).enumerate() {
                    if sa.hit.map(|h| h.triangle) != sb.hit.map(|h| h.triangle) {
                        let kind = if sa.shadow { 2 } else { usize::from(k > 0) };
                        through[kind] += 1;
                        break;
                    }
                }
            }
        }
        assert!(through.iter().all(|&n| n > 5), "{through:?}");
    }

    #[test]
    fn the_light_casts_shadows() {
        let scene = showcase();
        let p = Params::for_scene(&scene, 48, 48, 3);
        let shadowed = (0..48 * 48)
            .map(|i| trace_iterative(&scene, &p, i % 48, i / 48))
            .filter(|path| path.segments.iter().any(|s| s.shadow && s.hit.is_some()))
            .count();
        assert!(shadowed > 20, "{shadowed}");
    }
}
