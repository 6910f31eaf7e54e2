// Pixel shaders: semantics on parameters, struct members and the return
// value; derivatives in the entry body and in a helper; implicit-LOD Sample;
// discard.
Texture2D<float4> albedo : register(t0);
SamplerState linearSampler : register(s0);

struct VertexOut {
    float4 position : SV_Position;
    float2 uv : TEXCOORD0;
    float3 normal : NORMAL;
    uint material : MATERIAL;
};

struct Targets {
    float4 color : SV_Target0;
    float4 normals : SV_Target2;
};

float edge(float v)
{
    if (v < 0) {
        discard;
    }
    return fwidth(v);
}

[shader("pixel")]
Targets Shade(VertexOut input, float4 tint : COLOR, bool front : SV_IsFrontFace, out float4 extra : SV_Target1)
{
    if (tint.a == 0) {
        discard;
    }
    float2 dx = ddx(input.uv);
    float2 dy = ddy(input.uv);
    float3 n = ddx_fine(input.normal) + ddy_fine(input.normal)
        + ddx_coarse(input.normal) + ddy_coarse(input.normal);
    Targets t;
    t.color = float4(dx, dy) * tint + edge(input.position.x);
    t.normals = front ? float4(n, float(input.material)) : albedo.SampleLevel(linearSampler, input.uv, 0);
    extra = float4(fwidth(input.uv), 0, 1);
    return t;
}

[shader("pixel")]
float4 Explicit([[vk::location(3)]] float2 uv : TEXCOORD0, [[vk::location(1)]] float value : VALUE) : SV_Target
{
    return float4(ddx(uv), ddy(value), 1) + albedo.Sample(linearSampler, uv);
}
