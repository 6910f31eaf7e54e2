// Mirror reflections with inline ray queries in an HLSL compute shader
// (rtlint's own compiler). Same math as reflect_rayquery.wgsl and the
// iterative references; the image must be the same. `main` is for scenes
// without cut-outs (every candidate forced opaque, no texture bound);
// `main_alpha` handles non-opaque candidates in its Proceed loops: the alpha
// test, then the commit.
#include "reflect_cutout.hlsli"

[numthreads(8, 8, 1)]
void main(uint3 id : SV_DispatchThreadID)
{
    if (id.x >= params.width || id.y >= params.height)
        return;
    float3 origin = params.camera.xyz;
    float3 dir = camera_dir(id.xy);
    float3 color = float3(0.0, 0.0, 0.0);
    float throughput = 1.0;
    // Every candidate is opaque (the template flag forces it), so Proceed
    // commits the closest triangle by itself.
    RayQuery<RAY_FLAG_FORCE_OPAQUE> q;
    for (uint bounce = 0; bounce <= params.max_bounces; bounce++)
    {
        RayDesc ray;
        ray.Origin = origin;
        ray.Direction = dir;
        ray.TMin = params.ray.x;
        ray.TMax = params.ray.y;
        q.TraceRayInline(tlas, RAY_FLAG_NONE, 0xFF, ray);
        while (q.Proceed())
        {
        }
        if (q.CommittedStatus() == COMMITTED_NOTHING)
        {
            color += throughput * sky(dir);
            break;
        }
        Surface s = surfaces[q.CommittedInstanceID() + q.CommittedPrimitiveIndex()];
        float3 normal = s.normal_reflectivity.xyz;
        float reflectivity = s.normal_reflectivity.w;
        float3 n = select(dot(normal, dir) < 0.0, normal, -normal);
        float3 base = throughput * (1.0 - reflectivity) * s.albedo_roughness.xyz;
        throughput *= reflectivity;
        origin = offset_ray(origin + dir * q.CommittedRayT(), n);
        float ndl = dot(n, params.light.xyz);
        float headlight = max(dot(n, -dir), 0.0);
        dir = reflect(dir, n);
        if ((params.flags & FLAG_LIGHT) != 0)
        {
            color += base * params.light.w;
            if (ndl > 0.0)
            {
                RayDesc shadow;
                shadow.Origin = origin;
                shadow.Direction = params.light.xyz;
                shadow.TMin = params.ray.x;
                shadow.TMax = params.ray.y;
                q.TraceRayInline(tlas, RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH, 0xFF, shadow);
                while (q.Proceed())
                {
                }
                if (q.CommittedStatus() == COMMITTED_NOTHING)
                    color += base * ndl;
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

[numthreads(8, 8, 1)]
void main_alpha(uint3 id : SV_DispatchThreadID)
{
    if (id.x >= params.width || id.y >= params.height)
        return;
    float3 origin = params.camera.xyz;
    float3 dir = camera_dir(id.xy);
    float3 color = float3(0.0, 0.0, 0.0);
    float throughput = 1.0;
    // Opaque triangles commit by themselves; a cut-out's triangles come back
    // as candidates, committed only where their alpha texel keeps them.
    RayQuery<RAY_FLAG_NONE> q;
    for (uint bounce = 0; bounce <= params.max_bounces; bounce++)
    {
        RayDesc ray;
        ray.Origin = origin;
        ray.Direction = dir;
        ray.TMin = params.ray.x;
        ray.TMax = params.ray.y;
        q.TraceRayInline(tlas, RAY_FLAG_NONE, 0xFF, ray);
        while (q.Proceed())
        {
            if (q.CandidateType() == CANDIDATE_NON_OPAQUE_TRIANGLE && alpha_keeps(q.CandidateInstanceID() + q.CandidatePrimitiveIndex(), q.CandidateTriangleBarycentrics()))
                q.CommitNonOpaqueTriangleHit();
        }
        if (q.CommittedStatus() == COMMITTED_NOTHING)
        {
            color += throughput * sky(dir);
            break;
        }
        Surface s = surfaces[q.CommittedInstanceID() + q.CommittedPrimitiveIndex()];
        float3 normal = s.normal_reflectivity.xyz;
        float reflectivity = s.normal_reflectivity.w;
        float3 n = select(dot(normal, dir) < 0.0, normal, -normal);
        float3 base = throughput * (1.0 - reflectivity) * s.albedo_roughness.xyz;
        throughput *= reflectivity;
        origin = offset_ray(origin + dir * q.CommittedRayT(), n);
        float ndl = dot(n, params.light.xyz);
        float headlight = max(dot(n, -dir), 0.0);
        dir = reflect(dir, n);
        if ((params.flags & FLAG_LIGHT) != 0)
        {
            color += base * params.light.w;
            if (ndl > 0.0)
            {
                RayDesc shadow;
                shadow.Origin = origin;
                shadow.Direction = params.light.xyz;
                shadow.TMin = params.ray.x;
                shadow.TMax = params.ray.y;
                q.TraceRayInline(tlas, RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH, 0xFF, shadow);
                // The first kept candidate ends the search.
                while (q.Proceed())
                {
                    if (q.CandidateType() == CANDIDATE_NON_OPAQUE_TRIANGLE && alpha_keeps(q.CandidateInstanceID() + q.CandidatePrimitiveIndex(), q.CandidateTriangleBarycentrics()))
                        q.CommitNonOpaqueTriangleHit();
                }
                if (q.CommittedStatus() == COMMITTED_NOTHING)
                    color += base * ndl;
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
