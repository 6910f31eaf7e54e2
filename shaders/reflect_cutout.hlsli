// Alpha-tested cut-outs: the alpha texture and, per triangle, the texture
// coordinates of its corners with the texture's size (0 × 0: not tested).
// verify binds them only for scenes with cut-outs, and only any-hit shaders
// and the ray queries' candidate loops read them.
#pragma once
#include "reflect_common.hlsli"

Texture2D<float4> alpha_texture : register(t4);

struct Cutout
{
    // u0 v0 u1 v1
    float4 uv01;
    // u2 v2, texture width and height
    float4 uv2_size;
};
StructuredBuffer<Cutout> cutouts : register(t5);

// Whether triangle `index` is there at barycentrics `bary` (the weights of
// corners 1 and 2): the one texel under the interpolated coordinate.
bool alpha_keeps(uint index, float2 bary)
{
    Cutout c = cutouts[index];
    float2 size = c.uv2_size.zw;
    if (size.x == 0.0)
        return true;
    float2 uv = c.uv01.xy + bary.x * (c.uv01.zw - c.uv01.xy) + bary.y * (c.uv2_size.xy - c.uv01.xy);
    uint2 texel = min(uint2(clamp(uv, 0.0, 1.0) * size), uint2(size) - 1u);
    return alpha_texture.Load(int3(texel, 0)).a >= 0.5;
}
