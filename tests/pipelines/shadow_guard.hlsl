// Reflections and shadows guarded by one depth counter, in helpers that
// return early at the limit, as the official procedural-geometry DXR sample
// writes them: the raygen traces at depth 1, a closest hit at payload depth
// d traces a shadow ray and a reflection only while d < 3. Three levels are
// needed (raygen, hit at 1, hit or shadow miss at 2, hit or shadow miss at 3)
// and three are declared.
#define MAX_DEPTH 3

[[vk::binding(0, 0)]] RaytracingAccelerationStructure Scene : register(t0);
[[vk::binding(1, 0)]] RWTexture2D<float4> Output : register(u0);

struct RadiancePayload { float4 color; uint depth; };
struct ShadowPayload { bool hit; };

float4 TraceRadiance(float3 origin, float3 dir, uint depth)
{
    if (depth >= MAX_DEPTH)
        return float4(0, 0, 0, 0);
    RayDesc ray = { origin, 0.001, dir, 1000.0 };
    RadiancePayload p = { float4(0, 0, 0, 0), depth + 1 };
    TraceRay(Scene, RAY_FLAG_CULL_BACK_FACING_TRIANGLES, 0xFF, 0, 2, 0, ray, p);
    return p.color;
}

bool TraceShadow(float3 origin, float3 dir, uint depth)
{
    if (depth >= MAX_DEPTH)
        return false;
    RayDesc ray = { origin, 0.001, dir, 1000.0 };
    ShadowPayload p = { true };
    TraceRay(Scene,
        RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_FORCE_OPAQUE | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER,
        0xFF, 1, 2, 1, ray, p);
    return p.hit;
}

[shader("raygeneration")]
void RayGen()
{
    float2 uv = (DispatchRaysIndex().xy + 0.5) / DispatchRaysDimensions().xy;
    Output[DispatchRaysIndex().xy] = TraceRadiance(float3(uv * 2 - 1, -1), float3(0, 0, 1), 0);
}

[shader("closesthit")]
void Hit(inout RadiancePayload p, BuiltInTriangleIntersectionAttributes a)
{
    float3 at = WorldRayOrigin() + WorldRayDirection() * RayTCurrent();
    float3 n = float3(0, 1, 0);
    bool shadowed = TraceShadow(at, normalize(float3(1, 1, 0)), p.depth);
    float4 reflected = TraceRadiance(at, reflect(WorldRayDirection(), n), p.depth);
    p.color = (shadowed ? 0.2 : 1.0) * float4(a.barycentrics, 1, 1) + 0.5 * reflected;
}

[shader("miss")]
void Miss(inout RadiancePayload p) { p.color = float4(0, 0, 0.3, 1); }

[shader("miss")]
void ShadowMiss(inout ShadowPayload p) { p.hit = false; }
