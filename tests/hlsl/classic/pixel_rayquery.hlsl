// A classic pixel shader: no [shader(...)], the stage comes from the
// command line (`-E main -T ps_6_5`). It traces an inline shadow ray.
RaytracingAccelerationStructure scene : register(t0);
cbuffer Light : register(b0)
{
    float3 lightDirection;
    float lightIntensity;
};

struct PixelIn
{
    float4 position : SV_Position;
    float3 worldPos : TEXCOORD0;
    float3 normal : NORMAL;
};

float4 main(PixelIn input) : SV_Target
{
    RayQuery<RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER> q;
    RayDesc ray;
    ray.Origin = input.worldPos + input.normal * 1e-3;
    ray.Direction = -lightDirection;
    ray.TMin = 0.0;
    ray.TMax = 1e4;
    q.TraceRayInline(scene, RAY_FLAG_NONE, 0xFF, ray);
    q.Proceed();
    float lit = q.CommittedStatus() == COMMITTED_NOTHING ? 1.0 : 0.0;
    float ndotl = saturate(dot(normalize(input.normal), -lightDirection));
    return float4((ndotl * lit * lightIntensity).xxx, 1);
}
