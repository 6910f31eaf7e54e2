#include "include/common.hlsli"

[shader("closesthit")]
void ClosestHit(inout Payload p, in BuiltInTriangleIntersectionAttributes attr)
{
    float3 bary = float3(1.0 - attr.barycentrics.x - attr.barycentrics.y, attr.barycentrics);
    p.color = bary * (0.5 + 0.5 * sin(push.time));
    p.hitT = RayTCurrent();
    p.depth = p.depth + 1;
}
