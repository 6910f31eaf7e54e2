// Executed on a Vulkan driver by tests/hlsl_exec.rs: groupshared memory,
// barriers, atomics and byte-address buffers across one 64-thread group.
RWByteAddressBuffer raw : register(u0);
RWStructuredBuffer<uint> counts : register(u1);

groupshared uint total;
groupshared uint values[64];

[numthreads(64, 1, 1)]
void Main(uint gi : SV_GroupIndex)
{
    if (gi == 0)
        total = 0;
    GroupMemoryBarrierWithGroupSync();
    values[gi] = gi * 2;
    InterlockedAdd(total, gi);
    GroupMemoryBarrierWithGroupSync();
    uint v = raw.Load(gi * 4);
    raw.Store(256 + gi * 4, v + values[63 - gi]);
    if (gi == 0)
    {
        raw.Store2(512, uint2(total, 7));
        uint4 q = raw.Load4(0);
        raw.Store4(528, q.wzyx);
    }
    uint before;
    InterlockedMax(counts[0], gi);
    InterlockedAdd(counts[1], 1, before);
    InterlockedOr(counts[2], 1u << (gi % 32));
    // Only the thread that sees 0 swaps in its index + 1.
    uint seen;
    InterlockedCompareExchange(counts[3], 0u, gi + 1, seen);
    raw.InterlockedAdd(768, 2);
    uint prior;
    raw.InterlockedMax(772, gi * 3, prior);
}
