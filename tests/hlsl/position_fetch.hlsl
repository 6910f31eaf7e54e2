// Ray-tracing position fetch through DXC's inline-SPIR-V attributes: the
// hit triangle's vertex positions as a built-in input.
[[vk::ext_extension("SPV_KHR_ray_tracing_position_fetch")]]
[[vk::ext_capability(5336)]]
[[vk::ext_builtin_input(5335)]]
static const float3 gl_HitTriangleVertexPositions[3];

struct Payload
{
    float3 normal;
};

[shader("closesthit")]
void FaceNormal(inout Payload p, in BuiltInTriangleIntersectionAttributes a)
{
    float3 e1 = gl_HitTriangleVertexPositions[1] - gl_HitTriangleVertexPositions[0];
    float3 e2 = gl_HitTriangleVertexPositions[2] - gl_HitTriangleVertexPositions[0];
    p.normal = normalize(cross(e1, e2));
}

[shader("miss")]
void Sky(inout Payload p)
{
    p.normal = 0;
}
