// Inline ray tracing in a compute shader: ambient occlusion with RayQuery,
// committing procedural hits by hand.
RaytracingAccelerationStructure tlas : register(t0);
RWStructuredBuffer<float> occlusion : register(u1);

struct Params
{
    float3 origin;
    uint rayCount;
    float radius;
};
ConstantBuffer<Params> params : register(b2);

[numthreads(8, 8, 1)]
void AmbientOcclusion(uint3 tid : SV_DispatchThreadID, uint gi : SV_GroupIndex)
{
    RayQuery<RAY_FLAG_CULL_BACK_FACING_TRIANGLES> q;
    uint hits = 0;
    for (uint i = 0; i < params.rayCount; ++i)
    {
        float a = (float)(i + tid.x) * 2.39996;
        RayDesc ray;
        ray.Origin = params.origin;
        ray.Direction = normalize(float3(cos(a), sin(a), 0.5));
        ray.TMin = 0.001;
        ray.TMax = params.radius;
        q.TraceRayInline(tlas, RAY_FLAG_NONE, 0xFF, ray);
        while (q.Proceed())
        {
            if (q.CandidateType() == CANDIDATE_PROCEDURAL_PRIMITIVE)
            {
                float t = 0.5 * params.radius;
                if (t < q.CommittedRayT())
                    q.CommitProceduralPrimitiveHit(t);
            }
            else if (q.CandidateTriangleBarycentrics().x < 0.99)
            {
                q.CommitNonOpaqueTriangleHit();
            }
            else
            {
                q.Abort();
            }
        }
        switch (q.CommittedStatus())
        {
        case COMMITTED_TRIANGLE_HIT:
            hits += q.CommittedTriangleFrontFace() ? 1 : 0;
            break;
        case COMMITTED_PROCEDURAL_PRIMITIVE_HIT:
            hits += 1;
            break;
        default:
            break;
        }
        float3 o = q.CommittedObjectRayOrigin() + q.WorldRayDirection() * q.RayTMin();
        hits += (uint)(q.CommittedInstanceIndex() + q.CommittedPrimitiveIndex() + q.CommittedGeometryIndex()) * (uint)o.x * 0;
    }
    occlusion[tid.y * 64 + tid.x] = 1.0 - (float)hits / (float)max(params.rayCount, 1u) + gi * 0.0;
}
