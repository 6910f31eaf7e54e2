// Iterative mirror reflections in HLSL, compiled by rtlint's own compiler:
// the ray generation shader loops over bounces, the closest-hit shader only
// reports the surface, so the pipeline needs recursion depth 1. Shadow rays
// (when the scene has a light) are traced from raygen with their own payload
// and miss shader (miss index 1). Cut-outs: the any-hit shaders ignore
// candidates whose alpha texel is cut away. Same math as
// reflect_iterative.wgsl, which cannot express the alpha test.
#include "reflect_shadow.hlsli"

struct HitInfo
{
    float3 albedo;
    float t;
    float3 normal;
    float reflectivity;
};

[shader("raygeneration")]
void raygen()
{
    uint2 id = DispatchRaysIndex().xy;
    float3 origin = params.camera.xyz;
    float3 dir = camera_dir(id);
    float3 color = float3(0.0, 0.0, 0.0);
    // The product of the reflectivities so far; the path stops once it is
    // not above the cut-off.
    float throughput = 1.0;
    for (uint bounce = 0; bounce <= params.max_bounces; bounce++)
    {
        RayDesc ray;
        ray.Origin = origin;
        ray.Direction = dir;
        ray.TMin = params.ray.x;
        ray.TMax = params.ray.y;
        // Written whole, so nothing of the last bounce's payload stays live.
        HitInfo hit = (HitInfo)0;
        TraceRay(tlas, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, hit);
        if (hit.t < 0.0)
        {
            color += throughput * sky(dir);
            break;
        }
        float3 n = select(dot(hit.normal, dir) < 0.0, hit.normal, -hit.normal);
        float3 base = throughput * (1.0 - hit.reflectivity) * hit.albedo;
        throughput *= hit.reflectivity;
        origin = offset_ray(origin + dir * hit.t, n);
        float ndl = dot(n, params.light.xyz);
        float headlight = max(dot(n, -dir), 0.0);
        dir = reflect(dir, n);
        if ((params.flags & FLAG_LIGHT) != 0)
        {
            color += base * params.light.w;
            if (ndl > 0.0)
            {
                float3 lit = base * ndl;
                if (shadow_ray(origin) > 0.0)
                    color += lit;
            }
        }
        else
        {
            color += base * headlight;
        }
        if (!(throughput > params.ray.z))
            break;
    }
    image[id.y * params.width + id.x] = pack_rgba8(color);
}

[shader("miss")]
void miss(inout HitInfo hit)
{
    hit.t = -1.0;
}

[shader("closesthit")]
void closest_hit(inout HitInfo hit, in BuiltInTriangleIntersectionAttributes attr)
{
    Surface s = surfaces[InstanceID() + PrimitiveIndex()];
    hit.albedo = s.albedo_roughness.xyz;
    hit.t = RayTCurrent();
    hit.normal = s.normal_reflectivity.xyz;
    hit.reflectivity = s.normal_reflectivity.w;
}

[shader("anyhit")]
void any_hit(inout HitInfo hit, in BuiltInTriangleIntersectionAttributes attr)
{
    if (!alpha_keeps(InstanceID() + PrimitiveIndex(), attr.barycentrics))
        IgnoreHit();
}
