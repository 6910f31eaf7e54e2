// Mirror reflections with inline ray queries in a compute shader: no shader
// binding table and no ray stack. Same scene, camera and shading as
// reflect_iterative.wgsl.
enable wgpu_ray_query;

struct Params {
    width: u32,
    height: u32,
    max_bounces: u32,
    _pad: u32,
}

struct Surface {
    normal_reflectivity: vec4<f32>,
    albedo: vec4<f32>,
}

@group(0) @binding(0) var tlas: acceleration_structure;
@group(0) @binding(1) var<storage, read_write> image: array<u32>;
@group(0) @binding(2) var<storage, read> surfaces: array<Surface>;
@group(0) @binding(3) var<uniform> params: Params;

fn sky(dir: vec3<f32>) -> vec3<f32> {
    let k = 0.5 * (dir.y + 1.0);
    return mix(vec3<f32>(1.0, 1.0, 1.0), vec3<f32>(0.5, 0.7, 1.0), k);
}

fn pack_rgba8(c: vec3<f32>) -> u32 {
    let v = vec3<u32>(clamp(c, vec3<f32>(0.0), vec3<f32>(1.0)) * 255.0 + 0.5);
    return v.x | (v.y << 8u) | (v.z << 16u) | (255u << 24u);
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.width || id.y >= params.height {
        return;
    }
    let size = vec2<f32>(f32(params.width), f32(params.height));
    let uv = (vec2<f32>(id.xy) + 0.5) / size * 2.0 - 1.0;
    var origin = vec3<f32>(0.0, 1.0, 4.0);
    var dir = normalize(vec3<f32>(uv.x, -uv.y, -1.5));
    var color = vec3<f32>(0.0);
    var throughput = vec3<f32>(1.0);
    // Declared once, outside the loop: naga 30 emits invalid SPIR-V for a
    // ray query declared inside a loop body (rule RT005).
    var rq: ray_query;
    for (var bounce = 0u; bounce <= params.max_bounces; bounce++) {
        rayQueryInitialize(&rq, tlas, RayDesc(0x01u, 0xFFu, 0.001, 100.0, origin, dir));
        rayQueryProceed(&rq);
        let hit = rayQueryGetCommittedIntersection(&rq);
        if hit.kind == RAY_QUERY_INTERSECTION_NONE {
            color += throughput * sky(dir);
            break;
        }
        let s = surfaces[hit.primitive_index];
        let normal = s.normal_reflectivity.xyz;
        let reflectivity = s.normal_reflectivity.w;
        let shade = max(dot(normal, -dir), 0.0);
        color += throughput * s.albedo.xyz * shade * (1.0 - reflectivity);
        throughput *= reflectivity;
        if reflectivity <= 0.0 {
            break;
        }
        origin = origin + dir * hit.t + normal * 0.001;
        dir = reflect(dir, normal);
    }
    image[id.y * params.width + id.x] = pack_rgba8(color);
}
