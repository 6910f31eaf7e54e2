#include "include/common.hlsli"

RaytracingAccelerationStructure scene : register(t1);
RWTexture2D<float4> image : register(u2);

[shader("raygeneration")]
void RayGen()
{
    uint2 pixel = DispatchRaysIndex().xy;
    uint2 size = DispatchRaysDimensions().xy;
    float2 uv = (float2(pixel) + 0.5 + push.jitter) / float2(size) * 2.0 - 1.0;
    float4 target = mul(projInverse, float4(uv.x, -uv.y, 1.0, 1.0));

    RayDesc ray;
    ray.Origin = origin;
    ray.Direction = mul(viewInverse, float4(normalize(target.xyz), 0.0)).xyz;
    ray.TMin = 0.001;
    ray.TMax = 1000.0;

    Payload p;
    p.color = float3(0.0, 0.0, 0.0);
    p.hitT = 0.0;
    p.depth = 0;
    TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    float w = weights[0] + weights[1] + weights[2] + tail;
    float coverage = p.hitT > 0.0 ? 1.0 : 0.0;
    image[pixel] = float4(p.color * exposure * w, coverage) * push.tint;
}
