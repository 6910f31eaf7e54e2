// Resource kinds: bindless texture arrays with NonUniformResourceIndex,
// sampler and cube/array textures, shader records, push constants,
// storage images of several formats.
struct Payload
{
    float4 color;
};

struct HitRecord
{
    uint materialIndex;
    float roughness;
};

struct PushData
{
    float4 tint;
    uint frame;
    bool2 enabled;
};

struct Flags
{
    bool visible;
    float weight;
    bool sides[2];
};
RWStructuredBuffer<Flags> flags : register(u7);

Texture2D<float4> materials[] : register(t0, space1);
Texture2D textures8[8] : register(t0, space2);
TextureCube<float4> environment : register(t1);
Texture2DArray<float> layers : register(t2);
SamplerState samp : register(s0);
RWTexture2D<uint> ids : register(u3);
RWTexture2D<float2> motion : register(u4);
RWTexture2D<float3> noFormat : register(u5);
RaytracingAccelerationStructure tlas : register(t6);
[[vk::shader_record_ext]] ConstantBuffer<HitRecord> record;
ConstantBuffer<HitRecord> perDraw[4] : register(b9);
StructuredBuffer<float4> vertexStreams[] : register(t0, space3);
RWByteAddressBuffer rawBuffers[2] : register(u10);
[[vk::push_constant]] ConstantBuffer<PushData> push;

[shader("closesthit")]
void BindlessHit(inout Payload p, in BuiltInTriangleIntersectionAttributes attr)
{
    uint m = record.materialIndex + InstanceID();
    float4 albedo = materials[NonUniformResourceIndex(m)].SampleLevel(samp, attr.barycentrics, 0);
    float4 other = textures8[m & 7].SampleGrad(samp, attr.barycentrics, float2(0.01, 0), float2(0, 0.01));
    float4 env = environment.SampleLevel(samp, WorldRayDirection(), record.roughness * 8.0);
    float layer = layers.SampleLevel(samp, float3(attr.barycentrics, 2), 0);
    float4 texel = materials[0].Load(int3(1, 2, 0));
    float4 texel2 = textures8[1][uint2(3, 4)];
    float4 streamed = vertexStreams[NonUniformResourceIndex(m)][PrimitiveIndex()];
    float rough = perDraw[m & 3].roughness;
    rawBuffers[m & 1].Store(0, asuint(rough));
    p.color = albedo * env * push.tint + other * layer + texel + texel2 + streamed * rough;
}

[shader("miss")]
void EnvMiss(inout Payload p)
{
    uint w, h, levels;
    environment.GetDimensions(0, w, h, levels);
    p.color = environment.SampleLevel(samp, WorldRayDirection(), 0) * (float)levels / (float)(w * h);
}

[numthreads(8, 8, 1)]
void Resolve(uint3 id : SV_DispatchThreadID)
{
    uint w, h;
    ids.GetDimensions(w, h);
    if (id.x >= w || id.y >= h)
        return;
    uint old = ids[id.xy];
    ids[id.xy] = old + push.frame;
    motion[id.xy] += float2(0.5, -0.5);
    noFormat[id.xy] = float3(1, 2, 3);
    float3 prev = noFormat.Load(int2(id.xy));
    noFormat[id.xy].y = prev.x;
    Flags f = flags[id.x];
    if (f.visible && push.enabled.y)
        f.sides[1] = !f.sides[0];
    flags[id.x] = f;
    flags[id.y].visible = false;
}
