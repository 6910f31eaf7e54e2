// `sizeof(T)` (scalars packed, as DXC computes it), MSVC spellings
// (`unsigned int2`, `1.#INF`) and functional casts to structs `S(v)`.
#define META_COUNT (3 * sizeof(uint))

struct Packed
{
    float4 data0;
};

struct Vertex
{
    float3 position;
    float weight;
};

struct Mixed
{
    float a;
    float3 b;
    uint2 c[2];
};

Vertex unpack(Packed p)
{
    Vertex v;
    v.position = p.data0.xyz;
    v.weight = p.data0.w;
    return v;
}

RWByteAddressBuffer meta : register(u0);
RWStructuredBuffer<float4> output : register(u1);

[numthreads(4, 4, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    uint count = meta.Load(META_COUNT);
    static const float FAR = 1.#INF;
    Vertex v = unpack(Packed(float4(id, 1)));
    Vertex w = Vertex(float3(1, 2, 3), 4);
    uint sizes = sizeof(float3) + sizeof(Mixed) * 100 + sizeof(float4x4) * 10000;
    output[(unsigned int)id.x].x = (float)(unsigned int2(id.xy).y);
    output[count] = float4(v.position + w.position, min(FAR, sizes));
}
