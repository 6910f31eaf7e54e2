// Shared by every shader of the pipeline.
#pragma once

struct Payload
{
    float3 color;
    float hitT;
    uint depth;
};

cbuffer Camera : register(b0)
{
    float4x4 viewInverse;
    float4x4 projInverse;
    float3 origin;
    float exposure;
    float weights[3];
    float tail;
};

struct Push
{
    uint frame;
    float time;
    float2 jitter;
    float4 tint;
};

[[vk::push_constant]] ConstantBuffer<Push> push;
