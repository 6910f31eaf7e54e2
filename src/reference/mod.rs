//! CPU reference renderer for `shaders/reflect_iterative.wgsl`, and the scene
//! both it and the GPU test render.
//!
//! Everything is `f32` and follows the shader operation by operation (camera,
//! bounce loop, sky, shading, packing) so that the GPU image should match to
//! within one 8-bit step; ray/triangle tests use the shader's `t` range and
//! treat every triangle as opaque, as `RAY_FLAG_OPAQUE` does.

pub mod math;
pub mod scene;

pub use math::{cross, dot, normalize, reflect, Vec3};
pub use scene::{Scene, Surface};

/// The ray interval the shader traces with.
pub const T_MIN: f32 = 0.001;
pub const T_MAX: f32 = 100.0;
/// The shader offsets each bounce origin along the normal by this much.
pub const NORMAL_OFFSET: f32 = 0.001;
pub const CAMERA_ORIGIN: Vec3 = [0.0, 1.0, 4.0];

/// The shader's uniform block (`Params`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Params {
    pub width: u32,
    pub height: u32,
    pub max_bounces: u32,
}

impl Params {
    /// The uniform buffer contents: width, height, max_bounces, padding.
    pub fn to_words(self) -> [u32; 4] {
        [self.width, self.height, self.max_bounces, 0]
    }
}

/// The closest hit of a ray, as the closest-hit shader sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    /// `primitive_index`: the triangle's index in the scene.
    pub primitive: u32,
}

/// One traced segment of a pixel's path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub origin: Vec3,
    pub dir: Vec3,
    pub hit: Option<Hit>,
    /// World-space distance from where the ray crosses a triangle's plane
    /// (within the `t` range) to that triangle's nearest open edge (see
    /// [`Scene::open_edges`]), minimised over all triangles: how close this
    /// segment came to a different hit/miss decision. Infinite when it
    /// crossed no triangle's plane near an open edge.
    pub edge_margin: f32,
}

/// A pixel's colour and the path that produced it.
#[derive(Clone, Debug, PartialEq)]
pub struct PixelPath {
    pub color: Vec3,
    pub segments: Vec<Segment>,
}

/// The sky the miss path adds: white at the horizon blending to blue upwards.
pub fn sky(dir: Vec3) -> Vec3 {
    let k = 0.5 * (dir[1] + 1.0);
    math::mix([1.0, 1.0, 1.0], [0.5, 0.7, 1.0], k)
}

/// Packs a colour as the shader does: clamp, scale to 255, round half up,
/// RGBA8 with alpha 255 in the top byte.
pub fn pack_rgba8(c: Vec3) -> u32 {
    let ch = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u32;
    ch(c[0]) | (ch(c[1]) << 8) | (ch(c[2]) << 16) | (255 << 24)
}

/// The four channels of a packed pixel, red first.
pub fn unpack_rgba8(p: u32) -> [u8; 4] {
    p.to_le_bytes()
}

/// The primary ray direction through pixel `(x, y)`.
pub fn camera_dir(params: Params, x: u32, y: u32) -> Vec3 {
    let size = [params.width as f32, params.height as f32];
    let uv = [
        (x as f32 + 0.5) / size[0] * 2.0 - 1.0,
        (y as f32 + 0.5) / size[1] * 2.0 - 1.0,
    ];
    normalize([uv[0], -uv[1], -1.5])
}

/// The closest opaque triangle hit with `t` in `[t_min, t_max]`, and the
/// segment's edge margin (see [`Segment::edge_margin`]).
pub fn intersect(
    scene: &Scene,
    origin: Vec3,
    dir: Vec3,
    t_min: f32,
    t_max: f32,
) -> (Option<Hit>, f32) {
    let mut best: Option<Hit> = None;
    let mut margin = f32::INFINITY;
    for prim in 0..scene.triangle_count() {
        let [a, b, c] = scene.triangle(prim);
        let Some((t, bary)) = math::ray_triangle(origin, dir, a, b, c) else {
            continue;
        };
        if !(t_min..=t_max).contains(&t) {
            continue;
        }
        margin = margin.min(math::edge_distance([a, b, c], bary, scene.open_edges(prim)));
        if bary.iter().all(|&w| w >= 0.0) && best.is_none_or(|h| t < h.t) {
            best = Some(Hit {
                t,
                primitive: prim as u32,
            });
        }
    }
    (best, margin)
}

/// Follows the shader's bounce loop for one pixel.
pub fn trace_pixel(scene: &Scene, params: Params, x: u32, y: u32) -> PixelPath {
    let mut origin = CAMERA_ORIGIN;
    let mut dir = camera_dir(params, x, y);
    let mut color = [0.0f32; 3];
    let mut throughput = [1.0f32; 3];
    let mut segments = Vec::new();
    for _bounce in 0..=params.max_bounces {
        let (hit, edge_margin) = intersect(scene, origin, dir, T_MIN, T_MAX);
        segments.push(Segment {
            origin,
            dir,
            hit,
            edge_margin,
        });
        let Some(hit) = hit else {
            let s = sky(dir);
            for i in 0..3 {
                color[i] += throughput[i] * s[i];
            }
            break;
        };
        let surface = scene.surfaces[hit.primitive as usize];
        let n = surface.normal;
        let shade = dot(n, [-dir[0], -dir[1], -dir[2]]).max(0.0);
        let r = surface.reflectivity;
        for i in 0..3 {
            color[i] += throughput[i] * surface.albedo[i] * shade * (1.0 - r);
            throughput[i] *= r;
        }
        if r <= 0.0 {
            break;
        }
        for i in 0..3 {
            origin[i] = origin[i] + dir[i] * hit.t + n[i] * NORMAL_OFFSET;
        }
        dir = reflect(dir, n);
    }
    PixelPath { color, segments }
}

/// The image the shader writes: `width × height` packed RGBA8, row by row.
pub fn render(scene: &Scene, params: Params) -> Vec<u32> {
    let mut image = Vec::with_capacity((params.width * params.height) as usize);
    for y in 0..params.height {
        for x in 0..params.width {
            image.push(pack_rgba8(trace_pixel(scene, params, x, y).color));
        }
    }
    image
}

#[cfg(test)]
mod tests {
    use super::*;

    const PARAMS: Params = Params {
        width: 64,
        height: 64,
        max_bounces: 3,
    };

    #[test]
    fn packing_rounds_and_clamps() {
        assert_eq!(pack_rgba8([0.0, 1.0, 2.0]), 0xFFFF_FF00);
        // 0.5 * 255 + 0.5 = 128.0 → 128; just below rounds down.
        assert_eq!(
            unpack_rgba8(pack_rgba8([0.5, 0.498, -1.0])),
            [128, 127, 0, 255]
        );
    }

    #[test]
    fn sky_is_white_at_horizon_and_blue_straight_up() {
        assert_eq!(sky([0.0, -1.0, 0.0]), [1.0, 1.0, 1.0]);
        assert_eq!(sky([0.0, 1.0, 0.0]), [0.5, 0.7, 1.0]);
    }

    #[test]
    fn t_range_excludes_hits_behind_the_minimum() {
        let scene = Scene::reflection();
        // Straight down onto the floor from just above it.
        let (hit, _) = intersect(&scene, [0.5, 0.0005, 0.5], [0.0, -1.0, 0.0], T_MIN, T_MAX);
        assert_eq!(hit, None, "a hit at t = 0.0005 is below t_min");
        let (hit, _) = intersect(&scene, [0.5, 0.5, 0.5], [0.0, -1.0, 0.0], T_MIN, T_MAX);
        let hit = hit.expect("the floor is below");
        assert!((hit.t - 0.5).abs() < 1e-6);
        assert_eq!(scene.surfaces[hit.primitive as usize].reflectivity, 0.0);
        let (hit, _) = intersect(&scene, [0.5, 0.5, 0.5], [0.0, -1.0, 0.0], T_MIN, 0.4);
        assert_eq!(hit, None, "the floor is beyond t_max");
    }

    #[test]
    fn image_shows_sky_floor_and_mirror_reflections() {
        let scene = Scene::reflection();
        let mut kinds = [0usize; 3];
        for y in 0..PARAMS.height {
            for x in 0..PARAMS.width {
                let path = trace_pixel(&scene, PARAMS, x, y);
                let first = path.segments[0]
                    .hit
                    .map(|h| scene.surfaces[h.primitive as usize]);
                match first {
                    None => kinds[0] += 1,
                    Some(s) if s.reflectivity == 0.0 => kinds[1] += 1,
                    Some(_) => {
                        kinds[2] += 1;
                        assert!(path.segments.len() >= 2);
                    }
                }
            }
        }
        // The scene is meant to exercise every path kind with many pixels.
        assert!(
            kinds.iter().all(|&k| k > 200),
            "sky/floor/mirror pixels: {kinds:?}"
        );
    }

    #[test]
    fn quad_diagonals_are_closed_edges() {
        let scene = Scene::reflection();
        // Each quad is (0, 1, 2), (0, 2, 3): the diagonal 0–2 is opposite
        // corner 1 in the first triangle and corner 2 in the second.
        assert_eq!(scene.open_edges(0), [true, false, true]);
        assert_eq!(scene.open_edges(1), [true, true, false]);
        // A point on the diagonal is far from any open edge of a 3 × 4 tile.
        let [a, b, c] = scene.triangle(0);
        let d = math::edge_distance([a, b, c], [0.5, 0.0, 0.5], scene.open_edges(0));
        assert!(d > 1.0, "{d}");
        // Just across the diagonal, inside the neighbour: the neighbour answers.
        let d = math::edge_distance([a, b, c], [0.5, -0.01, 0.51], scene.open_edges(0));
        assert_eq!(d, f32::INFINITY);
    }

    #[test]
    fn stored_normals_face_the_camera() {
        let scene = Scene::reflection();
        for prim in 0..scene.triangle_count() {
            let [a, b, c] = scene.triangle(prim);
            let geometric = normalize(cross(math::sub(b, a), math::sub(c, a)));
            let stored = scene.surfaces[prim].normal;
            assert!(dot(geometric, stored).abs() > 0.9999, "triangle {prim}");
            assert!(
                dot(stored, math::sub(CAMERA_ORIGIN, a)) > 0.0,
                "triangle {prim}"
            );
        }
    }
}
