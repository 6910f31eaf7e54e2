// A ray-generation shader that calls callable shaders by index.
struct Material
{
    float3 albedo;
    uint kind;
};

RWTexture2D<float4> image : register(u0);

[shader("raygeneration")]
void Gen()
{
    uint2 id = DispatchRaysIndex().xy;
    Material m;
    m.albedo = float3(0.5, 0.5, 0.5);
    m.kind = id.x % 2;
    CallShader(m.kind, m);
    image[id] = float4(m.albedo, 1);
}

[shader("callable")]
void Checker(inout Material m)
{
    uint2 id = DispatchRaysIndex().xy;
    m.albedo *= ((id.x / 8 + id.y / 8) & 1) ? 1.0 : 0.25;
}

[shader("callable")]
void Tint(inout Material m)
{
    m.albedo.rb = m.albedo.br * float2(0.9, 1.1);
}

[[vk::constant_id(3)]] const bool USE_TINT = true;
[[vk::constant_id(4)]] const uint TINT_SHADER = 1;
[[vk::constant_id(5)]] const float STRENGTH = 0.5;

[shader("raygeneration")]
void GenSpecialized()
{
    uint2 id = DispatchRaysIndex().xy;
    Material m;
    m.albedo = STRENGTH;
    m.kind = 0;
    if (USE_TINT)
        CallShader(TINT_SHADER, m);
    image[id] = float4(m.albedo, 1);
}
