// 64-bit integers: arithmetic, shifts, conversions, literals, buffer layout.
struct Range
{
    uint64_t start;
    uint64_t size;
    uint flags;
};

StructuredBuffer<Range> ranges : register(t0);
RWStructuredBuffer<uint2> output : register(u0);

uint hash64(uint64_t value)
{
    return uint(value & 0xffffffff) ^ uint(value >> 32);
}

[numthreads(1, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    Range r = ranges[id.x];
    uint64_t end = r.start + r.size;
    int64_t delta = int64_t(r.size) - 5000000000ll;
    uint64_t big = 1ull << 40;
    uint64_t mixed = end * 3u + id.x;
    int small = -7;
    int64_t widened = small;
    int64_t negative = -7;
    uint64_t m = max(end, big);
    output[id.x] = uint2(hash64(mixed), uint(widened >> 1) + uint(negative)) + uint2(uint(delta < 0), hash64(m));
}
