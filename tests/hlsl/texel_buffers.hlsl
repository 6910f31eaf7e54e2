// Typed buffers: Buffer<T> (uniform texel buffers) and RWBuffer<T> (storage
// texel buffers) with Load, [] and GetDimensions.
Buffer<float4> colors : register(t0);
Buffer<uint> indices : register(t1);
RWBuffer<float> weights : register(u0);
RWBuffer<uint2> pairs : register(u1);

[numthreads(64, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    uint count;
    colors.GetDimensions(count);
    uint i = indices[id.x % count];
    float4 c = colors.Load(i) + colors[i + 1];
    weights[id.x] = c.x * weights.Load(id.x);
    pairs[id.x] = uint2(i, pairs[id.x].y + 1);
}
