#include "include/common.hlsli"

[shader("miss")]
void Miss(inout Payload p)
{
    float t = 0.5 * (normalize(WorldRayDirection()).y + 1.0);
    p.color = lerp(float3(1.0, 1.0, 1.0), float3(0.3, 0.5, 1.0), t);
    p.hitT = -1.0;
}
