//! A bounding-volume hierarchy over the scene's world-space triangles:
//! median splits on the longest axis of the centroids, up to four triangles a
//! leaf. Simple, and a ray visits O(log n) nodes instead of every triangle.

use super::scene::Triangle;
use glam::Vec3;

/// Boxes are grown by this much (world units, plus a relative part) so that
/// rays passing within the edge-margin distance of a triangle still visit it.
const PAD: f32 = 1e-3;
const LEAF: usize = 4;

#[derive(Clone, Copy, Debug, Default)]
struct Node {
    min: Vec3,
    max: Vec3,
    /// Leaf: the range `first..first + count` of `order`; inner: `count` is 0
    /// and the children are `first` and `first + 1`.
    first: u32,
    count: u32,
}

#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Triangle indices, leaves' ranges point into it.
    order: Vec<u32>,
}

impl Bvh {
    pub fn build(triangles: &[Triangle]) -> Bvh {
        let mut bvh = Bvh {
            nodes: Vec::with_capacity(triangles.len() * 2),
            order: (0..triangles.len() as u32).collect(),
        };
        if triangles.is_empty() {
            return bvh;
        }
        let centroid = |t: u32| {
            let c = triangles[t as usize].corners;
            (c[0] + c[1] + c[2]) / 3.0
        };
        bvh.nodes.push(Node::default());
        let mut work = vec![(0usize, 0usize, triangles.len())];
        while let Some((node, lo, hi)) = work.pop() {
            let (mut min, mut max) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
            for &t in &bvh.order[lo..hi] {
                for c in triangles[t as usize].corners {
                    min = min.min(c);
                    max = max.max(c);
                }
            }
            let pad = Vec3::splat(PAD) + (min.abs().max(max.abs())) * 1e-6;
            bvh.nodes[node].min = min - pad;
            bvh.nodes[node].max = max + pad;
            if hi - lo <= LEAF {
                bvh.nodes[node].first = lo as u32;
                bvh.nodes[node].count = (hi - lo) as u32;
                continue;
            }
            let (mut cmin, mut cmax) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
            for &t in &bvh.order[lo..hi] {
                cmin = cmin.min(centroid(t));
                cmax = cmax.max(centroid(t));
            }
            let axis = (cmax - cmin).max_position();
            let mid = (lo + hi) / 2;
            bvh.order[lo..hi].select_nth_unstable_by(mid - lo, |&a, &b| {
                centroid(a)[axis].total_cmp(&centroid(b)[axis])
            });
            let left = bvh.nodes.len();
            bvh.nodes.push(Node::default());
            bvh.nodes.push(Node::default());
            bvh.nodes[node].first = left as u32;
            bvh.nodes[node].count = 0;
            work.push((left, lo, mid));
            work.push((left + 1, mid, hi));
        }
        bvh
    }

    /// Calls `visit` with every triangle whose (padded) box the ray
    /// `origin + t·dir`, `t` in `[t_min, t_max]`, passes through.
    pub fn candidates(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_min: f32,
        t_max: f32,
        mut visit: impl FnMut(usize),
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let inv = dir.recip();
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            let node = &self.nodes[n];
            if !slab(origin, inv, node.min, node.max, t_min, t_max) {
                continue;
            }
            if node.count > 0 {
                let range = node.first as usize..(node.first + node.count) as usize;
                for &t in &self.order[range] {
                    visit(t as usize);
                }
            } else {
                stack.push(node.first as usize);
                stack.push(node.first as usize + 1);
            }
        }
    }
}

/// Whether the ray meets the box within `[t_min, t_max]`. Components of
/// `inv` may be infinite (axis-parallel rays); NaN from `0 × ∞` is treated
/// as "inside the slab".
fn slab(origin: Vec3, inv: Vec3, min: Vec3, max: Vec3, t_min: f32, t_max: f32) -> bool {
    let (mut lo, mut hi) = (t_min, t_max);
    for a in 0..3 {
        let t0 = (min[a] - origin[a]) * inv[a];
        let t1 = (max[a] - origin[a]) * inv[a];
        let (near, far) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
        if near.is_nan() || far.is_nan() {
            if origin[a] < min[a] || origin[a] > max[a] {
                return false;
            }
            continue;
        }
        lo = lo.max(near);
        hi = hi.min(far);
    }
    lo <= hi
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(x: f32) -> Triangle {
        Triangle {
            corners: [
                Vec3::new(x, 0.0, 0.0),
                Vec3::new(x + 0.5, 0.0, 0.0),
                Vec3::new(x, 0.5, 0.0),
            ],
            open: [true; 3],
            uvs: [glam::Vec2::ZERO; 3],
        }
    }

    #[test]
    fn a_ray_visits_only_nearby_triangles() {
        let tris: Vec<Triangle> = (0..100).map(|i| tri(i as f32)).collect();
        let bvh = Bvh::build(&tris);
        let mut seen = Vec::new();
        bvh.candidates(
            Vec3::new(42.1, 0.1, 1.0),
            Vec3::new(0.0, 0.0, -1.0),
            0.0,
            f32::INFINITY,
            |t| seen.push(t),
        );
        assert!(seen.contains(&42), "{seen:?}");
        assert!(seen.len() <= 8, "{seen:?}");
        // Every triangle is in exactly one leaf.
        let mut all = bvh.order.clone();
        all.sort();
        assert_eq!(all, (0..100).collect::<Vec<u32>>());
    }
}
