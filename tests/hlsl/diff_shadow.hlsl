// Differential test (tests/hlsl_differential.rs): a lit floor under a floating
// triangle. Primary rays use miss 0 and hit group 0; the closest-hit shader
// traces a shadow ray with SBT offset 1, stride 2 and miss index 1, whose
// payload type differs from the primary one.
#include "common.hlsli"

RaytracingAccelerationStructure scene : register(t0);
RWStructuredBuffer<float4> image : register(u1);

cbuffer Light : register(b2)
{
    float3 toLight;
    float ambient;
};

struct Payload
{
    float3 color;
    uint hits;
};

struct ShadowPayload
{
    float visibility;
};

[shader("raygeneration")]
void RayGen()
{
    uint2 pixel = DispatchRaysIndex().xy;
    uint2 size = DispatchRaysDimensions().xy;
    float2 uv = (float2(pixel) + 0.5) / float2(size) * 2.0 - 1.0;
    RayDesc ray;
    ray.Origin = float3(0.0, 1.5, 3.0);
    ray.Direction = normalize(float3(uv.x, -uv.y - 0.4, -1.2));
    ray.TMin = 0.001;
    ray.TMax = 100.0;
    Payload p;
    p.color = 0;
    p.hits = 0;
    TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 2, 0, ray, p);
    image[pixel.y * size.x + pixel.x] = float4(p.color, (float)p.hits);
}

[shader("miss")]
void Miss(inout Payload p)
{
    p.color = sky(WorldRayDirection());
}

[shader("miss")]
void ShadowMiss(inout ShadowPayload s)
{
    s.visibility = 1.0;
}

[shader("closesthit")]
void ClosestHit(inout Payload p, in BuiltInTriangleIntersectionAttributes attr)
{
    float3 bary = float3(1.0 - attr.barycentrics.x - attr.barycentrics.y, attr.barycentrics);
    float3 hitPos = WorldRayOrigin() + WorldRayDirection() * RayTCurrent();
    float3 l = normalize(toLight);

    RayDesc shadow;
    shadow.Origin = hitPos;
    shadow.Direction = l;
    shadow.TMin = 0.01;
    shadow.TMax = 100.0;
    ShadowPayload s;
    s.visibility = 0.0;
    TraceRay(scene, RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER,
             0xFF, 1, 2, 1, shadow, s);

    // Both instances are horizontal, facing up.
    float3 albedo = InstanceID() == 0 ? float3(0.8, 0.7, 0.6) : bary;
    float facing = HitKind() == HIT_KIND_TRIANGLE_FRONT_FACE ? 1.0 : 0.5;
    p.color = albedo * (ambient + s.visibility * facing * saturate(l.y));
    p.hits += 1 + PrimitiveIndex() * 10 + InstanceID() * 100;
}
