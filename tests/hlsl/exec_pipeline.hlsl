// Executed on a Vulkan driver by tests/hlsl_exec.rs: one triangle, a 4x4
// launch. Primary rays hit (closest hit writes barycentrics and t) unless the
// any-hit shader ignores the hit; a second ray uses miss shader 1 with another
// payload type.
RaytracingAccelerationStructure scene : register(t0);
RWStructuredBuffer<float4> outBuf : register(u1);

struct Payload
{
    float4 color;
};

struct Probe
{
    float seen;
};

// The acceleration structure passes to a helper as a parameter.
float probe(RaytracingAccelerationStructure tlas, RayDesc ray)
{
    Probe p;
    p.seen = 0;
    TraceRay(tlas, RAY_FLAG_NONE, 0xFF, 0, 1, 1, ray, p);
    return p.seen;
}

[shader("raygeneration")]
void RG()
{
    uint2 id = DispatchRaysIndex().xy;
    uint2 dim = DispatchRaysDimensions().xy;
    float2 uv = (float2(id) + 0.5) / float2(dim);
    RayDesc ray;
    ray.Origin = float3(uv * 2.0 - 1.0 + float2(0.1, 0.0), -1.0);
    ray.Direction = float3(0, 0, 1);
    ray.TMin = 0.0;
    ray.TMax = 10.0;
    Payload p;
    p.color = float4(0, 0, 0, 0);
    TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    ray.Direction = float3(0, 0, -1);
    outBuf[id.y * dim.x + id.x] = float4(p.color.xyz, p.color.w + probe(scene, ray));
}

[shader("miss")]
void MissColor(inout Payload p)
{
    p.color = float4(0, 0, 1, 0);
}

[shader("miss")]
void MissProbe(inout Probe probe)
{
    probe.seen = 10.0;
}

[shader("closesthit")]
void Hit(inout Payload p, in BuiltInTriangleIntersectionAttributes attr)
{
    p.color = float4(attr.barycentrics, RayTCurrent(), 1.0);
}

[shader("anyhit")]
void Filter(inout Payload p, in BuiltInTriangleIntersectionAttributes attr)
{
    if (attr.barycentrics.x > 0.5)
        IgnoreHit();
}
