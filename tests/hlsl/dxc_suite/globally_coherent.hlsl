// `globallycoherent` buffers and images are `Coherent`; the others are not.

globallycoherent RWByteAddressBuffer counters : register(u0);
globallycoherent RWStructuredBuffer<uint> flags : register(u1);
globallycoherent RWTexture2D<float4> image : register(u2);
RWStructuredBuffer<uint> results : register(u3);

[numthreads(64, 1, 1)]
void main(uint3 id : SV_DispatchThreadID)
{
    uint before;
    counters.InterlockedAdd(0, 1, before);
    flags[id.x] = before;
    image[id.xy] = float4(before, 0, 0, 1);
    results[id.x] = flags[(id.x + 1) % 64];
}
