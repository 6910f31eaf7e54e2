// Executed on a Vulkan driver by tests/hlsl_exec.rs: a procedural sphere
// (intersection shader, ReportHit with a user attribute struct, HitKind) and a
// callable shader.
RaytracingAccelerationStructure scene : register(t0);
RWStructuredBuffer<float4> outBuf : register(u1);

struct Payload
{
    float4 color;
};

struct Attributes
{
    float3 normal;
    float t;
};

struct CallData
{
    float value;
};

[shader("raygeneration")]
void Gen()
{
    uint2 id = DispatchRaysIndex().xy;
    float2 uv = (float2(id) + 0.5) / float2(DispatchRaysDimensions().xy);
    RayDesc ray = { float3(uv * 2.0 - 1.0 + float2(0.1, 0.0), -1.0), 0.0, float3(0, 0, 1), 10.0 };
    Payload p = (Payload)0;
    TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    CallData c;
    c.value = (float)id.x;
    CallShader(0, c);
    outBuf[id.y * 4 + id.x] = float4(p.color.xyz, p.color.w + c.value);
}

[shader("miss")]
void Miss(inout Payload p)
{
    p.color = float4(0, 0, 0, 100);
}

[shader("intersection")]
void Sphere()
{
    float3 center = float3(0, 0, 1);
    float3 oc = ObjectRayOrigin() - center;
    float3 d = ObjectRayDirection();
    float b = dot(oc, d);
    float disc = b * b - (dot(oc, oc) - 0.25);
    if (disc > 0)
    {
        float t = -b - sqrt(disc);
        Attributes a;
        a.normal = (ObjectRayOrigin() + t * d - center) / 0.5;
        a.t = t;
        ReportHit(t, 7, a);
    }
}

[shader("closesthit")]
void SphereHit(inout Payload p, in Attributes a)
{
    p.color = float4(a.normal.z, RayTCurrent(), (float)HitKind(), 0);
}

[shader("callable")]
void Twice(inout CallData c)
{
    c.value = c.value * 2 + 1;
}
