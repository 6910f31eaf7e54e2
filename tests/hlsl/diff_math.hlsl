// Differential test (tests/hlsl_differential.rs): float, integer, vector and
// matrix intrinsics over a range of inputs, one row of results per thread.
RWStructuredBuffer<float4> results : register(u0);

static const uint ROW = 10;

[numthreads(64, 1, 1)]
void Main(uint3 tid : SV_DispatchThreadID)
{
    uint i = tid.x;
    float x = ((float)i - 31.5) / 8.0;
    float y = (float)(i % 7) * 0.37 + 0.05;
    float3 v = float3(x, y, 1.0 - x * y);
    uint base = i * ROW;
    results[base + 0] = float4(sin(x), cos(x), tan(x * 0.3), atan2(x, y));
    results[base + 1] = float4(asin(x / 4.0), acos(x / 4.0), atan(x), exp(x * 0.5));
    results[base + 2] = float4(exp2(x), log(y), log2(y), pow(y, x * 0.25));
    results[base + 3] = float4(sqrt(y), rsqrt(y), floor(x), ceil(x));
    results[base + 4] = float4(frac(x), fmod(x, 1.5), sign(x), smoothstep(-1.0, 1.0, x));

    float3 n = normalize(v);
    float3 r = reflect(n, float3(0, 1, 0));
    float3 t = refract(n, float3(0, 0, -1), 0.66);
    results[base + 5] = float4(cross(v, float3(0.3, -0.2, 0.9)).xy, distance(v, float3(1, 2, 3)), dot(r, t));

    int k = (int)i * 37 - 1000;
    uint u = i * 2654435761u;
    results[base + 6] = float4(countbits(u), firstbithigh(k), firstbitlow(u), reversebits(u) >> 20);
    results[base + 7] = float4(k / 7, k % 7, u >> 27, max(k, -300) + (int)min(u % 100, 50u) + clamp(k, -5, 5));

    bool3 big = v > 2.0;
    results[base + 8] = float4(lerp(x, y, 0.3), saturate(x),
                               (any(big) ? 1.0 : 0.0) + (all(v > -5.0) ? 2.0 : 0.0),
                               f16tof32(f32tof16(x)));
    float3x3 m = float3x3(x, 1, 2, 3, y, 5, 6, 7, 1);
    results[base + 9] = float4(mul(m, v).xy, mul(v, m).z, determinant(m));
}
