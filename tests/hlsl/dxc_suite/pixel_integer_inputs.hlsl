// Integer pixel-shader inputs are not interpolated: Vulkan wants `Flat` on
// every one, 16-bit and 32-bit, and on the subgroup built-ins a pixel
// shader reads (compiled with -enable-16bit-types).

struct In {
    int16_t  a : A;
    uint16_t b : B;
    uint2    c : C;
    float    d : D;
};

float4 main(In i) : SV_Target
{
    uint lanes = WaveGetLaneCount();
    uint lane = WaveGetLaneIndex();
    return float4(i.a, i.b, i.c.x + lanes, i.d + lane);
}
