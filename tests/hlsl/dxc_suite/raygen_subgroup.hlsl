// A ray-generation shader may resume on another subgroup after TraceRay:
// Vulkan wants the subgroup built-ins it reads decorated `Volatile`.

struct Payload {
    float4 color;
};

RaytracingAccelerationStructure scene : register(t0);
RWTexture2D<float4> output : register(u0);

[shader("raygeneration")]
void RayGen()
{
    RayDesc ray;
    ray.Origin = float3(0, 0, 0);
    ray.Direction = float3(0, 0, 1);
    ray.TMin = 0.0;
    ray.TMax = 100.0;
    Payload p = (Payload)0;
    TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    output[DispatchRaysIndex().xy] = p.color * WaveGetLaneCount() + WaveGetLaneIndex();
}

[shader("miss")]
void Miss(inout Payload p)
{
    p.color = float4(WaveGetLaneCount(), 0, 0, 1);
}
