// Casts one ray query per input ray and records what the acceleration
// structure reported: the committed hit, and how many AABB candidates it
// offered (procedural geometry needs the shader to decide, so none is
// committed here). `var rq` sits at the top of the function: naga 30 emits
// invalid SPIR-V for a ray query declared inside a loop.
enable wgpu_ray_query;

struct Ray {
    origin_tmin: vec4<f32>,
    dir_tmax: vec4<f32>,
    // x = ray flags, y = cull mask.
    flags_mask: vec4<u32>,
}

struct Params {
    count: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var tlas: acceleration_structure;
@group(0) @binding(1) var<storage, read> rays: array<Ray>;
// Three per ray: (kind, primitive, custom index, instance),
// (geometry, SBT offset, AABB candidates, last candidate's custom index),
// (bits of t, last candidate's SBT offset, 0, 0).
@group(0) @binding(2) var<storage, read_write> hits: array<vec4<u32>>;
@group(0) @binding(3) var<uniform> params: Params;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    var rq: ray_query;
    let i = gid.x;
    if i >= params.count {
        return;
    }
    let r = rays[i];
    rayQueryInitialize(&rq, tlas, RayDesc(r.flags_mask.x, r.flags_mask.y, r.origin_tmin.w, r.dir_tmax.w, r.origin_tmin.xyz, r.dir_tmax.xyz));
    var aabbs = 0u;
    var aabb_custom = 0xFFFFFFFFu;
    var aabb_sbt = 0xFFFFFFFFu;
    while rayQueryProceed(&rq) {
        let c = rayQueryGetCandidateIntersection(&rq);
        if c.kind == RAY_QUERY_INTERSECTION_AABB {
            aabbs += 1u;
            aabb_custom = c.instance_custom_data;
            aabb_sbt = c.sbt_record_offset;
        }
    }
    let h = rayQueryGetCommittedIntersection(&rq);
    hits[i * 3u] = vec4<u32>(h.kind, h.primitive_index, h.instance_custom_data, h.instance_index);
    hits[i * 3u + 1u] = vec4<u32>(h.geometry_index, h.sbt_record_offset, aabbs, aabb_custom);
    hits[i * 3u + 2u] = vec4<u32>(bitcast<u32>(h.t), aabb_sbt, 0u, 0u);
}
