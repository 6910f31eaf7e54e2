// Differential test (tests/hlsl_differential.rs): any-hit alpha testing. Two
// overlapping quads (instances 0 and 1 of one non-opaque mesh) carry per-vertex
// UVs; the any-hit shader reads the hit's UV from structured buffers and cuts
// a checker of holes, so some rays pass through the front quad to the back one.
// A second ray with RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH stops at the first
// opaque texel.
RaytracingAccelerationStructure scene : register(t0);

struct Vertex
{
    float3 position;
    float2 uv;
};

StructuredBuffer<Vertex> vertices : register(t1);
StructuredBuffer<uint> indices : register(t2);
RWStructuredBuffer<float4> image : register(u3);

static const float CUTOFF = 0.5;

struct Payload
{
    float4 color;
};

float2 hitUV(uint prim, float2 bary)
{
    uint i0 = indices[prim * 3 + 0];
    uint i1 = indices[prim * 3 + 1];
    uint i2 = indices[prim * 3 + 2];
    float3 w = float3(1.0 - bary.x - bary.y, bary.x, bary.y);
    return vertices[i0].uv * w.x + vertices[i1].uv * w.y + vertices[i2].uv * w.z;
}

float alphaAt(float2 uv)
{
    float2 cell = floor(uv * 4.0);
    return fmod(cell.x + cell.y, 2.0) < 0.5 ? 0.75 + 0.25 * frac(uv.x * 3.0) : 0.2;
}

[shader("raygeneration")]
void RayGen()
{
    uint2 id = DispatchRaysIndex().xy;
    uint2 dim = DispatchRaysDimensions().xy;
    float2 uv = (float2(id) + 0.5) / float2(dim) * 2.4 - 1.2;
    RayDesc ray;
    ray.Origin = float3(uv, -1.0);
    ray.Direction = float3(0.05, 0.02, 1.0);
    ray.TMin = 0.0;
    ray.TMax = 10.0;
    Payload p;
    p.color = float4(0, 0, 0, 1);
    TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    Payload first;
    first.color = float4(0, 0, 0, 1);
    TraceRay(scene, RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH, 0xFF, 0, 1, 0, ray, first);
    image[(id.y * dim.x + id.x) * 2] = p.color;
    image[(id.y * dim.x + id.x) * 2 + 1] = first.color;
}

[shader("miss")]
void Miss(inout Payload p)
{
    p.color = float4(0, 0, -1, p.color.a);
}

[shader("anyhit")]
void AlphaTest(inout Payload p, in BuiltInTriangleIntersectionAttributes attr)
{
    float alpha = alphaAt(hitUV(PrimitiveIndex(), attr.barycentrics));
    if (alpha < CUTOFF)
    {
        IgnoreHit();
    }
    p.color.a = min(p.color.a, alpha);
    if (RayFlags() & RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH)
    {
        AcceptHitAndEndSearch();
    }
}

[shader("closesthit")]
void Shade(inout Payload p, in BuiltInTriangleIntersectionAttributes attr)
{
    float2 uv = hitUV(PrimitiveIndex(), attr.barycentrics);
    p.color = float4(uv, (float)InstanceID() + RayTCurrent() * 0.125, p.color.a);
}
