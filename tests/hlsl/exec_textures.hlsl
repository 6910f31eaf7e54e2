// Executed on a Vulkan driver by tests/hlsl_exec.rs: sampling with a separate
// sampler, texel fetches and a storage image written and read back.
Texture2D<float4> tex : register(t0);
SamplerState samp : register(s1);
RWTexture2D<float4> img : register(u2);
RWStructuredBuffer<float4> outBuf : register(u3);

[numthreads(16, 1, 1)]
void Main(uint3 tid : SV_DispatchThreadID)
{
    uint2 p = uint2(tid.x % 4, tid.x / 4);
    uint w, h;
    img.GetDimensions(w, h);
    float2 uv = (float2(p) + 0.5) / float2(w, h);
    float4 sampled = tex.SampleLevel(samp, uv, 0);
    float4 fetched = tex.Load(int3(p % 2, 0));
    img[p] = float4(p, 0.25, 1.0);
    img[p].z *= 2.0;
    float4 stored = img[p];
    outBuf[tid.x] = sampled + 10.0 * fetched + 100.0 * stored;
}
