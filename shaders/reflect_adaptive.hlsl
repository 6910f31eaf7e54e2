// Adaptive sampling in HLSL (rtlint's own compiler): the glossy GGX path of
// reflect_glossy.hlsl, accumulated over passes. verify runs the ray
// generation shader once per pass, as many passes as the most paths per
// pixel (16 by default); each pass a pixel traces one more path while it
// has fewer than the fewest (4 by default), or fewer than the most and a
// variance estimate of its mean's luminance above the tolerance
// (params.camera.w, 0.001 by default). The fewest and the most are
// params.knobs.w's halves. `counts` gets the paths each pixel traced;
// `state` keeps the sums between passes.
#include "reflect_ggx.hlsli"

struct Accumulator
{
    // xyz: the paths' light summed; w: how many (the bits of a uint)
    float4 sum_samples;
    // x: luminance summed, y: its squares summed
    float4 luminance;
    float4 unused0;
    float4 unused1;
};
RWStructuredBuffer<uint> counts : register(u6);
RWStructuredBuffer<Accumulator> state : register(u7);

static const float3 LUMINANCE = float3(0.2126, 0.7152, 0.0722);

[shader("raygeneration")]
void raygen()
{
    uint2 id = DispatchRaysIndex().xy;
    uint index = id.y * params.width + id.x;
    Accumulator acc = state[index];
    uint n = asuint(acc.sum_samples.w);
    uint paths = asuint(params.knobs.w);
    bool more = n < (paths & 0xFFFFu);
    if (!more && n < (paths >> 16u))
    {
        float mean = acc.luminance.x / float(n);
        float variance = max(acc.luminance.y / float(n) - mean * mean, 0.0);
        more = variance / float(n) > params.camera.w;
    }
    if (more)
    {
        float3 c = float3(0.0, 0.0, 0.0);
        glossy_sample(id, n, c);
        float l = dot(c, LUMINANCE);
        n += 1;
        acc.sum_samples = float4(acc.sum_samples.xyz + c, asfloat(n));
        acc.luminance.x += l;
        acc.luminance.y += l * l;
        state[index] = acc;
    }
    counts[index] = n;
    image[index] = pack_rgba8(acc.sum_samples.xyz / float(max(n, 1u)));
}
