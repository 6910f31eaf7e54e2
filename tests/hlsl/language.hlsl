// Language features in one compute shader: types, operators, conversions,
// control flow, functions with out/inout and overloads, namespaces, enums.
#define COUNT 4
#define SQUARE(x) ((x) * (x))
#define CAT(a, b) a##b
#define STR(x) #x
#define SUM(...) sum3(__VA_ARGS__)
#if defined(COUNT) && COUNT > 2
#define BIG 1
#elif COUNT
#define BIG 2
#else
#error no count
#endif

typedef float4 Color;
typedef uint2 Index2;

enum Mode { MODE_A, MODE_B = 5, MODE_C };
enum class Filter : uint { Nearest, Linear = 3 };

namespace util
{
    static const float HALF = 0.5;
    float twice(float x) { return x * 2.0; }
    float quad(float x) { return twice(twice(x)); }
}

struct Light
{
    float3 position;
    float intensity;
    row_major float3x3 basis;
    uint flags[2];
};

cbuffer Globals : register(b0)
{
    Light lights[COUNT];
    float4x4 transform;
    uint lightCount;
    int bias;
};

[[vk::binding(1, 0)]] RWByteAddressBuffer raw;
RWStructuredBuffer<Color> colors : register(u2);
[[vk::push_constant]] ConstantBuffer<Light> pushed;

groupshared float shared[64];
groupshared uint sharedCount;
RWStructuredBuffer<uint> counters : register(u3);
static float3 accumulated;
static const float weights[COUNT] = { 0.1, 0.2, 0.3, 0.4 };
static const int3 offsets[2] = { int3(1, 2, 3), int3(-1, -2, -3) };

export float sum3(float a, float b, float c) { return a + b + c; }
inline float id(float x) { return x; }

float scale(float x) { return x * 3.0; }
float3 scale(float3 x) { return x * 4.0; }
int scale(int x) { return x * 5; }

void split(float4 v, out float3 rgb, out float a)
{
    rgb = v.rgb;
    a = v.a;
}

void bump(inout uint counter, uint by)
{
    counter += by;
}

float3 shade(Light l, float3 p)
{
    float3 d = l.position - p;
    float att = l.intensity / max(dot(d, d), 1e-4);
    return mul(d, l.basis) * att;
}

[numthreads(64, 1, 1)]
void Main(uint3 dtid : SV_DispatchThreadID, uint3 gtid : SV_GroupThreadID, uint3 gid : SV_GroupID)
{
    uint i = dtid.x;
    shared[gtid.x] = (float)i;
    GroupMemoryBarrierWithGroupSync();

    // Operators and implicit conversions.
    int a = 7, b = -3;
    uint u = 10u;
    float f = a / 2;            // integer division, then int -> float
    f += u % 3;
    f -= SQUARE(b);
    int sh = (a << 2) >> 1 | (b & 0xF) ^ ~a;
    bool flag = !(a > b) || (u >= 3 && f != 0.0);
    float3 v = 1.0;             // scalar splat
    v.xz = float2(2.0, 3.0);    // swizzle write
    v.y += v.x;
    float2 t2 = v.zy;
    float4 c4 = float4(t2, v.xy);
    c4.wzyx = c4;
    float3 trunc3 = (float3)c4; // explicit truncation
    int3 iv = int3(1, 2, 3) * 2 + offsets[i & 1];
    uint2 ix = Index2(4, 5);
    bool3 mask = v > 1.5;
    float3 picked = mask ? v : -v;
    float tern = flag ? f : 1.0;
    a++;
    --b;
    int pre = ++a + b--;

    // Matrices.
    float4 wp = mul(transform, float4(v, 1.0));
    float4 wp2 = mul(float4(v, 1.0), transform);
    float4x4 m2 = mul(transform, transform);
    float3x3 m3 = (float3x3)transform;
    float row0 = transform[0].x + transform._m11 + transform._22 + m2[1][2];
    m3[1] = float3(0, 1, 0);
    m3._m00 = 2.0;
    float det = determinant(m3) + transpose(m3)[0][1];

    // Control flow.
    float acc = 0;
    [unroll] for (int k = 0; k < COUNT; ++k)
    {
        if (k == 2)
            continue;
        acc += weights[k] * shade(lights[k], v).x;
        if (acc > 100.0)
            break;
    }
    int w = 0;
    while (w < 3) { w++; }
    for (int s = 0; s < 6; s++)
    {
        switch (s)
        {
        case 1:
            continue;
        case 4:
            break;
        default:
            if (s == 5)
                return;
            acc += 0.5;
        }
        if (s > 3)
            break;
    }
    do { w--; } while (w > 0);
    bool going = true;
    for (int z = 0; z < 8 && going; z++)
        going = acc < 50.0 || z == 0;
    do { w++; } while (w < 4 && (going || acc > 1.0));
    while (w > 0 && shared[w] >= 0.0 ? true : false) { w--; }
    switch (i % 4)
    {
    case 0:
        acc += 1;
    case 1:
        acc += 2;
        break;
    case 2:
    default:
        acc -= 1;
        break;
    }

    // Functions: overloads, out, inout, namespaces, macros.
    float3 rgb;
    float alpha;
    split(c4, rgb, alpha);
    uint counter = 1;
    bump(counter, 2);
    bump(ix.x, 3);
    acc += scale(1.0) + scale(v).y + (float)scale(2) + util::quad(util::HALF);
    acc += SUM(1.0, 2.0, 3.0) + CAT(ac, c) * BIG;
    acc += (float)MODE_C + (float)Filter::Linear;

    // Intrinsics.
    float3 n = normalize(cross(v, float3(0, 1, 0)) + 0.001);
    acc += length(n) + distance(v, n) + dot(iv, iv) + reflect(v, n).x + refract(v, n, 1.5).y;
    acc += lerp(0.0, 1.0, 0.25) + saturate(f) + clamp(f, -1.0, 1.0) + min(a, b) + max(u, 2u);
    acc += abs(b) + sign(-f) + floor(f) + ceil(f) + frac(f) + fmod(f, 2.0) + pow(2.0, f);
    acc += exp(0.5) + exp2(1.5) + log(2.0) + log2(8.0) + sqrt(2.0) + rsqrt(4.0);
    acc += sin(f) + cos(f) + tan(f) + asin(0.5) + acos(0.5) + atan(1.0) + atan2(1.0, 2.0);
    acc += step(0.5, f) + smoothstep(0.0, 1.0, f);
    acc += any(mask) ? 1.0 : 0.0;
    acc += all(v > 0) ? 1.0 : 0.0;
    acc += asfloat(asuint(f)) + (float)asint(1.0f);
    acc += f16tof32(f32tof16(f));
    acc += countbits(u) + firstbithigh(u) + firstbitlow(u) + reversebits(u);
    acc += isnan(f) ? 1.0 : 0.0;
    acc += isinf(f) ? 1.0 : 0.0;
    acc += mad(f, 2.0, 1.0) + rcp(2.0);

    // Resources.
    uint word = raw.Load(i * 4);
    uint4 words = raw.Load4(16);
    raw.Store(i * 4, word + words.x);
    raw.Store2(32, uint2(1, 2));
    uint prev;
    InterlockedAdd(sharedCount, 1u, prev);
    InterlockedMax(counters[0], prev);
    InterlockedMin(counters[1], (uint)a);
    accumulated = rgb * alpha;
    colors[i] = Color(accumulated, acc + det + row0 + wp.x + wp2.y + (float)sh + tern + picked.x + (float)pre + trunc3.x
                      + (float)counter + (float)ix.x + lights[0].flags[1] + pushed.intensity + (float)bias + (float)lightCount
                      + (float)gid.x);
}
