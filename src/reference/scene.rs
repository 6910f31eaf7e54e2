//! The reflection test scene: a floor of four coloured tiles, a perfect
//! mirror tilted to show the floor in front of it, and a half-reflective
//! blue wall at the side. One mesh, one instance with the identity
//! transform, so `primitive_index` is the triangle's index here.

use super::math::{cross, normalize, scale, sub, Vec3};

/// Per-triangle material, as the shader's `Surface` (two `vec4<f32>`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Unit geometric normal, facing the side the camera sees.
    pub normal: Vec3,
    /// 0 = diffuse only, 1 = perfect mirror.
    pub reflectivity: f32,
    pub albedo: Vec3,
}

impl Surface {
    /// The 32 bytes the shader reads: `normal_reflectivity`, `albedo` (w = 0).
    pub fn to_gpu(&self) -> [f32; 8] {
        let n = self.normal;
        let a = self.albedo;
        [n[0], n[1], n[2], self.reflectivity, a[0], a[1], a[2], 0.0]
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub positions: Vec<Vec3>,
    /// Three per triangle.
    pub indices: Vec<u32>,
    /// One per triangle.
    pub surfaces: Vec<Surface>,
}

pub const FLOOR_ALBEDOS: [Vec3; 4] = [
    [0.9, 0.3, 0.2],
    [0.2, 0.7, 0.3],
    [0.9, 0.8, 0.2],
    [0.3, 0.4, 0.9],
];
/// Deliberately loud, so an image showing it instead of the reflection is obvious.
pub const MIRROR_ALBEDO: Vec3 = [1.0, 0.0, 1.0];
pub const WALL_ALBEDO: Vec3 = [0.2, 0.3, 0.9];
pub const WALL_REFLECTIVITY: f32 = 0.5;

impl Scene {
    pub fn reflection() -> Scene {
        let mut scene = Scene {
            positions: Vec::new(),
            indices: Vec::new(),
            surfaces: Vec::new(),
        };
        // Floor y = 0, x in [-3.1, 3.1], z in [-6, 2], in 2 × 2 tiles. Not
        // ±3: from the camera at height 1, x = ±3 on the floor is where
        // pixel rays with uv.x = ∓3 uv.y land, and at 64 × 64 several pixel
        // centres do, exactly on the floor's edge, where hit or miss is a
        // matter of rounding.
        for (k, albedo) in FLOOR_ALBEDOS.into_iter().enumerate() {
            let x = if k % 2 == 0 { -1.55 } else { 1.55 };
            let z = if k < 2 { -4.0 } else { 0.0 };
            scene.quad([x, 0.0, z], [1.55, 0.0, 0.0], [0.0, 0.0, -2.0], 0.0, albedo);
        }
        // The mirror leans towards the camera (normal (0, -a, b)), so primary
        // rays reflect down onto the near floor.
        let n = normalize([0.0, -0.35, 1.0]);
        let up = [0.0, n[2], -n[1]];
        scene.quad(
            [0.5, 1.3, -3.0],
            [1.2, 0.0, 0.0],
            scale(up, 0.8),
            1.0,
            MIRROR_ALBEDO,
        );
        // The wall at x = -2.4 faces +x. Its lower edge is at 0.23, not 0.2:
        // the ray from the camera to the floor point (-3, 0, z) crosses
        // x = -2.4 exactly at y = 0.2.
        scene.quad(
            [-2.4, 1.13, -2.5],
            [0.0, 0.9, 0.0],
            [0.0, 0.0, 1.5],
            WALL_REFLECTIVITY,
            WALL_ALBEDO,
        );
        scene
    }

    /// A parallelogram `center ± u ± v` as two triangles facing `u × v`.
    fn quad(&mut self, center: Vec3, u: Vec3, v: Vec3, reflectivity: f32, albedo: Vec3) {
        let base = self.positions.len() as u32;
        let at = |su: f32, sv: f32| -> Vec3 {
            [
                center[0] + su * u[0] + sv * v[0],
                center[1] + su * u[1] + sv * v[1],
                center[2] + su * u[2] + sv * v[2],
            ]
        };
        self.positions
            .extend([at(-1.0, -1.0), at(1.0, -1.0), at(1.0, 1.0), at(-1.0, 1.0)]);
        self.indices
            .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        let p = &self.positions[base as usize..];
        let normal = normalize(cross(sub(p[1], p[0]), sub(p[2], p[0])));
        let surface = Surface {
            normal,
            reflectivity,
            albedo,
        };
        self.surfaces.extend([surface, surface]);
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// The corners of triangle `prim`.
    pub fn triangle(&self, prim: usize) -> [Vec3; 3] {
        let i = &self.indices[prim * 3..prim * 3 + 3];
        [
            self.positions[i[0] as usize],
            self.positions[i[1] as usize],
            self.positions[i[2] as usize],
        ]
    }

    /// Which edges of triangle `prim` are open: not shared with another
    /// triangle of the same surface. Edge `i` is opposite corner `i`. A ray
    /// crossing a closed edge sees the same surface on either side, so only
    /// open edges make hit-or-miss a matter of rounding.
    pub fn open_edges(&self, prim: usize) -> [bool; 3] {
        let tri = &self.indices[prim * 3..prim * 3 + 3];
        std::array::from_fn(|i| {
            let (a, b) = (tri[(i + 1) % 3], tri[(i + 2) % 3]);
            !(0..self.triangle_count()).any(|other| {
                let o = &self.indices[other * 3..other * 3 + 3];
                other != prim
                    && self.surfaces[other] == self.surfaces[prim]
                    && o.contains(&a)
                    && o.contains(&b)
            })
        })
    }

    /// The shader's `surfaces` buffer.
    pub fn surface_data(&self) -> Vec<[f32; 8]> {
        self.surfaces.iter().map(Surface::to_gpu).collect()
    }
}
