// `countbits` of 16-bit integers (-enable-16bit-types): zero-extended to
// 32 bits for `OpBitCount`, a `uint` result (tests/hlsl_compile.rs).
StructuredBuffer<int16_t4> signedIn : register(t0);
StructuredBuffer<uint16_t> unsignedIn : register(t1);
RWStructuredBuffer<uint4> counts : register(u0);

[numthreads(4, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    // A negative int16_t counts its 16 bits only: countbits((int16_t)-1) is 16.
    uint4 c = countbits(signedIn[id.x]);
    c.x += countbits(unsignedIn[id.x]);
    counts[id.x] = c;
}
