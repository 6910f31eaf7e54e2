//! The few `f32` vector operations the reference needs, written the way the
//! shader's built-ins are defined.

pub type Vec3 = [f32; 3];

pub fn dot(a: Vec3, b: Vec3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

pub fn scale(a: Vec3, k: f32) -> Vec3 {
    [a[0] * k, a[1] * k, a[2] * k]
}

pub fn length(a: Vec3) -> f32 {
    dot(a, a).sqrt()
}

pub fn normalize(a: Vec3) -> Vec3 {
    scale(a, 1.0 / length(a))
}

/// WGSL `reflect(e, n)`: `e - 2 * dot(n, e) * n`.
pub fn reflect(e: Vec3, n: Vec3) -> Vec3 {
    let k = 2.0 * dot(n, e);
    [e[0] - k * n[0], e[1] - k * n[1], e[2] - k * n[2]]
}

/// WGSL `mix(a, b, t)`: `a * (1 - t) + b * t`.
pub fn mix(a: Vec3, b: Vec3, t: f32) -> Vec3 {
    [
        a[0] * (1.0 - t) + b[0] * t,
        a[1] * (1.0 - t) + b[1] * t,
        a[2] * (1.0 - t) + b[2] * t,
    ]
}

/// Where the ray meets the triangle's plane: `t` and the barycentric
/// coordinates `(w0, w1, w2)` of that point (all ≥ 0 inside), by
/// Möller–Trumbore. `None` when the ray is parallel to the plane.
pub fn ray_triangle(origin: Vec3, dir: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Option<(f32, [f32; 3])> {
    let e1 = sub(b, a);
    let e2 = sub(c, a);
    let p = cross(dir, e2);
    let det = dot(e1, p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = sub(origin, a);
    let u = dot(s, p) * inv;
    let q = cross(s, e1);
    let v = dot(dir, q) * inv;
    let t = dot(e2, q) * inv;
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
    let twice_area = length(cross(sub(tri[1], tri[0]), sub(tri[2], tri[0])));
    let signed: Vec<f32> = (0..3)
        .map(|i| {
            let edge = length(sub(tri[(i + 2) % 3], tri[(i + 1) % 3]));
            bary[i] * twice_area / edge
        })
        .collect();
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
