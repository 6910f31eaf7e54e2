// A function returning a ray query: the caller's variable is made in it.
RaytracingAccelerationStructure scene : register(t0);
RWStructuredBuffer<float4> o : register(u0);
typedef RayQuery<RAY_FLAG_FORCE_OPAQUE> ClosestQuery;
template<typename Q>
Q traceScene(RayDesc ray)
{
    Q q;
    q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, ray);
    while (q.Proceed()) {}
    return q;
}
[numthreads(1,1,1)] void m(uint3 id : SV_DispatchThreadID) {
  RayDesc r; r.Origin = float3(id); r.Direction = float3(0,0,1); r.TMin = 0; r.TMax = 10;
  ClosestQuery q = traceScene<ClosestQuery>(r);
  o[0] = float4(q.CommittedRayT(), q.CommittedStatus() == COMMITTED_TRIANGLE_HIT, 0, 1);
}
