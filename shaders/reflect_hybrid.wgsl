// Hybrid screen-space + ray-traced reflections in WGSL, two ray generation
// passes that verify runs in turn: `gbuffer_pass` traces the primary rays
// and writes, per pixel, position, view depth, facing normal, reflectivity,
// the surface's own light, roughness and albedo; `resolve_pass` marches
// each reflection over the G-buffer's depth (thickness test, confidence)
// and traces one ray only where the march misses, leaves the screen or is
// not confident. `paths` records which (0 none, 1 screen space, 2 ray).
// Depth 1: rays start in ray generation only. Same math as
// reflect_hybrid.hlsl (naga gives one miss shader, so shadow rays share it).
enable wgpu_ray_tracing_pipeline;
enable primitive_index;

struct Params {
    width: u32,
    height: u32,
    max_bounces: u32,
    // FLAG_LIGHT | FLAG_ROBUST
    flags: u32,
    camera: vec4<f32>,
    // xyz: unit direction towards the light, w: ambient
    light: vec4<f32>,
    // t_min, t_max, throughput cut-off, fixed origin epsilon
    ray: vec4<f32>,
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

struct GTexel {
    // xyz: where the primary ray hit; w: view depth, negative on a miss
    position_depth: vec4<f32>,
    // xyz: the normal facing the camera; w: reflectivity
    normal_reflectivity: vec4<f32>,
    // xyz: the surface's own light (the sky on a miss); w: roughness
    local_roughness: vec4<f32>,
    albedo: vec4<f32>,
}

@group(0) @binding(6) var<storage, read_write> paths: array<u32>;
@group(0) @binding(7) var<storage, read_write> gbuffer: array<GTexel>;

var<ray_payload> hit: HitInfo;
// Shadow rays get a payload of their own (only `t` is used).
var<ray_payload> shadow: HitInfo;
var<incoming_ray_payload> incoming: HitInfo;

const MISS_T: f32 = -1.0;
const PATH_NONE: u32 = 0u;
const PATH_SCREEN: u32 = 1u;
const PATH_RAY: u32 = 2u;
const SSR_STEPS: u32 = 64u;
const SSR_STEP: f32 = 0.1;
const SSR_THICKNESS: f32 = 0.25;
const SSR_MIN_CONFIDENCE: f32 = 0.5;
const FLAG_LIGHT: u32 = 1u;
const FLAG_ROBUST: u32 = 2u;
// Ray only: every reflection is traced, none marched (rtlint tradeoff).
const FLAG_RAY_ONLY: u32 = 4u;
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

fn camera_dir(id: vec2<u32>) -> vec3<f32> {
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id) + 0.5) / size * 2.0 - 1.0;
    return normalize(vec3<f32>(uv.x, -uv.y, -1.5));
}

fn facing(normal: vec3<f32>, dir: vec3<f32>) -> vec3<f32> {
    return select(-normal, normal, dot(normal, dir) < 0.0);
}

// The closest surface along a ray; t < 0 on a miss.
fn closest(origin: vec3<f32>, dir: vec3<f32>) -> HitInfo {
    hit = HitInfo(0.0, 0u);
    traceRay(tlas, RayDesc(RAY_FLAG_OPAQUE, 0xFFu, params.ray.x, params.ray.y, origin, dir), &hit);
    return hit;
}

// A surface's own light, as the iterative shader's first bounce: ambient,
// plus the light where the shadow ray from `start` reaches it; without a
// light, the headlight.
fn local_light(s: Surface, n: vec3<f32>, dir: vec3<f32>, start: vec3<f32>) -> vec3<f32> {
    let base = (1.0 - s.normal_reflectivity.w) * s.albedo_roughness.xyz;
    if (params.flags & FLAG_LIGHT) == 0u {
        return base * max(dot(n, -dir), 0.0);
    }
    var c = base * params.light.w;
    let ndl = dot(n, params.light.xyz);
    if ndl > 0.0 {
        shadow.t = 0.0;
        traceRay(tlas, RayDesc(SHADOW_FLAGS, 0xFFu, params.ray.x, params.ray.y, start, params.light.xyz), &shadow);
        if shadow.t < 0.0 {
            c += base * ndl;
        }
    }
    return c;
}

@ray_generation
fn gbuffer_pass(@builtin(ray_invocation_id) id: vec3<u32>) {
    let dir = camera_dir(id.xy);
    let h = closest(params.camera.xyz, dir);
    var g = GTexel(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    if h.t < 0.0 {
        g.position_depth = vec4<f32>(0.0, 0.0, 0.0, -1.0);
        g.local_roughness = vec4<f32>(sky(dir), 0.0);
    } else {
        let p = params.camera.xyz + dir * h.t;
        let n = facing(surfaces[h.surface].normal_reflectivity.xyz, dir);
        let local = local_light(surfaces[h.surface], n, dir, offset_ray(p, n));
        // The record is filled after the shadow ray, from the buffer,
        // rather than kept across it.
        let s = surfaces[h.surface];
        g.position_depth = vec4<f32>(p, -(p - params.camera.xyz).z);
        g.normal_reflectivity = vec4<f32>(n, s.normal_reflectivity.w);
        g.local_roughness = vec4<f32>(local, s.albedo_roughness.w);
        g.albedo = vec4<f32>(s.albedo_roughness.xyz, 0.0);
    }
    gbuffer[id.y * params.width + id.x] = g;
}

// What the march found: whether it is confident, and that texel's light.
struct Found {
    confident: bool,
    light: vec3<f32>,
}

// Marches from `p` along `r` in fixed steps, projecting each onto the
// screen: the first step behind the depth buffer by less than the
// thickness decides. Not confident when the march misses, leaves the
// screen, ends near the screen's edge or on a surface not facing the ray.
fn march(p: vec3<f32>, r: vec3<f32>) -> Found {
    let size = vec2<f32>(f32(params.width), f32(params.height));
    for (var i = 1u; i <= SSR_STEPS; i++) {
        let rel = p + r * (f32(i) * SSR_STEP) - params.camera.xyz;
        let z = -rel.z;
        if !(z > 1e-3) {
            break;
        }
        // The camera's projection: direction (u, -v, -1.5).
        let u = 1.5 * rel.x / z;
        let v = -1.5 * rel.y / z;
        let pixel = (vec2<f32>(u, v) + 1.0) * 0.5 * size;
        if !(pixel.x >= 0.0 && pixel.x < size.x && pixel.y >= 0.0 && pixel.y < size.y) {
            break;
        }
        let texel = vec2<u32>(pixel);
        let t = gbuffer[texel.y * params.width + texel.x];
        if t.position_depth.w < 0.0 {
            continue;
        }
        let behind = z - t.position_depth.w;
        if behind > 0.0 && behind < SSR_THICKNESS {
            let edge = clamp((1.0 - max(abs(u), abs(v))) * 8.0, 0.0, 1.0);
            let facing_ray = clamp(dot(t.normal_reflectivity.xyz, -r) * 4.0, 0.0, 1.0);
            return Found(min(edge, facing_ray) >= SSR_MIN_CONFIDENCE, t.local_roughness.xyz);
        }
    }
    return Found(false, vec3<f32>(0.0));
}

@ray_generation
fn resolve_pass(@builtin(ray_invocation_id) id: vec3<u32>) {
    let index = id.y * params.width + id.x;
    let g = gbuffer[index];
    var color = g.local_roughness.xyz;
    let reflectivity = g.normal_reflectivity.w;
    var path = PATH_NONE;
    if g.position_depth.w >= 0.0 && reflectivity > params.ray.z {
        let n = g.normal_reflectivity.xyz;
        let r = reflect(camera_dir(id.xy), n);
        var found = Found(false, vec3<f32>(0.0));
        if (params.flags & FLAG_RAY_ONLY) == 0u {
            found = march(g.position_depth.xyz, r);
        }
        var light = found.light;
        path = PATH_SCREEN;
        if !found.confident {
            path = PATH_RAY;
            let start = offset_ray(g.position_depth.xyz, n);
            let h = closest(start, r);
            if h.t < 0.0 {
                light = sky(r);
            } else {
                let hn = facing(surfaces[h.surface].normal_reflectivity.xyz, r);
                light = local_light(surfaces[h.surface], hn, r, offset_ray(start + r * h.t, hn));
            }
        }
        color += reflectivity * light;
    }
    paths[index] = path;
    image[index] = pack_rgba8(color);
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
