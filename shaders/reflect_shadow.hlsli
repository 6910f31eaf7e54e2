// Shadow rays of the HLSL ray-tracing pipelines: a payload of their own and
// a miss shader of their own (miss index 1) that marks the light visible.
#pragma once
#include "reflect_common.hlsli"

struct ShadowInfo
{
    float visible;
};

static const uint SHADOW_FLAGS = RAY_FLAG_FORCE_OPAQUE | RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER;

float shadow_ray(float3 origin)
{
    RayDesc ray;
    ray.Origin = origin;
    ray.Direction = params.light.xyz;
    ray.TMin = params.ray.x;
    ray.TMax = params.ray.y;
    ShadowInfo shadow;
    shadow.visible = 0.0;
    TraceRay(tlas, SHADOW_FLAGS, 0xFF, 0, 1, 1, ray, shadow);
    return shadow.visible;
}

[shader("miss")]
void shadow_miss(inout ShadowInfo shadow)
{
    shadow.visible = 1.0;
}
