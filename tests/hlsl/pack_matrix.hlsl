// `#pragma pack_matrix(row_major)`: matrices declared after it are row
// major unless marked `column_major`; `pack_matrix(column_major)` restores
// the default.
#pragma pack_matrix(row_major)
cbuffer Camera : register(b0)
{
    float4x4 viewProj;
    column_major float4x4 explicitColumns;
};

struct Instance
{
    float3x4 objectToWorld;
};

#pragma pack_matrix(column_major)
cbuffer Later : register(b1)
{
    float4x4 columns;
};

StructuredBuffer<Instance> instances : register(t0);
StructuredBuffer<float4x4> transforms : register(t1);
RWStructuredBuffer<float4> output : register(u0);

[numthreads(1, 1, 1)]
void Main()
{
    float4 p = mul(viewProj, float4(1, 2, 3, 1));
    p += mul(explicitColumns, p) + mul(columns, p) + mul(transforms[1], p);
    output[0] = p + float4(mul(instances[0].objectToWorld, p), 0);
}
