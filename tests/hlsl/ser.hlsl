// Shader Execution Reordering (SM 6.9): dx::HitObject and
// dx::MaybeReorderThread → SPV_NV_shader_invocation_reorder.
using namespace dx;

struct [raypayload] Payload
{
    float3 color : read(caller) : write(closesthit, miss);
};

class Material;

RaytracingAccelerationStructure scene : register(t0);
RWTexture2D<float4> image : register(u0);

// A hit object is passed to a function as its variable.
uint materialOf(in HitObject h) { return h.IsHit() ? h.GetInstanceID() : 0; }

[shader("raygeneration")]
void Gen()
{
    uint2 pixel = DispatchRaysIndex().xy;
    RayDesc ray;
    ray.Origin = float3(pixel, -1);
    ray.Direction = float3(0, 0, 1);
    ray.TMin = 0.001;
    ray.TMax = 1000;
    Payload p;
    p.color = 0;
    dx::HitObject hit = dx::HitObject::TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    uint material = materialOf(hit);
    dx::MaybeReorderThread(hit, material, 4);
    HitObject::Invoke(hit, p);
    if (hit.IsMiss())
    {
        HitObject sky = HitObject::MakeMiss(RAY_FLAG_NONE, 1, ray);
        MaybeReorderThread(sky);
        HitObject::Invoke(sky, p);
    }
    HitObject nop;
    nop = HitObject::MakeNop();
    MaybeReorderThread(pixel.x & 1, 1);
    float t = hit.IsNop() ? 0 : hit.GetRayTCurrent();
    image[pixel] = float4(p.color, t + nop.IsNop() + hit.GetShaderTableIndex());
}

[shader("closesthit")]
void Shade(inout Payload p, in BuiltInTriangleIntersectionAttributes a)
{
    p.color = float3(a.barycentrics, 1);
}

[shader("miss")]
void Sky(inout Payload p)
{
    p.color = float3(0.2, 0.4, 0.8);
}
