// Mirror reflections with inline ray queries in a compute shader: no shader
// binding table and no ray stack. Same scene, camera, shading, shadow rays
// and ray origins as reflect_iterative.wgsl; the image must be the same.
// `main` is for scenes without cut-outs (every candidate forced opaque, no
// texture bound); `main_alpha` handles non-opaque candidates in its Proceed
// loops: the alpha test, then the commit.
enable wgpu_ray_query;

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

struct Surface {
    normal_reflectivity: vec4<f32>,
    albedo_roughness: vec4<f32>,
}

@group(0) @binding(0) var tlas: acceleration_structure;
@group(0) @binding(1) var<storage, read_write> image: array<u32>;
@group(0) @binding(2) var<storage, read> surfaces: array<Surface>;
@group(0) @binding(3) var<uniform> params: Params;

// Alpha-tested cut-outs, bound only for scenes that have them: the alpha
// texture and, per triangle, its corners' texture coordinates and the
// texture's size (0 × 0: not tested).
struct Cutout {
    // u0 v0 u1 v1
    uv01: vec4<f32>,
    // u2 v2, texture width and height
    uv2_size: vec4<f32>,
}

@group(0) @binding(4) var alpha_texture: texture_2d<f32>;
@group(0) @binding(5) var<storage, read> cutouts: array<Cutout>;

const FLAG_LIGHT: u32 = 1u;
const FLAG_ROBUST: u32 = 2u;
const RAY_FLAG_OPAQUE: u32 = 0x01u;
// OPAQUE | ACCEPT_FIRST_HIT_AND_END_SEARCH
const SHADOW_FLAGS: u32 = 0x05u;
const RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH: u32 = 0x04u;

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

// Whether triangle `index` is there at barycentrics `bary` (the weights of
// corners 1 and 2): the one texel under the interpolated coordinate.
fn alpha_keeps(index: u32, bary: vec2<f32>) -> bool {
    let c = cutouts[index];
    let size = c.uv2_size.zw;
    if size.x == 0.0 {
        return true;
    }
    let uv = c.uv01.xy + bary.x * (c.uv01.zw - c.uv01.xy) + bary.y * (c.uv2_size.xy - c.uv01.xy);
    let texel = min(vec2<u32>(clamp(uv, vec2<f32>(0.0), vec2<f32>(1.0)) * size), vec2<u32>(size) - 1u);
    return textureLoad(alpha_texture, texel, 0).a >= 0.5;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id.xy) + 0.5) / size * 2.0 - 1.0;
    var origin = params.camera.xyz;
    var dir = normalize(vec3<f32>(uv.x, -uv.y, -1.5));
    var color = vec3<f32>(0.0);
    var throughput = 1.0;
    // Declared once, outside the loop: naga 30 emits invalid SPIR-V for a
    // ray query declared inside a loop body (rule RT005).
    var rq: ray_query;
    for (var bounce = 0u; bounce <= params.max_bounces; bounce++) {
        rayQueryInitialize(&rq, tlas, RayDesc(RAY_FLAG_OPAQUE, 0xFFu, params.ray.x, params.ray.y, origin, dir));
        // Every candidate is opaque here (the flag forces it), so Proceed
        // commits the closest triangle by itself.
        while rayQueryProceed(&rq) {
        }
        let hit = rayQueryGetCommittedIntersection(&rq);
        if hit.kind == RAY_QUERY_INTERSECTION_NONE {
            color += throughput * sky(dir);
            break;
        }
        let s = surfaces[hit.instance_custom_data + hit.primitive_index];
        let normal = s.normal_reflectivity.xyz;
        let reflectivity = s.normal_reflectivity.w;
        let n = select(-normal, normal, dot(normal, dir) < 0.0);
        let base = throughput * (1.0 - reflectivity) * s.albedo_roughness.xyz;
        throughput *= reflectivity;
        origin = offset_ray(origin + dir * hit.t, n);
        let ndl = dot(n, params.light.xyz);
        let headlight = max(dot(n, -dir), 0.0);
        dir = reflect(dir, n);
        if (params.flags & FLAG_LIGHT) != 0u {
            color += base * params.light.w;
            if ndl > 0.0 {
                rayQueryInitialize(&rq, tlas, RayDesc(SHADOW_FLAGS, 0xFFu, params.ray.x, params.ray.y, origin, params.light.xyz));
                while rayQueryProceed(&rq) {
                }
                if rayQueryGetCommittedIntersection(&rq).kind == RAY_QUERY_INTERSECTION_NONE {
                    color += base * ndl;
                }
            }
        } else {
            color += base * headlight;
        }
        if !(throughput > params.ray.z) {
            break;
        }
    }
    image[id.y * params.width + id.x] = pack_rgba8(color);
}

@compute @workgroup_size(8, 8)
fn main_alpha(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id.xy) + 0.5) / size * 2.0 - 1.0;
    var origin = params.camera.xyz;
    var dir = normalize(vec3<f32>(uv.x, -uv.y, -1.5));
    var color = vec3<f32>(0.0);
    var throughput = 1.0;
    // Declared once, outside the loop: naga 30 emits invalid SPIR-V for a
    // ray query declared inside a loop body (rule RT005).
    var query: ray_query;
    for (var bounce = 0u; bounce <= params.max_bounces; bounce++) {
        rayQueryInitialize(&query, tlas, RayDesc(0u, 0xFFu, params.ray.x, params.ray.y, origin, dir));
        // Opaque triangles commit by themselves; a cut-out's triangles come
        // back as candidates, committed where their alpha texel keeps them.
        // (naga takes no ray query as a function argument.)
        while rayQueryProceed(&query) {
            let c = rayQueryGetCandidateIntersection(&query);
            if c.kind == RAY_QUERY_INTERSECTION_TRIANGLE && alpha_keeps(c.instance_custom_data + c.primitive_index, c.barycentrics) {
                rayQueryConfirmIntersection(&query);
            }
        }
        let hit = rayQueryGetCommittedIntersection(&query);
        if hit.kind == RAY_QUERY_INTERSECTION_NONE {
            color += throughput * sky(dir);
            break;
        }
        let s = surfaces[hit.instance_custom_data + hit.primitive_index];
        let normal = s.normal_reflectivity.xyz;
        let reflectivity = s.normal_reflectivity.w;
        let n = select(-normal, normal, dot(normal, dir) < 0.0);
        let base = throughput * (1.0 - reflectivity) * s.albedo_roughness.xyz;
        throughput *= reflectivity;
        origin = offset_ray(origin + dir * hit.t, n);
        let ndl = dot(n, params.light.xyz);
        let headlight = max(dot(n, -dir), 0.0);
        dir = reflect(dir, n);
        if (params.flags & FLAG_LIGHT) != 0u {
            color += base * params.light.w;
            if ndl > 0.0 {
                // The first kept candidate ends the search.
                rayQueryInitialize(&query, tlas, RayDesc(RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH, 0xFFu, params.ray.x, params.ray.y, origin, params.light.xyz));
                while rayQueryProceed(&query) {
                    let c = rayQueryGetCandidateIntersection(&query);
                    if c.kind == RAY_QUERY_INTERSECTION_TRIANGLE && alpha_keeps(c.instance_custom_data + c.primitive_index, c.barycentrics) {
                        rayQueryConfirmIntersection(&query);
                    }
                }
                if rayQueryGetCommittedIntersection(&query).kind == RAY_QUERY_INTERSECTION_NONE {
                    color += base * ndl;
                }
            }
        } else {
            color += base * headlight;
        }
        if !(throughput > params.ray.z) {
            break;
        }
    }
    image[id.y * params.width + id.x] = pack_rgba8(color);
}
