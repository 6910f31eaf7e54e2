// Reached as `util\hlslcompat.hlsli`: backslashes, and a case that differs.
#ifndef HLSL_COMPAT_HLSLI
#define HLSL_COMPAT_HLSLI

#include "Sampling.hlsli"

float3 srgbToLinear(float3 c)
{
    return pow(c, 2.2);
}

#endif
