// Depth-comparison sampling: SamplerComparisonState with SampleCmpLevelZero
// in a hit shader, SampleCmp in a pixel shader.
Texture2D<float> shadowMap : register(t0);
Texture2DArray<float> cascades : register(t1);
SamplerComparisonState shadowSampler : register(s0);

struct Payload
{
    float visibility;
};

float shadowAt(float2 uv, float depth)
{
    return shadowMap.SampleCmpLevelZero(shadowSampler, uv, depth);
}

[shader("closesthit")]
void ShadowHit(inout Payload p, in BuiltInTriangleIntersectionAttributes a)
{
    p.visibility = shadowAt(a.barycentrics, RayTCurrent() / 100.0)
        * cascades.SampleCmpLevelZero(shadowSampler, float3(a.barycentrics, 1), 0.5);
}

[shader("pixel")]
float4 Lit(float4 position : SV_Position, float2 uv : TEXCOORD0) : SV_Target
{
    float lit = shadowMap.SampleCmp(shadowSampler, uv, position.z);
    return float4(lit.xxx, 1);
}
