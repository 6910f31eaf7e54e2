//! Scenes described in data: a small TOML file names the meshes (quads,
//! boxes and spheres as triangle meshes), the instances that place them
//! (translation, rotation, scale), their materials, an optional directional
//! light and the camera. The sky is the analytic gradient of [`super::sky`].
//!
//! ```toml
//! [camera]
//! position = [0.0, 1.0, 4.0]
//!
//! [light]                    # optional: without it no shadow rays are traced
//! direction = [0.3, 1.0, 0.4]  # towards the light; normalised on load
//! ambient = 0.25
//!
//! [[material]]
//! name = "mirror"
//! albedo = [1.0, 0.0, 1.0]
//! metallic = 1.0             # the mirror shaders' reflectivity
//! roughness = 0.0
//! cutout = false             # alpha-tested against [cutout] at the mesh's UVs
//!
//! [cutout]                   # optional: the alpha texture, one string per row
//! rows = ["#.", ".#"]        # '#' keeps the surface, '.' cuts it away
//!
//! [[mesh]]
//! name = "ball"
//! kind = "sphere"            # quad (center, u, v) | box (size) | sphere (radius, segments, rings)
//! radius = 0.5
//!
//! [[instance]]
//! mesh = "ball"
//! material = "mirror"
//! translate = [0.0, 0.5, -2.0]
//! rotate = [0.0, 30.0, 0.0]  # degrees about x, y, z, applied in that order
//! scale = [1.0, 1.0, 1.0]
//! ```
//!
//! Loading flattens every instance into world-space triangles (instance
//! order, then the mesh's triangle order), each with its [`Surface`]; the GPU
//! harness builds one bottom-level structure per mesh and gives each
//! instance the index of its first triangle as its custom index, so
//! `surfaces[instance_custom_index + primitive_index]` is the same surface on
//! both sides.

use super::bvh::Bvh;
use glam::{Affine3A, EulerRot, Quat, Vec2, Vec3};
use serde::Deserialize;
use std::path::Path;

/// Per-triangle surface, as the shaders' `Surface` (two `vec4<f32>`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Unit geometric normal of the world-space triangle (its winding's side).
    pub normal: Vec3,
    /// 0 = diffuse only, 1 = perfect mirror (the material's `metallic`).
    pub reflectivity: f32,
    pub albedo: Vec3,
    pub roughness: f32,
    /// Alpha-tested against the scene's [`Cutout`] texture.
    pub cutout: bool,
}

impl Surface {
    /// The 32 bytes the shader reads: `normal_reflectivity`, `albedo_roughness`.
    pub fn to_gpu(&self) -> [f32; 8] {
        let (n, a) = (self.normal, self.albedo);
        [
            n.x,
            n.y,
            n.z,
            self.reflectivity,
            a.x,
            a.y,
            a.z,
            self.roughness,
        ]
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    pub albedo: Vec3,
    pub metallic: f32,
    pub roughness: f32,
    pub cutout: bool,
}

/// The alpha texture of cut-out materials: `width × height` texels, row by
/// row, each 1 (surface) or 0 (cut away).
#[derive(Clone, Debug, PartialEq)]
pub struct Cutout {
    pub width: u32,
    pub height: u32,
    pub alpha: Vec<f32>,
}

impl Cutout {
    /// Whether the surface is there at texture coordinate `uv`: the one texel
    /// under `uv` (clamped to the texture), as the shaders' `alpha_test`.
    pub fn keeps(&self, uv: Vec2) -> bool {
        let size = Vec2::new(self.width as f32, self.height as f32);
        // `uint2(clamp(uv, 0, 1) * size)`: float-to-uint truncates.
        let texel = uv.clamp(Vec2::ZERO, Vec2::ONE) * size;
        let x = (texel.x as u32).min(self.width - 1);
        let y = (texel.y as u32).min(self.height - 1);
        self.alpha[(y * self.width + x) as usize] >= 0.5
    }

    /// The texels as the GPU's RGBA32F image: alpha in every channel.
    pub fn texels(&self) -> Vec<[f32; 4]> {
        self.alpha.iter().map(|&a| [a; 4]).collect()
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Unit direction towards the light.
    pub direction: Vec3,
    /// Light every lit or shadowed surface gets regardless.
    pub ambient: f32,
}

/// Triangles in object space.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    /// Texture coordinates, one per position.
    pub uvs: Vec<Vec2>,
    /// Three per triangle.
    pub indices: Vec<u32>,
}

impl Mesh {
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Positions as the acceleration-structure builder takes them.
    pub fn positions_f32(&self) -> Vec<[f32; 3]> {
        self.positions.iter().map(|p| p.to_array()).collect()
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    pub mesh: usize,
    pub material: usize,
    /// Object to world.
    pub transform: Affine3A,
    /// Index of the instance's first triangle among the scene's triangles:
    /// the instance custom index the GPU sees.
    pub first_triangle: u32,
}

impl Instance {
    /// The row-major 3×4 matrix of `VkTransformMatrixKHR`.
    pub fn rows(&self) -> [[f32; 4]; 3] {
        let m = self.transform.matrix3;
        let t = self.transform.translation;
        [
            [m.x_axis.x, m.y_axis.x, m.z_axis.x, t.x],
            [m.x_axis.y, m.y_axis.y, m.z_axis.y, t.y],
            [m.x_axis.z, m.y_axis.z, m.z_axis.z, t.z],
        ]
    }
}

/// One world-space triangle of the flattened scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    pub corners: [Vec3; 3],
    /// Which edges are open: not shared with another triangle of the same
    /// instance and surface. Edge `i` is opposite corner `i`. A ray crossing a
    /// closed edge sees the same surface on either side, so only open edges
    /// make the result a matter of rounding.
    pub open: [bool; 3],
    /// Texture coordinates at the corners.
    pub uvs: [Vec2; 3],
}

impl Triangle {
    /// The texture coordinate at barycentrics `(w0, w1, w2)`, as the shaders
    /// interpolate it: `uv0 + w1 (uv1 - uv0) + w2 (uv2 - uv0)`.
    pub fn uv(&self, bary: [f32; 3]) -> Vec2 {
        let [a, b, c] = self.uvs;
        a + bary[1] * (b - a) + bary[2] * (c - a)
    }
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub camera: Vec3,
    pub light: Option<Light>,
    pub cutout: Option<Cutout>,
    pub materials: Vec<Material>,
    pub meshes: Vec<Mesh>,
    pub instances: Vec<Instance>,
    /// World-space triangles, instance by instance.
    pub triangles: Vec<Triangle>,
    /// One per triangle: the shaders' `surfaces` buffer.
    pub surfaces: Vec<Surface>,
    pub bvh: Bvh,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    camera: RawCamera,
    light: Option<RawLight>,
    cutout: Option<RawCutout>,
    #[serde(default)]
    material: Vec<RawMaterial>,
    #[serde(default)]
    mesh: Vec<RawMesh>,
    #[serde(default)]
    instance: Vec<RawInstance>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCamera {
    position: [f32; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawLight {
    direction: [f32; 3],
    #[serde(default)]
    ambient: f32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCutout {
    rows: Vec<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMaterial {
    name: String,
    albedo: [f32; 3],
    #[serde(default)]
    metallic: f32,
    #[serde(default)]
    roughness: f32,
    #[serde(default)]
    cutout: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "lowercase")]
enum RawMeshKind {
    Quad {
        center: [f32; 3],
        u: [f32; 3],
        v: [f32; 3],
    },
    Box {
        size: [f32; 3],
    },
    Sphere {
        radius: f32,
        #[serde(default = "default_segments")]
        segments: u32,
        #[serde(default = "default_rings")]
        rings: u32,
    },
}

fn default_segments() -> u32 {
    16
}

fn default_rings() -> u32 {
    8
}

#[derive(Deserialize)]
struct RawMesh {
    name: String,
    #[serde(flatten)]
    kind: RawMeshKind,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawInstance {
    mesh: String,
    material: String,
    #[serde(default)]
    translate: [f32; 3],
    #[serde(default)]
    rotate: [f32; 3],
    #[serde(default = "unit_scale")]
    scale: [f32; 3],
}

fn unit_scale() -> [f32; 3] {
    [1.0; 3]
}

impl Scene {
    /// Reads and builds the scene at `path`; errors name the file.
    pub fn load(path: &Path) -> Result<Scene, String> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| format!("cannot read scene {}: {e}", path.display()))?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        Scene::parse(&name, &text).map_err(|e| format!("scene {}: {e}", path.display()))
    }

    /// Parses and builds a scene from TOML text.
    pub fn parse(name: &str, text: &str) -> Result<Scene, String> {
        let raw: RawScene = toml::from_str(text).map_err(|e| e.message().trim().to_string())?;
        let finite = |v: &[f32], what: &str| -> Result<(), String> {
            if v.iter().all(|x| x.is_finite()) {
                Ok(())
            } else {
                Err(format!("{what} must be finite"))
            }
        };
        finite(&raw.camera.position, "camera.position")?;
        let light = match raw.light {
            Some(l) => {
                finite(&l.direction, "light.direction")?;
                let d = Vec3::from(l.direction);
                if d.length() == 0.0 {
                    return Err("light.direction must not be zero".into());
                }
                Some(Light {
                    direction: d.normalize(),
                    ambient: l.ambient,
                })
            }
            None => None,
        };
        let cutout = match raw.cutout {
            Some(c) => Some(cutout(&c.rows)?),
            None => None,
        };
        let materials: Vec<Material> = raw
            .material
            .into_iter()
            .map(|m| Material {
                name: m.name,
                albedo: m.albedo.into(),
                metallic: m.metallic,
                roughness: m.roughness,
                cutout: m.cutout,
            })
            .collect();
        if let Some(m) = materials.iter().find(|m| m.cutout) {
            if cutout.is_none() {
                return Err(format!(
                    "material `{}` is a cut-out, but the scene has no [cutout] texture",
                    m.name
                ));
            }
        }
        let mut meshes = Vec::new();
        for m in raw.mesh {
            let mesh = match m.kind {
                RawMeshKind::Quad { center, u, v } => quad(center.into(), u.into(), v.into()),
                RawMeshKind::Box { size } => cuboid(Vec3::from(size) * 0.5),
                RawMeshKind::Sphere {
                    radius,
                    segments,
                    rings,
                } => {
                    if !(3..=256).contains(&segments) || !(2..=256).contains(&rings) {
                        return Err(format!(
                            "mesh `{}`: a sphere needs 3–256 segments and 2–256 rings",
                            m.name
                        ));
                    }
                    sphere(radius, segments, rings)
                }
            };
            meshes.push(Mesh {
                name: m.name,
                ..mesh
            });
        }
        let mut scene = Scene {
            name: name.to_string(),
            camera: raw.camera.position.into(),
            light,
            cutout,
            materials,
            meshes,
            instances: Vec::new(),
            triangles: Vec::new(),
            surfaces: Vec::new(),
            bvh: Bvh::default(),
        };
        for i in raw.instance {
            let mesh = scene
                .meshes
                .iter()
                .position(|m| m.name == i.mesh)
                .ok_or_else(|| format!("instance names unknown mesh `{}`", i.mesh))?;
            let material = scene
                .materials
                .iter()
                .position(|m| m.name == i.material)
                .ok_or_else(|| format!("instance names unknown material `{}`", i.material))?;
            finite(&i.translate, "instance.translate")?;
            finite(&i.rotate, "instance.rotate")?;
            finite(&i.scale, "instance.scale")?;
            let [rx, ry, rz] = i.rotate.map(f32::to_radians);
            let transform = Affine3A::from_scale_rotation_translation(
                i.scale.into(),
                Quat::from_euler(EulerRot::ZYX, rz, ry, rx),
                i.translate.into(),
            );
            scene.instances.push(Instance {
                mesh,
                material,
                transform,
                first_triangle: 0,
            });
        }
        if scene.instances.is_empty() {
            return Err("the scene has no instance".into());
        }
        scene.flatten();
        Ok(scene)
    }

    /// The same scene with every instance and the camera moved by `offset`.
    pub fn translated(&self, offset: Vec3) -> Scene {
        let mut s = self.clone();
        s.camera += offset;
        for i in &mut s.instances {
            i.transform.translation += glam::Vec3A::from(offset);
        }
        s.flatten();
        s
    }

    /// The same scene with every material's roughness set to `roughness`.
    pub fn with_roughness(&self, roughness: f32) -> Scene {
        let mut s = self.clone();
        for m in &mut s.materials {
            m.roughness = roughness;
        }
        s.flatten();
        s
    }

    /// The same scene with every triangle wound the other way: every
    /// geometric normal the shaders read points to the other side, away
    /// from whoever sees the surface first.
    pub fn with_flipped_normals(&self) -> Scene {
        let mut s = self.clone();
        for m in &mut s.meshes {
            for t in m.indices.chunks_exact_mut(3) {
                t.swap(1, 2);
            }
        }
        s.flatten();
        s
    }

    /// Rebuilds the world-space triangles, surfaces and BVH from the instances.
    fn flatten(&mut self) {
        self.triangles.clear();
        self.surfaces.clear();
        for inst in &mut self.instances {
            inst.first_triangle = self.triangles.len() as u32;
            let mesh = &self.meshes[inst.mesh];
            let material = &self.materials[inst.material];
            let world: Vec<Vec3> = mesh
                .positions
                .iter()
                .map(|&p| inst.transform.transform_point3(p))
                .collect();
            let first = self.surfaces.len();
            for tri in mesh.indices.chunks_exact(3) {
                let c = [0, 1, 2].map(|k| world[tri[k] as usize]);
                let normal = (c[1] - c[0]).cross(c[2] - c[0]).normalize();
                self.surfaces.push(Surface {
                    normal,
                    reflectivity: material.metallic,
                    albedo: material.albedo,
                    roughness: material.roughness,
                    cutout: material.cutout,
                });
                self.triangles.push(Triangle {
                    corners: c,
                    open: [true; 3],
                    uvs: [0, 1, 2].map(|k| mesh.uvs[tri[k] as usize]),
                });
            }
            // Open edges: shared with no other triangle of this instance
            // that has the same surface.
            let n = mesh.triangle_count();
            let mut edges: std::collections::HashMap<(u32, u32), Vec<usize>> = Default::default();
            for t in 0..n {
                let tri = &mesh.indices[t * 3..t * 3 + 3];
                for i in 0..3 {
                    let (a, b) = (tri[(i + 1) % 3], tri[(i + 2) % 3]);
                    edges.entry((a.min(b), a.max(b))).or_default().push(t);
                }
            }
            for t in 0..n {
                let tri = &mesh.indices[t * 3..t * 3 + 3];
                for i in 0..3 {
                    let (a, b) = (tri[(i + 1) % 3], tri[(i + 2) % 3]);
                    let shared = edges[&(a.min(b), a.max(b))]
                        .iter()
                        .any(|&o| o != t && self.surfaces[first + o] == self.surfaces[first + t]);
                    self.triangles[first + t].open[i] = !shared;
                }
            }
        }
        self.bvh = Bvh::build(&self.triangles);
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// The world-space triangles as one mesh (three corners per triangle, in
    /// order), so that a single identity instance of it has
    /// `primitive_index` equal to the triangle's index here.
    pub fn world_mesh(&self) -> (Vec<[f32; 3]>, Vec<u32>) {
        let positions: Vec<[f32; 3]> = self
            .triangles
            .iter()
            .flat_map(|t| t.corners.map(|c| c.to_array()))
            .collect();
        let indices = (0..positions.len() as u32).collect();
        (positions, indices)
    }

    /// The shaders' `surfaces` buffer.
    pub fn surface_data(&self) -> Vec<[f32; 8]> {
        self.surfaces.iter().map(Surface::to_gpu).collect()
    }

    /// Whether any instance is alpha-tested: only then does the GPU build
    /// any-hit shaders and bind the texture and the `cutouts` buffer.
    pub fn has_cutouts(&self) -> bool {
        self.surfaces.iter().any(|s| s.cutout)
    }

    /// Whether the surface of `triangle` is there at barycentrics `bary`
    /// (always, unless its material is a cut-out).
    pub fn keeps(&self, triangle: usize, bary: [f32; 3]) -> bool {
        match &self.cutout {
            Some(c) if self.surfaces[triangle].cutout => c.keeps(self.triangles[triangle].uv(bary)),
            _ => true,
        }
    }

    /// The shaders' `cutouts` buffer, one record per triangle: the corners'
    /// texture coordinates `u0 v0 u1 v1, u2 v2`, then the texture's width and
    /// height, or 0 and 0 for a surface that is not alpha-tested.
    pub fn cutout_data(&self) -> Vec<[f32; 8]> {
        let (w, h) = self
            .cutout
            .as_ref()
            .map_or((0.0, 0.0), |c| (c.width as f32, c.height as f32));
        self.triangles
            .iter()
            .zip(&self.surfaces)
            .map(|(t, s)| {
                let [a, b, c] = t.uvs;
                let (w, h) = if s.cutout { (w, h) } else { (0.0, 0.0) };
                [a.x, a.y, b.x, b.y, c.x, c.y, w, h]
            })
            .collect()
    }
}

/// Parses `[cutout] rows`: equal-length rows of `#` (kept) and `.` (cut).
fn cutout(rows: &[String]) -> Result<Cutout, String> {
    let width = rows.first().map_or(0, |r| r.chars().count());
    if width == 0 || rows.len() > 256 || width > 256 {
        return Err("cutout.rows must be 1–256 rows of 1–256 texels".into());
    }
    let mut alpha = Vec::with_capacity(width * rows.len());
    for (y, r) in rows.iter().enumerate() {
        if r.chars().count() != width {
            return Err(format!("cutout.rows[{y}] is not {width} texels long"));
        }
        for ch in r.chars() {
            alpha.push(match ch {
                '#' => 1.0,
                '.' => 0.0,
                other => {
                    return Err(format!(
                        "cutout.rows[{y}] has `{other}`; use `#` (kept) and `.` (cut)"
                    ))
                }
            });
        }
    }
    Ok(Cutout {
        width: width as u32,
        height: rows.len() as u32,
        alpha,
    })
}

/// A parallelogram `center ± u ± v` as two triangles facing `u × v`; the
/// texture runs from (0, 0) at `center - u - v` to (1, 1) at `center + u + v`.
fn quad(center: Vec3, u: Vec3, v: Vec3) -> Mesh {
    Mesh {
        name: String::new(),
        positions: vec![
            center - u - v,
            center + u - v,
            center + u + v,
            center - u + v,
        ],
        uvs: vec![
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ],
        indices: vec![0, 1, 2, 0, 2, 3],
    }
}

/// An axis-aligned box of half extents `h` centred at the origin, faces
/// outwards, two triangles per face, corners not shared between faces.
fn cuboid(h: Vec3) -> Mesh {
    let mut m = Mesh {
        name: String::new(),
        positions: Vec::new(),
        uvs: Vec::new(),
        indices: Vec::new(),
    };
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut n = Vec3::ZERO;
            n[axis] = sign;
            let mut u = Vec3::ZERO;
            u[(axis + 1) % 3] = h[(axis + 1) % 3];
            let mut v = Vec3::ZERO;
            v[(axis + 2) % 3] = h[(axis + 2) % 3];
            // u × v points along +axis; flip v for the negative face.
            let v = v * sign;
            let q = quad(n * h[axis], u, v);
            let base = m.positions.len() as u32;
            m.positions.extend(q.positions);
            m.uvs.extend(q.uvs);
            m.indices.extend(q.indices.iter().map(|i| i + base));
        }
    }
    m
}

/// A UV sphere of `segments` around and `rings` from pole to pole, faces
/// outwards (flat facets).
fn sphere(radius: f32, segments: u32, rings: u32) -> Mesh {
    let mut positions = Vec::new();
    let mut uvs = Vec::new();
    for r in 0..=rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..=segments {
            let phi = 2.0 * std::f32::consts::PI * (s % segments) as f32 / segments as f32;
            positions.push(Vec3::new(
                radius * theta.sin() * phi.cos(),
                radius * theta.cos(),
                -radius * theta.sin() * phi.sin(),
            ));
            uvs.push(Vec2::new(
                s as f32 / segments as f32,
                r as f32 / rings as f32,
            ));
        }
    }
    let row = segments + 1;
    let mut indices = Vec::new();
    for r in 0..rings {
        for s in 0..segments {
            let a = r * row + s;
            let b = a + 1;
            let c = a + row;
            let d = c + 1;
            // Skip the degenerate triangles at the poles.
            if r != 0 {
                indices.extend([a, c, b]);
            }
            if r != rings - 1 {
                indices.extend([b, c, d]);
            }
        }
    }
    Mesh {
        name: String::new(),
        positions,
        uvs,
        indices,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCENE: &str = r#"
        [camera]
        position = [0.0, 1.0, 4.0]
        [light]
        direction = [0.0, 2.0, 0.0]
        ambient = 0.2
        [[material]]
        name = "m"
        albedo = [0.5, 0.5, 0.5]
        metallic = 1.0
        [[mesh]]
        name = "ball"
        kind = "sphere"
        radius = 1.0
        [[mesh]]
        name = "crate"
        kind = "box"
        size = [1.0, 2.0, 3.0]
        [[instance]]
        mesh = "ball"
        material = "m"
        translate = [0.0, 0.0, -5.0]
        [[instance]]
        mesh = "crate"
        material = "m"
        rotate = [0.0, 90.0, 0.0]
    "#;

    #[test]
    fn meshes_face_outwards_and_instances_are_placed() {
        let s = Scene::parse("t", SCENE).unwrap();
        assert_eq!(s.light.unwrap().direction, Vec3::Y);
        let ball = &s.instances[0];
        let centre = Vec3::new(0.0, 0.0, -5.0);
        let n = s.meshes[ball.mesh].triangle_count();
        assert_eq!(n, 16 * 2 * 7);
        for t in 0..n {
            let tri = s.triangles[t];
            let mid = (tri.corners[0] + tri.corners[1] + tri.corners[2]) / 3.0;
            assert!(s.surfaces[t].normal.dot(mid - centre) > 0.0, "facet {t}");
            // Every facet edge borders a facet of another normal: all open.
            assert_eq!(tri.open, [true; 3]);
        }
        let first = s.instances[1].first_triangle as usize;
        assert_eq!(first, n);
        for t in first..s.triangle_count() {
            let tri = s.triangles[t];
            let mid = (tri.corners[0] + tri.corners[1] + tri.corners[2]) / 3.0;
            assert!(s.surfaces[t].normal.dot(mid) > 0.0, "box face {t}");
            // The face diagonal is shared: one closed edge per triangle.
            assert_eq!(tri.open.iter().filter(|&&o| !o).count(), 1);
        }
        // Rotated by 90° about y, the box's 3-unit depth lies along x.
        let max_x = s.triangles[first..]
            .iter()
            .flat_map(|t| t.corners)
            .map(|c| c.x)
            .fold(f32::MIN, f32::max);
        assert!((max_x - 1.5).abs() < 1e-5, "{max_x}");
    }

    #[test]
    fn bad_scenes_are_errors() {
        for (text, what) in [
            ("[camera]\nposition = [0, 0]", "3"),
            (
                "[camera]\nposition = [0.0, 0.0, 0.0]\n[[instance]]\nmesh = \"x\"\nmaterial = \"y\"",
                "unknown mesh `x`",
            ),
            ("[camera]\nposition = [0.0, 0.0, 0.0]", "no instance"),
            ("[camera]\nposition = [0.0, 0.0, 0.0]\nfov = 3", "unknown field"),
            (
                "[camera]\nposition = [0.0, 0.0, 0.0]\n[cutout]\nrows = [\"#.\", \"#\"]",
                "cutout.rows[1] is not 2 texels long",
            ),
            (
                "[camera]\nposition = [0.0, 0.0, 0.0]\n[cutout]\nrows = [\"#o\"]",
                "has `o`",
            ),
            (
                "[camera]\nposition = [0.0, 0.0, 0.0]\n[[material]]\nname = \"m\"\nalbedo = [1.0, 1.0, 1.0]\ncutout = true",
                "no [cutout] texture",
            ),
        ] {
            let e = Scene::parse("t", text).unwrap_err();
            assert!(e.contains(what), "{e}");
        }
    }

    #[test]
    fn a_cutout_texel_is_looked_up_at_the_interpolated_coordinate() {
        let c = cutout(&["#.".into(), "..".into()]).unwrap();
        assert!(c.keeps(Vec2::new(0.25, 0.25)));
        assert!(!c.keeps(Vec2::new(0.75, 0.25)));
        // Clamped to the texture: beyond (0, 0) is the corner texel.
        assert!(c.keeps(Vec2::new(-3.0, -1.0)));
        assert!(!c.keeps(Vec2::new(1.0, 1.0)));
        let q = quad(Vec3::ZERO, Vec3::X, Vec3::Y);
        let t = Triangle {
            corners: [0, 1, 2].map(|k| q.positions[q.indices[k] as usize]),
            open: [true; 3],
            uvs: [0, 1, 2].map(|k| q.uvs[q.indices[k] as usize]),
        };
        assert_eq!(t.uv([1.0, 0.0, 0.0]), Vec2::ZERO);
        assert_eq!(t.uv([0.0, 0.0, 1.0]), Vec2::ONE);
        assert_eq!(t.uv([0.5, 0.5, 0.0]), Vec2::new(0.5, 0.0));
    }

    #[test]
    fn flipping_turns_every_normal_around() {
        let s = Scene::parse("t", SCENE).unwrap();
        let f = s.with_flipped_normals();
        for (a, b) in s.surfaces.iter().zip(&f.surfaces) {
            assert!(
                (a.normal + b.normal).length() < 1e-5,
                "{} {}",
                a.normal,
                b.normal
            );
        }
    }

    #[test]
    fn translation_moves_camera_and_triangles() {
        let s = Scene::parse("t", SCENE).unwrap();
        let t = s.translated(Vec3::splat(1000.0));
        assert_eq!(t.camera, s.camera + Vec3::splat(1000.0));
        let d = t.triangles[5].corners[0] - s.triangles[5].corners[0];
        assert!((d - Vec3::splat(1000.0)).abs().max_element() < 1e-3);
    }
}
