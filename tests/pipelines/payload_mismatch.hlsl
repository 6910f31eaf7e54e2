// A pipeline whose ray generation shader traces a 12-byte payload into a
// closest hit declared with a 16-byte one, selected by a constant SBT
// offset of 0 in the description (a public sample ships this shape and
// runs: the driver does not check payload types). The closest hit runs, so
// its shadow ray is a second level: two are needed, two are declared.

[[vk::binding(0, 0)]] RaytracingAccelerationStructure Scene : register(t0);
[[vk::binding(1, 0)]] RWTexture2D<float4> Output : register(u0);

struct CameraPayload { float3 color; };
struct HitPayload { float3 color; uint shadowed; };
struct ShadowPayload { uint shadowed; };

[shader("raygeneration")]
void RayGen()
{
    float2 uv = (DispatchRaysIndex().xy + 0.5) / DispatchRaysDimensions().xy;
    RayDesc ray = { float3(uv * 2 - 1, -1), 0.001, float3(0, 0, 1), 1000.0 };
    CameraPayload p = { float3(0, 0, 0) };
    TraceRay(Scene, RAY_FLAG_FORCE_OPAQUE, 0xFF, 0, 0, 0, ray, p);
    Output[DispatchRaysIndex().xy] = float4(p.color, 1);
}

[shader("closesthit")]
void Hit(inout HitPayload p, BuiltInTriangleIntersectionAttributes a)
{
    float3 at = WorldRayOrigin() + WorldRayDirection() * RayTCurrent();
    RayDesc ray = { at, 0.001, normalize(float3(1, 1, 0)), 1000.0 };
    ShadowPayload s = { 1 };
    TraceRay(Scene,
        RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_FORCE_OPAQUE | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER,
        0xFF, 0, 0, 1, ray, s);
    p.color = float3(a.barycentrics, 1) * (s.shadowed != 0 ? 0.2 : 1.0);
}

[shader("miss")]
void Miss(inout CameraPayload p) { p.color = float3(0, 0, 0.3); }

[shader("miss")]
void ShadowMiss(inout ShadowPayload p) { p.shadowed = 0; }
