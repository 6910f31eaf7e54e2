// Executed on a Vulkan driver with VK_KHR_ray_tracing_position_fetch by
// tests/hlsl_exec.rs: a 4x4 launch at one tilted triangle whose structure
// allows data access. The closest hit reads the hit triangle's vertex
// positions through DXC's inline-SPIR-V built-in and writes the face normal
// and a checksum of the positions; misses write -1.
[[vk::ext_extension("SPV_KHR_ray_tracing_position_fetch")]]
[[vk::ext_capability(5336)]]
[[vk::ext_builtin_input(5335)]]
static const float3 gl_HitTriangleVertexPositions[3];

RaytracingAccelerationStructure scene : register(t0);
RWStructuredBuffer<float4> outBuf : register(u1);

struct Payload
{
    float4 value;
};

[shader("raygeneration")]
void Gen()
{
    uint2 id = DispatchRaysIndex().xy;
    uint2 dim = DispatchRaysDimensions().xy;
    float2 uv = (float2(id) + 0.5) / float2(dim);
    RayDesc ray;
    ray.Origin = float3(uv * 2.0 - 1.0 + float2(0.1, 0.0), -1.0);
    ray.Direction = float3(0, 0, 1);
    ray.TMin = 0.0;
    ray.TMax = 10.0;
    Payload p;
    p.value = float4(0, 0, 0, 0);
    TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    outBuf[id.y * dim.x + id.x] = p.value;
}

[shader("miss")]
void Miss(inout Payload p)
{
    p.value = float4(-1, -1, -1, -1);
}

[shader("closesthit")]
void FaceNormal(inout Payload p, in BuiltInTriangleIntersectionAttributes a)
{
    float3 v0 = gl_HitTriangleVertexPositions[0];
    float3 v1 = gl_HitTriangleVertexPositions[1];
    float3 v2 = gl_HitTriangleVertexPositions[2];
    // Weights 1, 2, 3 so that a permuted or repeated vertex changes the sum.
    float3 s = v0 + 2.0 * v1 + 3.0 * v2;
    p.value = float4(normalize(cross(v1 - v0, v2 - v0)), s.x + 10.0 * s.y + 100.0 * s.z);
}
