// Inline-SPIR-V decorations (`[[vk::ext_decorate(decoration, literals...)]]`)
// on global variables and on a function parameter: an `OpDecorate` of the
// variable and of the `OpFunctionParameter` (tests/hlsl_compile.rs).
#define DECORATION_RELAXED_PRECISION 0
#define DECORATION_RESTRICT 19

[[vk::ext_decorate(DECORATION_RESTRICT)]] RWStructuredBuffer<float> gResults : register(u0);
[[vk::ext_decorate(DECORATION_RELAXED_PRECISION)]] static float gScale = 2.0;
[[vk::ext_decorate(DECORATION_RELAXED_PRECISION)]] groupshared float gShared[8];

float scaled([[vk::ext_decorate(DECORATION_RELAXED_PRECISION)]] float x)
{
    return x * gScale;
}

[numthreads(8, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    gShared[id.x] = scaled(float(id.x));
    GroupMemoryBarrierWithGroupSync();
    gResults[id.x] = gShared[7 - id.x];
}
