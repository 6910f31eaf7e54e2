// Space-only registers for bindless arrays, and `static const` values used
// as array sizes in structs, typedefs, cbuffers and groupshared memory.
static const uint MAX_BOUNCES = 4;
namespace config
{
    static const uint TAPS = MAX_BOUNCES + 1;
}

struct PathState
{
    float3 throughput[MAX_BOUNCES];
    float weights[config::TAPS];
};
typedef float Kernel[MAX_BOUNCES];

cbuffer Params : register(b0)
{
    float4 bounceWeights[MAX_BOUNCES];
};

Texture2D<float4> bindlessTextures[] : register(space99);
ByteAddressBuffer bindlessBuffers[] : register(space98);
cbuffer Extra : register(space7)
{
    float scale;
};
RWStructuredBuffer<float4> output : register(u0);
groupshared float cache[MAX_BOUNCES * 2];

[numthreads(8, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    PathState p;
    Kernel k;
    for (uint i = 0; i < MAX_BOUNCES; i++)
    {
        p.throughput[i] = bounceWeights[i].xyz;
        k[i] = i;
    }
    p.weights[config::TAPS - 1] = scale;
    cache[id.x] = k[id.x % MAX_BOUNCES];
    GroupMemoryBarrierWithGroupSync();
    float4 t = bindlessTextures[NonUniformResourceIndex(id.x)].Load(int3(0, 0, 0));
    float b = asfloat(bindlessBuffers[NonUniformResourceIndex(id.x)].Load(0));
    output[id.x] = t * b + float4(p.throughput[0], p.weights[config::TAPS - 1]) + cache[(id.x + 1) % 8];
}
