// 16-bit arithmetic on the driver (compiled with -enable-16bit-types): the
// thread id keeps the values from being folded at compile time.

#ifdef __SLANG__
// Slang (the differential in tests/hlsl_exec.rs) has no min-precision types;
// with -enable-16bit-types DXC makes them these.
typedef half min16float;
typedef int16_t min16int;
#endif

RWStructuredBuffer<half> OutH : register(u0);
RWStructuredBuffer<int16_t> OutI : register(u1);
RWStructuredBuffer<uint16_t> OutU : register(u2);
RWStructuredBuffer<float> OutF : register(u3);
ByteAddressBuffer Raw : register(t5);
cbuffer Inputs : register(b4)
{
    half scale;      // 0.5
    uint16_t count;  // 7
    int16_t neg;     // -2
    float base;      // 10
};

[numthreads(1, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    uint s = id.x;
    half a = (half)(s + 3);
    OutH[0] = a * scale + 0.25;
    OutH[1] = sqrt(a + 1.0);
    // 2051 is not a half: it rounds to 2052.
    OutH[2] = a + 2048.0;
    OutH[3] = max(-a, scale) + 1;
    OutH[4] = (half)(count * 3) / 8.0;
    min16float m = a;
    OutH[5] = m > a ? m : -m;
    OutH[6] = (half)(base / 100.0);
    // Row vector (3, 1, 0) times a half3x3: the middle column, 2*3 + 5 = 11.
    // One lane: the sum is its own value.
    OutH[9] = WaveActiveSum(a);
    OutH[7] = mul(half3(a, 1, 0), half3x3(1, 2, 3, 4, 5, 6, 7, 8, 9)).y;

    OutI[0] = neg * (int16_t)a;
    int16_t big = 32767;
    // 16-bit wrap-around.
    OutI[1] = big + (int16_t)(s + 1);
    OutI[2] = (int16_t)(-a * 3.0);
    min16int mi = neg;
    OutI[3] = abs(mi) + sign(mi);

    OutU[0] = count << 13;
    OutU[1] = count - 8;
    // The bits of half 1.5 (0x3e00), and back.
    OutU[2] = asuint16(scale * a);
    OutU[3] = ~count;
    // 16-bit loads at 2-byte addresses: the high half of word 0, then word 1's halves.
    half3 raw = Raw.Load<half3>(s + 2);
    OutH[10] = raw.x + raw.y + raw.z;
    OutU[4] = Raw.Load<uint16_t>(s + 6);
    OutH[8] = asfloat16(OutU[2]) + asfloat16((int16_t)0x3c00);
    OutI[4] = asint16(-scale);

    OutF[0] = a + base;
    OutF[1] = (float)((half)0.1);
    OutF[2] = length(half2(3, 4) * (half)(s + 1));
}
