// 16-bit types with -enable-16bit-types: `half`/`min16float` are float16_t,
// `min16int`/`min16uint` int16_t/uint16_t. Compiled with the flag only.

#ifdef __SLANG__
// Slang (tests/invariance.rs compares with it) has no min-precision types.
typedef half min16float;
typedef int16_t min16int;
#endif

struct Packed
{
    half a;
    half2 b;
    float c;
    int16_t d;
    uint16_t e;
    half3x3 basis;
};

RWStructuredBuffer<Packed> packed : register(u0);
RWStructuredBuffer<half> halves : register(u1);
cbuffer Params : register(b6)
{
    half scale;
    uint16_t count;
    float bias;
};

struct Push
{
    half3 tint;
    uint16_t mode;
};
[[vk::push_constant]] ConstantBuffer<Push> push;
static const half K = 2.0h;
static const int16_t N = 3;
groupshared half shared16[4];
// 16-bit texels: the images hold 32-bit ones (as Vulkan requires); reads
// narrow and writes widen.
Texture2D<half4> albedo : register(t2);
SamplerState linearSampler : register(s3);
RWTexture2D<half4> target : register(u4);
Buffer<uint16_t> indices : register(t5);

[numthreads(4, 1, 1)]
void cs(uint3 id : SV_DispatchThreadID, uint gi : SV_GroupIndex)
{
    half h = 1.5;
    float16_t3 v = float16_t3(1, 2, 3) * h;
    h = h * 2.0 + scale;
    int16_t i = -3;
    uint16_t u = count + 1;
    min16float m = (half)bias;
    min16int mi = i;
    Packed p;
    p.a = sqrt(h) + length(v) + dot(v, v);
    p.b = half2(v.x, (half)i);
    p.c = h + bias;
    p.d = i * 2 + (int16_t)u + abs(i) + max(mi, 5);
    p.e = u << 2;
    p.a += m + clamp(h, 0.0, 1.0) + lerp(h, m, 0.5) + (half)sign(h);
    shared16[gi] = (half)gi * push.tint.x * K;
    GroupMemoryBarrierWithGroupSync();
    half s = shared16[(gi + 1) % 4];
    uint16_t2 u2 = uint16_t2(gi, push.mode);
    switch ((int16_t)u2.y)
    {
    case 1:
        s += 1.0h;
        break;
    default:
        break;
    }
    half arr[N];
    for (int16_t j = 0; j < N; j++)
        arr[j] = s + j;
    half4 texel = albedo.SampleLevel(linearSampler, float2(0.5, 0.5), 0) + albedo.Load(int3(0, 0, 0));
    target[id.xy] = texel * h;
    half4 back = target[id.xy];
    arr[2] += back.w + (half)indices[gi];
    // 16-bit matrices: built, multiplied, mixed with float ones, stored.
    half3x3 tbn = half3x3(half3(1, 0, 0), half3(0, 1, 0), v);
    half3 n = mul(half3(1, 2, 3), tbn) + mul(tbn, v);
    float3x3 wide = tbn;
    p.basis = mul(tbn, (half3x3)wide) * 2.0;
    p.a += n.z + determinant(tbn) + tbn._m22;
    // f32tof16 takes a half as the float it is exactly.
    p.e += (uint16_t)f32tof16(h);
    // Wave operations on 16-bit values (shaderSubgroupExtendedTypes).
    p.a += WaveActiveSum(h) + WavePrefixProduct(m) + WaveReadLaneFirst(v).x;
    p.d += WaveActiveMin(i) + (int16_t)WaveActiveBitOr(u);
    packed[id.x] = p;
    halves[id.x] = h > m ? h : -m + arr[1] + arr[2];
}

// 16-bit stage inputs and outputs (StorageInputOutput16).
[shader("pixel")]
half4 ps(float4 pos : SV_Position, half2 uv : TEXCOORD0) : SV_Target
{
    half3 v = (half3)1;
    // Derivatives of 16-bit values: computed in 32 bits, narrowed back.
    half2 d = ddx(uv) + fwidth(uv.x);
    v *= uv.x + d.y;
    return half4(v, uv.y > 0.5h ? 1.0h : 0.0h);
}

struct [raypayload] HalfPayload
{
    half3 color : read(caller) : write(closesthit);
    half t : read(caller) : write(closesthit);
    uint16_t flags : read(caller) : write(closesthit);
};

[shader("closesthit")]
void hit(inout HalfPayload p, BuiltInTriangleIntersectionAttributes a)
{
    p.color = half3(a.barycentrics, 1.0);
    p.t = (half)RayTCurrent();
    p.flags = (uint16_t)HitKind();
}
