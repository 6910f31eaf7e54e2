// Raygen + miss + closest hit with a shadow ray that uses miss shader 1.
#include "common.hlsli"

RaytracingAccelerationStructure scene : register(t0);
RWTexture2D<float4> output : register(u1);

cbuffer Camera : register(b2)
{
    float4x4 viewInverse;
    float3 lightDir;
    float tMax;
};

struct [raypayload] Payload
{
    float3 color : read(caller) : write(closesthit, miss);
    uint depth : read(closesthit) : write(caller);
};

struct ShadowPayload
{
    bool hit;
};

[shader("raygeneration")]
void RayGen()
{
    uint2 pixel = DispatchRaysIndex().xy;
    uint2 size = DispatchRaysDimensions().xy;
    float2 uv = (float2(pixel) + 0.5) / float2(size) * 2.0 - 1.0;

    RayDesc ray;
    ray.Origin = mul(viewInverse, float4(0, 0, 0, 1)).xyz;
    ray.Direction = normalize(float3(uv.x, -uv.y, -1.0));
    ray.TMin = 0.001;
    ray.TMax = tMax;

    Payload p;
    p.color = 0;
    p.depth = 0;
    TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 2, 0, ray, p);
    output[pixel] = float4(p.color, 1.0);
}

[shader("miss")]
void Miss(inout Payload p)
{
    p.color = sky(WorldRayDirection());
}

[shader("miss")]
void ShadowMiss(inout ShadowPayload s)
{
    s.hit = false;
}

// Resources pass to helpers as the variables themselves.
bool occluded(RaytracingAccelerationStructure tlas, float3 origin, float3 dir)
{
    RayDesc r;
    r.Origin = origin;
    r.Direction = dir;
    r.TMin = 0.01;
    r.TMax = 1000.0;
    ShadowPayload s;
    s.hit = true;
    // Offset 1, stride 2, miss shader 1: the shadow miss.
    TraceRay(tlas, RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER,
             0xFF, 1, 2, 1, r, s);
    return s.hit;
}

[shader("closesthit")]
void ClosestHit(inout Payload p, in BuiltInTriangleIntersectionAttributes attr)
{
    float3 bary = float3(1.0 - attr.barycentrics.x - attr.barycentrics.y, attr.barycentrics);
    float3 hitPos = WorldRayOrigin() + WorldRayDirection() * RayTCurrent();

    float lit = occluded(scene, hitPos, -lightDir) ? 0.2 : 1.0;
    p.color = bary * lit * saturate(dot(normalize(hitPos), -lightDir));
}
