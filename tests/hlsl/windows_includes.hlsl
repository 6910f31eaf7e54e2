// Includes written the Windows way: backslash separators, a folder and a
// file name whose case differs from the files on disk, and guarded headers
// that include each other.
#include "include\util\hlslcompat.hlsli"
#include "include\Util\Sampling.hlsli"

RWStructuredBuffer<float4> output : register(u0);

[numthreads(8, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    output[id.x] = float4(srgbToLinear(float3(0.5, 0.5, 0.5)), radicalInverse(id.x));
}
