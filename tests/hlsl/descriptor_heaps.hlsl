// SM 6.6 descriptor heaps: resources and samplers taken by index, typed by
// the variable they initialize or by a cast.
struct Material
{
    uint albedo;
    uint sampler;
    uint normals;
};

ConstantBuffer<Material> material : register(b0);
RWStructuredBuffer<float4> output : register(u1);

[numthreads(8, 8, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    Texture2D<float4> albedo = ResourceDescriptorHeap[material.albedo];
    SamplerState linear = SamplerDescriptorHeap[material.sampler];
    StructuredBuffer<float4> normals = ResourceDescriptorHeap[NonUniformResourceIndex(material.normals + id.x)];
    float4 c = albedo.SampleLevel(linear, float2(id.xy) / 8.0, 0);
    uint w, h;
    ((Texture2D<float4>)ResourceDescriptorHeap[material.albedo + 1]).GetDimensions(w, h);
    output[id.x] = c + normals[id.y] + float4(w, h, 0, 0);
}
