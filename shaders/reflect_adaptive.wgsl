// Adaptive sampling in WGSL: the glossy GGX path of reflect_glossy.wgsl,
// accumulated over passes. verify runs the ray generation shader once per
// pass, as many passes as the most paths per pixel (16 by default); each
// pass a pixel traces one more path while it has fewer than the fewest
// (4 by default), or fewer than the most and a variance estimate of its
// mean's luminance above the tolerance (params.camera.w, 0.001 by
// default). `counts` gets the paths each pixel traced; `state` keeps the
// sums between passes. Same math as reflect_adaptive.hlsl.
enable wgpu_ray_tracing_pipeline;
enable primitive_index;

struct Params {
    width: u32,
    height: u32,
    max_bounces: u32,
    // FLAG_LIGHT | FLAG_ROBUST | samples << 8
    flags: u32,
    camera: vec4<f32>,
    // xyz: unit direction towards the light, w: ambient
    light: vec4<f32>,
    // t_min, t_max, throughput cut-off, fixed origin epsilon
    ray: vec4<f32>,
    // xyz: the glossy shader's (unread here); w: the bits of a u32, the
    // fewest paths per pixel | the most << 16
    knobs: vec4<f32>,
}

// One entry per triangle (instance custom index + primitive index):
// xyz = world-space geometric normal, w = reflectivity.
struct Surface {
    normal_reflectivity: vec4<f32>,
    albedo_roughness: vec4<f32>,
}

// What the closest hit reports: the distance and the surface's index; the
// ray generation shader reads the surface itself.
struct HitInfo {
    t: f32,
    surface: u32,
}

@group(0) @binding(0) var tlas: acceleration_structure;
@group(0) @binding(1) var<storage, read_write> image: array<u32>;
@group(0) @binding(2) var<storage, read> surfaces: array<Surface>;
@group(0) @binding(3) var<uniform> params: Params;

struct Accumulator {
    // xyz: the paths' light summed; w: how many (the bits of a u32)
    sum_samples: vec4<f32>,
    // x: luminance summed, y: its squares summed
    luminance: vec4<f32>,
    unused0: vec4<f32>,
    unused1: vec4<f32>,
}

@group(0) @binding(6) var<storage, read_write> counts: array<u32>;
@group(0) @binding(7) var<storage, read_write> state: array<Accumulator>;

var<ray_payload> hit: HitInfo;
// Shadow rays get a payload of their own (only `t` is used).
var<ray_payload> shadow: HitInfo;
var<incoming_ray_payload> incoming: HitInfo;

const MISS_T: f32 = -1.0;
const LUMINANCE: vec3<f32> = vec3<f32>(0.2126, 0.7152, 0.0722);
const FLAG_LIGHT: u32 = 1u;
const FLAG_ROBUST: u32 = 2u;
const RAY_FLAG_OPAQUE: u32 = 0x01u;
// OPAQUE | ACCEPT_FIRST_HIT_AND_END_SEARCH | SKIP_CLOSEST_HIT_SHADER
const SHADOW_FLAGS: u32 = 0x0Du;

fn sky(dir: vec3<f32>) -> vec3<f32> {
    let k = 0.5 * (dir.y + 1.0);
    return mix(vec3<f32>(1.0, 1.0, 1.0), vec3<f32>(0.5, 0.7, 1.0), k);
}

// RGBA8 with alpha 255; a colour with an infinite or NaN channel is written
// as 0 (alpha 0), so the image counts them. The exponent bits are tested:
// a compiler may assume no NaN in `c != c`.
fn pack_rgba8(c: vec3<f32>) -> u32 {
    if any((bitcast<vec3<u32>>(c) & vec3<u32>(0x7F800000u)) == vec3<u32>(0x7F800000u)) {
        return 0u;
    }
    let v = vec3<u32>(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0 + 0.5);
    return v.x | (v.y << 8u) | (v.z << 16u) | (255u << 24u);
}

// Wächter & Binder, Ray Tracing Gems ch. 6: move the origin a few ulps
// along the normal; a fixed epsilon when FLAG_ROBUST is off.
fn offset_ray(p: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    if (params.flags & FLAG_ROBUST) == 0u {
        return p + n * params.ray.w;
    }
    let of_i = vec3<i32>(256.0 * n);
    let p_i = bitcast<vec3<f32>>(bitcast<vec3<i32>>(p) + select(of_i, -of_i, p < vec3<f32>(0.0)));
    return select(p_i, p + (1.0 / 65536.0) * n, abs(p) < vec3<f32>(1.0 / 32.0));
}

// PCG hash (Jarzynski & Olano 2020).
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// A uniform number in [0, 1) with 24 bits, advancing the seed.
fn rand(seed: ptr<function, u32>) -> f32 {
    *seed = pcg(*seed);
    return f32(*seed >> 8u) * (1.0 / 16777216.0);
}

// A GGX visible normal for the view `ve` (tangent space, z up) and roughness
// `alpha` (Heitz 2018). alpha = 0 gives the normal itself; a view along the
// normal (lensq = 0) gets any tangent.
fn sample_vndf(ve: vec3<f32>, alpha: f32, u1: f32, u2: f32) -> vec3<f32> {
    // A grazing view (ve.z = 0) with alpha = 0 would normalise zero.
    let vh = normalize(vec3<f32>(alpha * ve.x, alpha * ve.y, max(ve.z, 1e-7)));
    let lensq = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3<f32>(1.0, 0.0, 0.0);
    if lensq > 0.0 {
        t1 = vec3<f32>(-vh.y, vh.x, 0.0) * inverseSqrt(lensq);
    }
    let t2 = cross(vh, t1);
    let r = sqrt(u1);
    let phi = 6.2831855 * u2;
    let p1 = r * cos(phi);
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * sqrt(1.0 - p1 * p1) + s * (r * sin(phi));
    let nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(vec3<f32>(alpha * nh.x, alpha * nh.y, max(0.0, nh.z)));
}

// Path number `sample` of pixel `id`: its light is added into `sum` term
// by term (the rounding, which the CPU follows, depends on it).
fn glossy_sample(id: vec2<u32>, sample: u32, sum: ptr<function, vec3<f32>>) {
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id) + 0.5) / size * 2.0 - 1.0;
    var seed = pcg(id.y * params.width + id.x) ^ pcg(sample + 0x9E3779B9u);
    var origin = params.camera.xyz;
    var dir = normalize(vec3<f32>(uv.x, -uv.y, -1.5));
    var t_max = params.ray.y;
    var throughput = 1.0;
    for (var bounce = 0u; bounce <= params.max_bounces; bounce++) {
        traceRay(tlas, RayDesc(RAY_FLAG_OPAQUE, 0xFFu, params.ray.x, t_max, origin, dir), &hit);
        if hit.t < 0.0 {
            *sum += throughput * sky(dir);
            break;
        }
        // The shadow ray first, from the next origin: across it only the
        // path's own state stays live; the surface is read again after it.
        let normal = surfaces[hit.surface].normal_reflectivity.xyz;
        var n = select(-normal, normal, dot(normal, dir) < 0.0);
        origin = offset_ray(origin + dir * hit.t, n);
        var visible = false;
        if (params.flags & FLAG_LIGHT) != 0u && dot(n, params.light.xyz) > 0.0 {
            shadow.t = 0.0;
            traceRay(tlas, RayDesc(SHADOW_FLAGS, 0xFFu, params.ray.x, params.ray.y, origin, params.light.xyz), &shadow);
            visible = shadow.t < 0.0;
        }
        let s = surfaces[hit.surface];
        n = select(-s.normal_reflectivity.xyz, s.normal_reflectivity.xyz, dot(s.normal_reflectivity.xyz, dir) < 0.0);
        let base = throughput * (1.0 - s.normal_reflectivity.w) * s.albedo_roughness.xyz;
        throughput *= s.normal_reflectivity.w;
        let roughness = s.albedo_roughness.w;
        let ndl = dot(n, params.light.xyz);
        let headlight = max(dot(n, -dir), 0.0);
        if roughness > 0.0 {
            // Tangent frame (Duff et al. 2017), the view in it, a
            // visible normal, and the reflection about it weighted by
            // the masking of the outgoing direction, G1(l).
            let sgn = select(-1.0, 1.0, n.z >= 0.0);
            let a = -1.0 / (sgn + n.z);
            let b = n.x * n.y * a;
            let tx = vec3<f32>(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
            let ty = vec3<f32>(b, sgn + n.y * n.y * a, -n.y);
            let alpha = roughness * roughness;
            let ve = vec3<f32>(dot(-dir, tx), dot(-dir, ty), dot(-dir, n));
            let m = sample_vndf(ve, alpha, rand(&seed), rand(&seed));
            dir = reflect(dir, tx * m.x + ty * m.y + n * m.z);
            let nl = dot(n, dir);
            if nl > 0.0 {
                let a2 = alpha * alpha;
                throughput *= 2.0 * nl / (nl + sqrt(a2 + (1.0 - a2) * nl * nl));
            } else {
                throughput = 0.0;
            }
            t_max = params.ray.y / (1.0 + 64.0 * roughness);
        } else {
            dir = reflect(dir, n);
            t_max = params.ray.y;
        }
        if (params.flags & FLAG_LIGHT) != 0u {
            *sum += base * params.light.w;
            if ndl > 0.0 && visible {
                *sum += base * ndl;
            }
        } else {
            *sum += base * headlight;
        }
        if !(throughput > params.ray.z) {
            break;
        }
    }
}

@ray_generation
fn raygen(@builtin(ray_invocation_id) id: vec3<u32>) {
    let index = id.y * params.width + id.x;
    var acc = state[index];
    var n = bitcast<u32>(acc.sum_samples.w);
    let paths = bitcast<u32>(params.knobs.w);
    var more = n < (paths & 0xFFFFu);
    if !more && n < (paths >> 16u) {
        let mean = acc.luminance.x / f32(n);
        let variance = max(acc.luminance.y / f32(n) - mean * mean, 0.0);
        more = variance / f32(n) > params.camera.w;
    }
    if more {
        var c = vec3<f32>(0.0);
        glossy_sample(id.xy, n, &c);
        let l = dot(c, LUMINANCE);
        n += 1u;
        acc.sum_samples = vec4<f32>(acc.sum_samples.xyz + c, bitcast<f32>(n));
        acc.luminance.x += l;
        acc.luminance.y += l * l;
        state[index] = acc;
    }
    counts[index] = n;
    image[index] = pack_rgba8(acc.sum_samples.xyz / f32(max(n, 1u)));
}

@miss
@incoming_payload(incoming)
fn miss() {
    incoming.t = MISS_T;
}

@closest_hit
@incoming_payload(incoming)
fn closest_hit(
    @builtin(instance_custom_data) first: u32,
    @builtin(primitive_index) prim: u32,
    @builtin(ray_t_current_max) t: f32,
) {
    incoming.t = t;
    incoming.surface = first + prim;
}
