// 16-bit specialization constants (-enable-16bit-types): `OpSpecConstant`
// of the 16-bit type, its default in the low bits of one word
// (tests/hlsl_compile.rs).
[[vk::constant_id(7)]] const half kGain = 1.5;
[[vk::constant_id(8)]] const int16_t kBias = -2;
[[vk::constant_id(9)]] const uint16_t kCount = 40000;

RWStructuredBuffer<half> results : register(u0);

[numthreads(4, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    results[id.x] = kGain * (half)(kBias + (int16_t)id.x) + (half)kCount;
}
