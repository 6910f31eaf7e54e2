// Local names for resources (`Texture2D t = textures[i];`), cube-map and
// 1D texture arrays, a variable used in its own initializer, hex floats.
Texture2D<float4> textures[16] : register(t0);
TextureCubeArray<float4> probes : register(t16);
Texture1DArray<float> ramps : register(t17);
SamplerState linearSampler : register(s0);
RWStructuredBuffer<float4> output : register(u0);

RayDesc makeRay(float3 origin)
{
    RayDesc r;
    r.Origin = origin;
    r.Direction = float3(0, 0, 1);
    r.TMin = 0x1.0p-10;
    r.TMax = 0x1.8p4;
    return r;
}

[numthreads(8, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    Texture2D<float4> albedo = textures[NonUniformResourceIndex(id.x)];
    SamplerState s = linearSampler;
    float4 c = albedo.SampleLevel(s, float2(0.5, 0.5), 0);
    c += probes.SampleLevel(s, float4(0, 1, 0, id.x), 0);
    c.x += ramps.SampleLevel(s, float2(0.25, 1), 0);
    uint w, h, layers;
    probes.GetDimensions(w, h, layers);
    RayDesc ray = ray = makeRay(c.xyz);
    output[id.x] = c + float4(ray.TMin, ray.TMax, w, layers);
}
