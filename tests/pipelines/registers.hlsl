// DXR-style registers with no [[vk::binding]]: t0, u0 and b0 all become
// binding 0 of set 0 when compiled for Vulkan unless the build shifts each
// register class into a range of its own (DXC's -fvk-t-shift and friends).
RaytracingAccelerationStructure Scene : register(t0);
RWTexture2D<float4> Output : register(u0);
cbuffer Camera : register(b0) { float4 origin; };

struct Payload { float4 color; };

[shader("raygeneration")]
void RayGen()
{
    RayDesc ray;
    ray.Origin = origin.xyz;
    ray.Direction = float3(0, 0, 1);
    ray.TMin = 0.001;
    ray.TMax = 100.0;
    Payload p = { float4(0, 0, 0, 0) };
    TraceRay(Scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    Output[DispatchRaysIndex().xy] = p.color;
}

[shader("miss")]
void Miss(inout Payload p) { p.color = float4(0, 0, 0.2, 1); }

[shader("closesthit")]
void Hit(inout Payload p, BuiltInTriangleIntersectionAttributes a)
{
    p.color = float4(a.barycentrics, 0, 1);
}
