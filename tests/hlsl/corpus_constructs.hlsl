// Constructs that made public DXR and Vulkan HLSL code fail to compile,
// each as the smallest shader of our own that uses it (checked by
// tests/hlsl_compile.rs).
#define DECORATION_RELAXED_PRECISION 0

Texture2D<float4> gTextures[4] : register(t0);
Texture2D<float4> gBindless[] : register(t0, space1);
SamplerState gSampler : register(s0);
RaytracingAccelerationStructure gScene : register(t4);
RWBuffer<uint> gCounts : register(u0);
RWTexture2D<uint> gMask : register(u1);
RWTexture2D<float4> gOut : register(u2);

struct Material
{
    // Inline SPIR-V: a member decoration (`OpMemberDecorate`).
    [[vk::ext_decorate(DECORATION_RELAXED_PRECISION)]] float roughness;
    uint64_t vertices;
};

struct Frame
{
    uint flags;
    bool has(uint f) { return (flags & f) != 0; }
};

cbuffer Constants : register(b0)
{
    Frame frame;
    Material material;
};

// A texture array parameter, sized and unsized, and an acceleration
// structure passed on from a parameter.
float4 pick(Texture2D<float4> ts[4], uint i) { return ts[i].SampleLevel(gSampler, 0.5, 0); }
float4 pickAny(Texture2D<float4> ts[], uint i) { return ts[NonUniformResourceIndex(i)].SampleLevel(gSampler, 0.5, 0); }

bool hitsAnything(RaytracingAccelerationStructure scene)
{
    RayQuery<RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH> q;
    RayDesc r = { float3(0, 0, 0), 0, float3(0, 0, 1), 100 };
    q.TraceRayInline(scene, 0, 0xFF, r);
    q.Proceed();
    return q.CommittedStatus() != COMMITTED_NOTHING;
}

bool occluded(RaytracingAccelerationStructure scene) { return hitsAnything(scene); }

[numthreads(8, 8, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    float4 c = pick(gTextures, id.x % 4) + pickAny(gBindless, id.y);
    // A method of a constant buffer member works on a copy.
    if (frame.has(1))
    {
        c *= 0.5;
    }
    // Atomics on a texel buffer element and a storage image texel.
    InterlockedOr(gCounts[id.x], 1u << (id.y % 32));
    uint before;
    InterlockedMin(gMask[id.xy], id.x, before);
    // A load through a device address.
    float3 p = vk::RawBufferLoad<float3>(material.vertices + id.x * 12);
    uint n = vk::RawBufferLoad(material.vertices, 16);
    gOut[id.xy] = c + float4(p, n + material.roughness + before) + occluded(gScene);
}

struct PixelIn
{
    float4 position : SV_Position;
    centroid float2 uv : TEXCOORD0;
    nointerpolation float layer : TEXCOORD1;
    noperspective float3 screen : TEXCOORD2;
    sample float sharp : TEXCOORD3;
};

[shader("pixel")]
[earlydepthstencil]
float4 Shade(PixelIn i) : SV_Target
{
    // `sample` and `centroid` are names too where no declaration follows.
    float centroid = i.uv.x;
    float sample = i.sharp;
    return float4(i.uv * centroid, i.layer + sample, i.screen.x);
}
