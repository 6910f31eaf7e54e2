// Shared by the HLSL reflection references: resources, the uniform block,
// the sky, packing and the robust ray origin. Bindings match the WGSL
// versions: t0 = scene, u1 = image, t2 = surfaces, b3 = parameters.
#pragma once

RaytracingAccelerationStructure tlas : register(t0);
RWStructuredBuffer<uint> image : register(u1);

// One entry per triangle (instance custom index + primitive index):
// xyz = world-space geometric normal, w = reflectivity.
struct Surface
{
    float4 normal_reflectivity;
    float4 albedo_roughness;
};
StructuredBuffer<Surface> surfaces : register(t2);

struct ParamsData
{
    uint width;
    uint height;
    uint max_bounces;
    // FLAG_LIGHT | FLAG_ROBUST
    uint flags;
    float4 camera;
    // xyz: unit direction towards the light, w: ambient
    float4 light;
    // t_min, t_max, throughput cut-off, fixed origin epsilon
    float4 ray;
    // x: reflection rays' t_max (before the roughness shortening);
    // y: roughness above which the environment replaces the reflection ray
    // (read by the glossy shader only); w: the bits of a uint, the adaptive
    // shader's fewest paths per pixel | the most << 16
    float4 knobs;
};
ConstantBuffer<ParamsData> params : register(b3);

static const uint FLAG_LIGHT = 1;
static const uint FLAG_ROBUST = 2;
// The hybrid shader traces every reflection, marching none (rtlint tradeoff).
static const uint FLAG_RAY_ONLY = 4;

float3 sky(float3 dir)
{
    float k = 0.5 * (dir.y + 1.0);
    return lerp(float3(1.0, 1.0, 1.0), float3(0.5, 0.7, 1.0), k);
}

// RGBA8 with alpha 255; a colour with an infinite or NaN channel is written
// as 0 (alpha 0), so the image counts them. The exponent bits are tested:
// a compiler may assume no NaN in `c != c`.
uint pack_rgba8(float3 c)
{
    if (any((asuint(c) & 0x7F800000u) == 0x7F800000u))
        return 0u;
    uint3 v = uint3(clamp(c, float3(0.0, 0.0, 0.0), float3(1.0, 1.0, 1.0)) * 255.0 + 0.5);
    return v.x | (v.y << 8) | (v.z << 16) | (255u << 24);
}

// Wächter & Binder, Ray Tracing Gems ch. 6: move the origin a few ulps
// along the normal; a fixed epsilon when FLAG_ROBUST is off.
float3 offset_ray(float3 p, float3 n)
{
    if ((params.flags & FLAG_ROBUST) == 0)
        return p + n * params.ray.w;
    int3 of_i = int3(256.0 * n);
    float3 p_i = asfloat(asint(p) + select(p < 0.0, -of_i, of_i));
    return select(abs(p) < 0.03125, p + 0.0000152587890625 * n, p_i);
}

// The geometric normal turned towards the side the ray comes from.
float3 facing(float3 normal, float3 dir)
{
    return select(dot(normal, dir) < 0.0, normal, -normal);
}

float3 camera_dir(uint2 id)
{
    float2 size = float2(params.width, params.height);
    float2 uv = (float2(id) + 0.5) / size * 2.0 - 1.0;
    return normalize(float3(uv.x, -uv.y, -1.5));
}
