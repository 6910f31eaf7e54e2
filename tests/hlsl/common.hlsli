#pragma once
#ifndef COMMON_HLSLI
#define COMMON_HLSLI

#define SKY_TOP float3(0.3, 0.5, 1.0)
#define SKY_BOTTOM float3(1.0, 1.0, 1.0)

float3 sky(float3 dir)
{
    float t = 0.5 * (normalize(dir).y + 1.0);
    return lerp(SKY_BOTTOM, SKY_TOP, t);
}

#endif
