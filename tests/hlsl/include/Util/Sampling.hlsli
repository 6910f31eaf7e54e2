// Includes the header that includes it: the guard stops the cycle.
#ifndef SAMPLING_HLSLI
#define SAMPLING_HLSLI

#include "HlslCompat.hlsli"

float radicalInverse(uint bits)
{
    return reversebits(bits) * 2.3283064365386963e-10;
}

#endif
