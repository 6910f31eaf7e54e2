// Shadow rays of the HLSL ray-tracing pipelines: a payload of their own, a
// miss shader of their own (miss index 1) that marks the light visible, and
// a hit group of their own (SBT offset 1) whose any-hit shader lets them
// through a cut-out's holes. Opaque geometry never runs it.
#pragma once
#include "reflect_cutout.hlsli"

struct ShadowInfo
{
    float visible;
};

static const uint SHADOW_FLAGS = RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER;

float shadow_ray(float3 origin)
{
    RayDesc ray;
    ray.Origin = origin;
    ray.Direction = params.light.xyz;
    ray.TMin = params.ray.x;
    ray.TMax = params.ray.y;
    ShadowInfo shadow;
    shadow.visible = 0.0;
    TraceRay(tlas, SHADOW_FLAGS, 0xFF, 1, 1, 1, ray, shadow);
    return shadow.visible;
}

[shader("miss")]
void shadow_miss(inout ShadowInfo shadow)
{
    shadow.visible = 1.0;
}

[shader("anyhit")]
void shadow_any_hit(inout ShadowInfo shadow, in BuiltInTriangleIntersectionAttributes attr)
{
    if (!alpha_keeps(InstanceID() + PrimitiveIndex(), attr.barycentrics))
        IgnoreHit();
}
