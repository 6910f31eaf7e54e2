// Wave intrinsics in a compute shader and in a closest-hit shader.
RWStructuredBuffer<uint4> counts : register(u0);
RWStructuredBuffer<float4> sums : register(u1);

[numthreads(64, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    uint lane = WaveGetLaneIndex();
    uint width = WaveGetLaneCount();
    bool odd = (lane & 1) != 0;
    uint4 ballot = WaveActiveBallot(odd);
    uint active = WaveActiveCountBits(true);
    uint before = WavePrefixCountBits(odd);
    float value = float(id.x);
    float total = WaveActiveSum(value);
    float3 prefix = WavePrefixSum(float3(value, 1, 2));
    int product = WaveActiveProduct(int(lane % 3) + 1);
    uint lowest = WaveActiveMin(lane);
    float highest = WaveActiveMax(value);
    uint2 prefixProduct = WavePrefixProduct(uint2(1, lane + 1));
    uint bits = WaveActiveBitAnd(lane) | WaveActiveBitOr(lane) | WaveActiveBitXor(lane);
    float first = WaveReadLaneFirst(value);
    float2 neighbour = WaveReadLaneAt(float2(value, total), (lane + 1) % width);
    bool all = WaveActiveAllTrue(lane < width);
    bool any = WaveActiveAnyTrue(odd);
    bool same = WaveActiveAllEqual(width);
    if (WaveIsFirstLane())
        counts[id.x / 64] = ballot + uint4(active, before, lowest, bits);
    sums[id.x] = float4(total + prefix.x + product + highest + prefixProduct.y, first, neighbour.y, all && any && same);
}

struct Payload
{
    float4 color;
};

[shader("closesthit")]
void Hit(inout Payload p, in BuiltInTriangleIntersectionAttributes a)
{
    p.color = float4(WaveActiveSum(a.barycentrics), WaveGetLaneIndex(), 1);
}
