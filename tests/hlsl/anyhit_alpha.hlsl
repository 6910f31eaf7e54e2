// Any-hit alpha test: fetch the hit's UV, sample an alpha mask, ignore
// transparent hits; shadow rays end the search at the first opaque hit.
struct Payload
{
    float4 color;
};

struct Vertex
{
    float3 position;
    float2 uv;
};

StructuredBuffer<Vertex> vertices : register(t1);
StructuredBuffer<uint> indices : register(t2);
Texture2D<float4> alphaMask : register(t3);
SamplerState linearSampler : register(s4);

static const float ALPHA_CUTOFF = 0.5;

float2 hitUV(uint prim, float2 bary)
{
    uint i0 = indices[prim * 3 + 0];
    uint i1 = indices[prim * 3 + 1];
    uint i2 = indices.Load(prim * 3 + 2);
    float3 w = float3(1.0 - bary.x - bary.y, bary.x, bary.y);
    return vertices[i0].uv * w.x + vertices[i1].uv * w.y + vertices[i2].uv * w.z;
}

[shader("anyhit")]
void AlphaTest(inout Payload p, in BuiltInTriangleIntersectionAttributes attr)
{
    float2 uv = hitUV(PrimitiveIndex(), attr.barycentrics);
    float alpha = alphaMask.SampleLevel(linearSampler, uv, 0).a;
    if (alpha < ALPHA_CUTOFF)
    {
        IgnoreHit();
    }
    if (RayFlags() & RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH)
    {
        AcceptHitAndEndSearch();
    }
    p.color.a = min(p.color.a, alpha);
}

[shader("closesthit")]
void Shade(inout Payload p, in BuiltInTriangleIntersectionAttributes attr)
{
    uint w, h;
    alphaMask.GetDimensions(w, h);
    float2 uv = hitUV(PrimitiveIndex(), attr.barycentrics);
    p.color = float4(uv, (float)InstanceID() / 255.0, HitKind() == HIT_KIND_TRIANGLE_FRONT_FACE ? 1.0 : 0.5);
    p.color.rg *= float2(w, h) / 1024.0;
}
