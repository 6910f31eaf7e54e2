// Helpers that return a texture, a buffer or a sampler (inlined, as SPIR-V
// cannot return a resource), including from a resource array.
Texture2D<float4> materials[8] : register(t0);
StructuredBuffer<float4> palettes[4] : register(t8);
ByteAddressBuffer rawData : register(t12);
SamplerState linearClamp : register(s0);
SamplerState pointWrap : register(s1);
RWTexture2D<float4> output : register(u0);

Texture2D<float4> material(uint index) { return materials[NonUniformResourceIndex(index)]; }
StructuredBuffer<float4> palette(uint index) { return palettes[index & 3]; }
ByteAddressBuffer raw() { return rawData; }
SamplerState pickSampler(bool smooth = true) { return smooth ? linearClamp : pointWrap; }
SamplerState defaultSampler() { return linearClamp; }

[numthreads(8, 8, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    float2 uv = float2(id.xy) / 64.0;
    float4 c = material(id.x % 8).SampleLevel(defaultSampler(), uv, 0);
    c += palette(id.y)[id.x % 16];
    c.w = asfloat(raw().Load(id.x * 4));
    uint w, h;
    material(1).GetDimensions(w, h);
    output[id.xy] = c * (w > 0 ? 1.0 : 0.0);
}
