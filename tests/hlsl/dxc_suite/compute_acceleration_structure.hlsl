// A compute shader that queries an acceleration structure needs ray
// queries, not ray-tracing pipelines: RayQueryKHR alone, so that a device
// with only VK_KHR_ray_query runs it.

RaytracingAccelerationStructure scene : register(t0);
RWStructuredBuffer<float> hits : register(u0);

[numthreads(8, 1, 1)]
void main(uint3 id : SV_DispatchThreadID)
{
    RayDesc ray;
    ray.Origin = float3(id.x, 0, 0);
    ray.Direction = float3(0, 0, 1);
    ray.TMin = 0.0;
    ray.TMax = 100.0;
    RayQuery<RAY_FLAG_NONE> q;
    q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, ray);
    q.Proceed();
    hits[id.x] = q.CommittedStatus() == COMMITTED_TRIANGLE_HIT ? q.CommittedRayT() : -1.0;
}
