// Executed by tests/hlsl_exec.rs on a driver with
// VK_NV_ray_tracing_invocation_reorder: a 4x4 launch at one triangle. The
// ray-generation shader traces into a hit object, reorders, invokes it, and
// on a miss makes and invokes a second miss (shader 1); the output records
// which shaders ran and what the hit object reported.
using namespace dx;

RaytracingAccelerationStructure scene : register(t0);
RWStructuredBuffer<float4> outBuf : register(u1);

struct Payload
{
    float4 value;
};

[shader("raygeneration")]
void Gen()
{
    uint2 id = DispatchRaysIndex().xy;
    uint2 dim = DispatchRaysDimensions().xy;
    float2 uv = (float2(id) + 0.5) / float2(dim);
    RayDesc ray;
    ray.Origin = float3(uv * 2.0 - 1.0 + float2(0.1, 0.0), -1.0);
    ray.Direction = float3(0, 0, 1);
    ray.TMin = 0.0;
    ray.TMax = 10.0;
    Payload p;
    p.value = float4(0, 0, 0, 0);
    HitObject hit = HitObject::TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    MaybeReorderThread(hit, hit.IsHit() ? 1 : 0, 1);
    HitObject::Invoke(hit, p);
    if (hit.IsMiss())
    {
        HitObject sky = HitObject::MakeMiss(RAY_FLAG_NONE, 1, ray);
        HitObject::Invoke(sky, p);
    }
    float t = hit.IsHit() ? hit.GetRayTCurrent() : -1.0;
    float seen = p.value.w + (hit.IsMiss() ? 10.0 : 0.0) + (hit.IsHit() ? 20.0 : 0.0);
    outBuf[id.y * dim.x + id.x] = float4(p.value.xy, t, seen);
}

[shader("miss")]
void Miss(inout Payload p)
{
    p.value = float4(0, 0, 0, 2);
}

[shader("miss")]
void Sky(inout Payload p)
{
    p.value.w += 3;
}

[shader("closesthit")]
void Hit(inout Payload p, in BuiltInTriangleIntersectionAttributes a)
{
    p.value = float4(a.barycentrics, 0, 1);
}
