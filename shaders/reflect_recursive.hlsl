// Recursive mirror reflections in HLSL, compiled by rtlint's own compiler:
// the closest-hit shader traces the reflected ray itself, and a shadow ray
// (miss index 1, its own payload) when the scene has a light, so the
// pipeline needs recursion depth max_bounces + 2. Same math as
// reflect_recursive.wgsl; the image must equal the iterative one. Cut-outs:
// the any-hit shaders ignore candidates whose alpha texel is cut away.
#include "reflect_shadow.hlsli"

// Radiance gathered along the ray, how many bounces led to it, and the
// product of the reflectivities on the way.
struct Radiance
{
    float3 color;
    uint depth;
    float throughput;
};

[shader("raygeneration")]
void raygen()
{
    uint2 id = DispatchRaysIndex().xy;
    RayDesc ray;
    ray.Origin = params.camera.xyz;
    ray.Direction = camera_dir(id);
    ray.TMin = params.ray.x;
    ray.TMax = params.ray.y;
    Radiance r;
    r.color = float3(0.0, 0.0, 0.0);
    r.depth = 0;
    r.throughput = 1.0;
    TraceRay(tlas, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, r);
    image[id.y * params.width + id.x] = pack_rgba8(r.color);
}

[shader("miss")]
void miss(inout Radiance r)
{
    r.color = sky(WorldRayDirection());
}

[shader("closesthit")]
void closest_hit(inout Radiance r, in BuiltInTriangleIntersectionAttributes attr)
{
    Surface s = surfaces[InstanceID() + PrimitiveIndex()];
    float3 dir = WorldRayDirection();
    float reflectivity = s.normal_reflectivity.w;
    float3 n = select(dot(s.normal_reflectivity.xyz, dir) < 0.0, s.normal_reflectivity.xyz, -s.normal_reflectivity.xyz);
    float3 base = (1.0 - reflectivity) * s.albedo_roughness.xyz;
    float3 start = offset_ray(WorldRayOrigin() + dir * RayTCurrent(), n);
    float3 color;
    if ((params.flags & FLAG_LIGHT) != 0)
    {
        float ndl = dot(n, params.light.xyz);
        color = base * params.light.w;
        if (ndl > 0.0 && shadow_ray(start) > 0.0)
            color += base * ndl;
    }
    else
    {
        color = base * max(dot(n, -dir), 0.0);
    }
    // The guard that bounds the recursion: depth grows by one per level.
    if (r.depth < params.max_bounces)
    {
        float next = r.throughput * reflectivity;
        if (next > params.ray.z)
        {
            RayDesc ray;
            ray.Origin = start;
            ray.Direction = reflect(dir, n);
            ray.TMin = params.ray.x;
            ray.TMax = params.ray.y;
            Radiance reflected;
            reflected.color = float3(0.0, 0.0, 0.0);
            reflected.depth = r.depth + 1;
            reflected.throughput = next;
            // rtlint: allow(recursive-trace, reason = "the recursive reference: bounded by maxBounces; reflect_iterative.hlsl is the loop form")
            TraceRay(tlas, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, reflected);
            color += reflectivity * reflected.color;
        }
    }
    r.color = color;
}

[shader("anyhit")]
void any_hit(inout Radiance r, in BuiltInTriangleIntersectionAttributes attr)
{
    if (!alpha_keeps(InstanceID() + PrimitiveIndex(), attr.barycentrics))
        IgnoreHit();
}
