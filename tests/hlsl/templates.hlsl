// Function templates (type and value parameters, explicit and deduced
// arguments, defaults), struct templates, and method templates.
template<typename T>
T interpolate(T v[3], float2 bary)
{
    return v[0] + bary.x * (v[1] - v[0]) + bary.y * (v[2] - v[0]);
}

template<typename T, uint N>
T sumFirst(vector<T, N> v)
{
    T s = 0;
    [unroll] for (uint i = 0; i < N; i++)
        s += v[i];
    return s;
}

template<uint COUNT = 4>
float average(float values[8])
{
    float s = 0;
    for (uint i = 0; i < COUNT; i++)
        s += values[i];
    return s / COUNT;
}

template<typename T>
struct Pair
{
    T first;
    T second;

    T sum() { return first + second; }
};

struct Sampler
{
    uint seed;

    template<uint DIMS>
    float next()
    {
        seed = seed * 1664525u + 1013904223u + DIMS;
        return float(seed >> 8) / 16777216.0;
    }
};

template<RAY_FLAG FLAGS>
bool anyHit(RayQuery<FLAGS> q)
{
    return q.CommittedStatus() != COMMITTED_NOTHING;
}

RWStructuredBuffer<float4> output : register(u0);
ByteAddressBuffer vertexData : register(t0);

struct PackedVertex
{
    float3 position;
    uint normal;
    float2 uv[2];
};

[numthreads(8, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    float3 normals[3] = { float3(1, 0, 0), float3(0, 1, 0), float3(0, 0, 1) };
    float2 uvs[3] = { float2(0, 0), float2(1, 0), float2(0, 1) };
    float2 bary = float2(0.25, 0.5);
    float3 n = interpolate(normals, bary);
    float2 uv = interpolate<float2>(uvs, bary);
    float s3 = sumFirst(float3(1, 2, 3));
    uint s2 = sumFirst(uint2(4, 5));
    float values[8] = { 1, 2, 3, 4, 5, 6, 7, 8 };
    Pair<float3> p;
    p.first = n;
    p.second = float3(uv, 0);
    Pair<uint> q;
    q.first = 1;
    q.second = s2;
    Sampler rng;
    rng.seed = id.x;
    float r = rng.next<2>() + rng.next<3>();
    // Typed loads from a byte-address buffer.
    float3 position = vertexData.Load<float3>(id.x * 12);
    uint2 packed = vertexData.Load<uint2>(id.x * 8 + 4096);
    r += position.x + packed.y;
    PackedVertex pv = vertexData.Load<PackedVertex>(id.x * sizeof(PackedVertex));
    r += pv.position.y + pv.uv[1].x + pv.normal;
    output[id.x] = float4(p.sum(), s3 + q.sum() + average(values) + average<8>(values) + r);
}
