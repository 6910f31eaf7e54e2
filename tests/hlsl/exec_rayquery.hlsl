// Executed on a Vulkan driver by tests/hlsl_exec.rs: inline ray tracing of the
// triangle scene, committing candidates by hand like the any-hit shader of
// exec_pipeline.hlsl does.
RaytracingAccelerationStructure scene : register(t0);
RWStructuredBuffer<float4> outBuf : register(u1);

[numthreads(16, 1, 1)]
void Query(uint3 tid : SV_DispatchThreadID)
{
    uint2 id = uint2(tid.x % 4, tid.x / 4);
    float2 uv = (float2(id) + 0.5) / 4.0;
    RayDesc ray;
    ray.Origin = float3(uv * 2.0 - 1.0 + float2(0.1, 0.0), -1.0);
    ray.Direction = float3(0, 0, 1);
    ray.TMin = 0.0;
    ray.TMax = 10.0;
    RayQuery<RAY_FLAG_NONE> q;
    q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, ray);
    while (q.Proceed())
    {
        if (q.CandidateType() == CANDIDATE_NON_OPAQUE_TRIANGLE && q.CandidateTriangleBarycentrics().x <= 0.5)
            q.CommitNonOpaqueTriangleHit();
    }
    float4 result = float4(0, 0, 1, 0);
    if (q.CommittedStatus() == COMMITTED_TRIANGLE_HIT)
        result = float4(q.CommittedTriangleBarycentrics(), q.CommittedRayT(), 1);
    outBuf[tid.x] = result;
}
