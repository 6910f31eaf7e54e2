// Interface types whose Rust layouts are hard to get right: a row_major
// matrix, a 3x4 matrix, an array of structs and an int2 array whose last
// element shares its row with the next member, a bool, a nested struct in a
// payload. tests/build_script.rs compiles what rtlint::build generates for it.

struct Inner
{
    float2 uv;
    uint id;
};

struct Light
{
    float3 position;
    float radius;
    float3 color;
};

cbuffer Scene : register(b0)
{
    row_major float4x4 world;
    float4x4 view;
    float3x4 skew;
    Light lights[3];
    float fog;
    Inner inner;
    bool enabled;
    int2 counts[2];
    float2 tail;
};

struct NestedPayload
{
    Inner inner;
    float2 uvs[3];
    bool hit;
    float3x3 basis;
};

struct Constants
{
    float3 dir;
    uint flags;
    float4x4 mvp;
};

[[vk::push_constant]] ConstantBuffer<Constants> constants;

RaytracingAccelerationStructure tlas : register(t1);

[shader("raygeneration")]
void RayGen()
{
    RayDesc r;
    r.Origin = mul(world, float4(0, 0, 0, 1)).xyz + mul(view, float4(constants.dir, 0)).xyz + mul(skew, float4(1, 1, 1, 1)).xyz;
    r.Direction = lights[2].color + float3(fog, inner.uv) + float3(counts[1], tail.x) + constants.mvp[0].xyz;
    r.TMin = enabled ? 0.0 : 1.0;
    r.TMax = 100.0;
    NestedPayload p = (NestedPayload)0;
    TraceRay(tlas, 0, 0xFF, 0, 1, 0, r, p);
}
