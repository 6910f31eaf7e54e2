//! The vector operations the reference needs, on glam's `Vec3`, written the
//! way the shaders' built-ins are defined (WGSL and HLSL agree on these).

pub use glam::Vec3;

/// WGSL `reflect(e, n)` / HLSL `reflect(i, n)`: `e - 2 * dot(n, e) * n`.
pub fn reflect(e: Vec3, n: Vec3) -> Vec3 {
    e - n * (2.0 * n.dot(e))
}

/// WGSL `mix(a, b, t)` / HLSL `lerp`: `a * (1 - t) + b * t`.
pub fn mix(a: Vec3, b: Vec3, t: f32) -> Vec3 {
    a * (1.0 - t) + b * t
}

/// Robust ray-origin constants of Wächter & Binder (Ray Tracing Gems, ch. 6).
pub const ROBUST_ORIGIN: f32 = 1.0 / 32.0;
pub const ROBUST_FLOAT_SCALE: f32 = 1.0 / 65536.0;
pub const ROBUST_INT_SCALE: f32 = 256.0;

/// Moves `p` off the surface with unit normal `n` (pointing to the side the
/// next ray leaves from) by a few ulps of each coordinate: the integer
/// representation of each float is offset by `256 × n` (sign following the
/// coordinate), and near the origin, where ulps are tiny, a fixed
/// `n / 65536` is added instead. The shaders' `offset_ray`, operation by
/// operation.
pub fn offset_ray(p: Vec3, n: Vec3) -> Vec3 {
    let of_i = n * ROBUST_INT_SCALE;
    let component = |p: f32, n: f32, of: f32| -> f32 {
        // `i32(x)` in WGSL and `int(x)` in HLSL truncate towards zero.
        let of = of as i32;
        let moved = f32::from_bits(
            (p.to_bits() as i32).wrapping_add(if p < 0.0 { -of } else { of }) as u32,
        );
        if p.abs() < ROBUST_ORIGIN {
            p + ROBUST_FLOAT_SCALE * n
        } else {
            moved
        }
    };
    Vec3::new(
        component(p.x, n.x, of_i.x),
        component(p.y, n.y, of_i.y),
        component(p.z, n.z, of_i.z),
    )
}

/// Where the ray meets the triangle's plane: `t` and the barycentric
/// coordinates `(w0, w1, w2)` of that point (all ≥ 0 inside), by
/// Möller–Trumbore. `None` when the ray is parallel to the plane.
pub fn ray_triangle(origin: Vec3, dir: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Option<(f32, [f32; 3])> {
    let e1 = b - a;
    let e2 = c - a;
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = origin - a;
    let u = s.dot(p) * inv;
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    let t = e2.dot(q) * inv;
    Some((t, [1.0 - u - v, u, v]))
}

/// World-space distance from the point with barycentrics `bary` to the
/// boundary of triangle `tri`, counting only the edges marked in `open`
/// (edge `i` is opposite vertex `i`). Coordinate `w_i` times vertex `i`'s
/// altitude is the signed distance to the opposite edge's line.
///
/// Inside, it is the distance to the nearest open edge. Outside across an
/// open edge, it is the largest violated distance (exact off an edge, a lower
/// bound off a corner). Outside across closed (shared) edges only, the point
/// lies in a neighbour that has the same surface, which answers for it:
/// infinity.
pub fn edge_distance(tri: [Vec3; 3], bary: [f32; 3], open: [bool; 3]) -> f32 {
    let twice_area = (tri[1] - tri[0]).cross(tri[2] - tri[0]).length();
    let signed: [f32; 3] = std::array::from_fn(|i| {
        let edge = (tri[(i + 2) % 3] - tri[(i + 1) % 3]).length();
        bary[i] * twice_area / edge
    });
    let inside = signed.iter().all(|&d| d >= 0.0);
    if inside {
        (0..3)
            .filter(|&i| open[i])
            .map(|i| signed[i])
            .fold(f32::INFINITY, f32::min)
    } else if (0..3).any(|i| open[i] && signed[i] < 0.0) {
        signed.iter().map(|&d| -d).fold(0.0, f32::max)
    } else {
        f32::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn robust_offset_moves_a_few_ulps_away_from_the_origin() {
        let p = Vec3::new(1000.0, -1000.0, 0.01);
        let n = Vec3::new(0.0, 1.0, 0.0);
        let q = offset_ray(p, n);
        assert_eq!(q.x, p.x, "no offset along x");
        // y < 0: the integer offset is subtracted, moving -1000 towards 0 (up).
        // 256 ulps of 1000 (6.1e-5 each).
        assert!(q.y > p.y && q.y - p.y < 0.02, "{}", q.y - p.y);
        assert_eq!(q.y.to_bits(), p.y.to_bits() - 256);
        // Near 0 the fixed float offset applies.
        assert_eq!(q.z, p.z);
        let q = offset_ray(Vec3::ZERO, n);
        assert_eq!(q, Vec3::new(0.0, 1.0 / 65536.0, 0.0));
    }

    #[test]
    fn reflect_and_mix_follow_the_builtins() {
        let r = reflect(Vec3::new(1.0, -1.0, 0.0), Vec3::Y);
        assert_eq!(r, Vec3::new(1.0, 1.0, 0.0));
        assert_eq!(mix(Vec3::ZERO, Vec3::ONE, 0.25), Vec3::splat(0.25));
    }
}
