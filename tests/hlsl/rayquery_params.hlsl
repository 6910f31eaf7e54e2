// Ray queries passed to helpers (and to a template deducing the flags).
RaytracingAccelerationStructure scene : register(t0);
RWStructuredBuffer<float4> o : register(u0);
struct HitInfo { uint instance; float2 bary; };
template<RAY_FLAG F>
HitInfo committed(RayQuery<F> q) { HitInfo h; h.instance = q.CommittedInstanceIndex(); h.bary = q.CommittedTriangleBarycentrics(); return h; }
bool hit(in RayQuery<RAY_FLAG_FORCE_OPAQUE> q) { return q.CommittedStatus() == COMMITTED_TRIANGLE_HIT; }
[numthreads(1,1,1)] void m() {
  RayQuery<RAY_FLAG_FORCE_OPAQUE> q;
  RayDesc r; r.Origin = 0; r.Direction = float3(0,0,1); r.TMin = 0; r.TMax = 10;
  q.TraceRayInline(scene, 0, 0xff, r);
  q.Proceed();
  HitInfo h = committed(q);
  o[0] = float4(h.bary, h.instance, hit(q));
}
