// Differential test (tests/hlsl_differential.rs): default arguments,
// overloads, methods and wave intrinsics, compiled by rtlint and by Slang;
// one row of results per thread. (Slang 2026.12 does not parse HLSL
// templates: tests/hlsl/exec_frontend.hlsl checks those against known values.)
RWStructuredBuffer<float4> results : register(u0);

static const uint ROW = 4;

float shift(float x, float by = 0.5, uint times = 2) { return x + by * times; }

float scaled(float x) { return x * 3; }
float scaled(float x, float k) { return x * k; }
int scaled(int x) { return x * 3; }

struct Range
{
    float lo;
    float hi;
    float width() { return hi - lo; }
    float clampIn(float v) { return clamp(v, lo, hi); }
};

[numthreads(64, 1, 1)]
void Main(uint3 tid : SV_DispatchThreadID)
{
    uint i = tid.x;
    float x = ((float)i - 31.5) / 8.0;
    uint base = i * ROW;
    results[base + 0] = float4(shift(x), shift(x, 1.5), shift(x, -1.0, 3), x * x);
    Range r;
    r.lo = -1.0;
    r.hi = 2.5;
    results[base + 1] = float4(r.width(), r.clampIn(x), scaled((int)i), scaled(x, 0.25));
    results[base + 2] = float4(scaled(x), shift(scaled(x)), r.clampIn(shift(x, 2.0)), 0);
    // Lanes of one subgroup: same driver, same subgroup size for both compilers.
    uint lane = WaveGetLaneIndex();
    results[base + 3] = float4(WaveActiveSum(x), WavePrefixSum((float)lane),
                               WaveReadLaneFirst(x), WaveActiveMax((int)i) + WaveActiveCountBits(x > 0.0));
}
