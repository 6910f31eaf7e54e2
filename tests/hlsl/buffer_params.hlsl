// Buffers passed to functions: each call site's buffer gets its own copy of
// the function (SPIR-V cannot pass storage-buffer pointers without the
// variable-pointers capability); textures and samplers stay parameters.
ByteAddressBuffer indicesA : register(t0);
ByteAddressBuffer indicesB : register(t1);
StructuredBuffer<float3> positions : register(t2);
Texture2D<float4> albedo : register(t3);
Texture2D<float4> layers[2] : register(t4);
SamplerState linearSampler : register(s0);
RWStructuredBuffer<float4> output : register(u0);

uint3 loadTriangle(ByteAddressBuffer indices, uint primitive)
{
    return indices.Load3(primitive * 12);
}

float3 centroid(ByteAddressBuffer indices, StructuredBuffer<float3> verts, uint primitive)
{
    uint3 i = loadTriangle(indices, primitive);
    return (verts[i.x] + verts[i.y] + verts[i.z]) / 3.0;
}

float4 shade(Texture2D<float4> tex, SamplerState s, float2 uv)
{
    return tex.SampleLevel(s, uv, 0);
}

[numthreads(64, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    float3 a = centroid(indicesA, positions, id.x);
    float3 b = centroid(indicesB, positions, id.x);
    float3 c = centroid(indicesA, positions, id.x + 1);
    // An element of a texture array may be passed (images and samplers only).
    output[id.x] = float4(a + b + c, 0) + shade(albedo, linearSampler, a.xy)
        + shade(layers[id.x % 2], linearSampler, b.xy);
}
