// Executed on a Vulkan driver by tests/hlsl_exec.rs: each `put` stores one
// result, which the test compares with the value HLSL semantics give.
RWStructuredBuffer<uint> results : register(u0);

cbuffer Inputs : register(b1)
{
    float3 a3;    // (1, 2, 3)
    float b1;     // 4
    float c[3];   // 5, 6, 7
    float d;      // 8
    float2 e2;    // (9, 10)
    float3x3 m;   // m[r][c] = 10 r + c
    float tail;   // 11
    bool flag;    // true, stored as a uint
};

enum Mode { MODE_A, MODE_B = 5, MODE_C };

namespace util
{
    float twice(float x) { return x * 2.0; }
}

static uint slot = 0;
static const uint table[4] = { 10, 20, 30, 40 };
static const float3 UNIT = normalize(float3(3, 0, 4));
static float fromBuffer = b1 * 2;

void put(uint v) { results[slot] = v; slot += 1; }
void put(int v) { put(asuint(v)); }
void put(float v) { put(asuint(v)); }

bool bump(inout int counter)
{
    counter += 1;
    return true;
}

void split(float4 v, out float3 rgb, out float a)
{
    rgb = v.rgb;
    a = v.a;
}

struct Counter
{
    uint count;
    float scale;
    void add(uint n) { count += n; }
    float scaled() { return (float)count * scale; }
    float twiceScaled() { return scaled() * 2.0; }
    void reset() { this.count = 0; }
};

int scale(int x) { return x * 5; }
float scale(float x) { return x * 3.0; }

[numthreads(1, 1, 1)]
void Main()
{
    // 0..5: arithmetic
    put(7 / 2);
    put(-7 / 2);
    // Signed remainder with non-negative operands: Vulkan leaves OpSRem of a
    // negative operand undefined (lavapipe gives -1 for -7 % 3, NVIDIA 0).
    put(7 % 3);
    put(7u % 3u);
    put(1.5f * 2);
    put(fmod(-5.5, 2.0));
    // 6..8: swizzles
    float3 v = float3(1, 2, 3);
    v.xz = v.zx;
    put(v.x);
    put(v.z);
    v.yz += 10;
    put(v.y);
    // 9..10: post-increment
    int i = 5;
    int j = i++;
    put(j);
    put(i);
    // 11: && short-circuits on scalars
    int calls = 0;
    bool r = (b1 < 0) && bump(calls);
    put(calls + (r ? 100 : 0));
    // 12: ternary on a scalar condition
    put(b1 > 0 ? 1.0 : 2.0);
    // 13..18: constant-buffer packing
    put(a3.y);
    put(b1);
    put(c[1]);
    put(d);
    put(e2.y);
    put(tail);
    // 19..26: matrices
    put(m[2][1]);
    put(m._m12);
    float3 mv = mul(m, float3(1, 0, 0));
    put(mv.y);
    float3 vm = mul(float3(1, 0, 0), m);
    put(vm.y);
    float3x3 p = mul(m, m);
    put(p[1][2]);
    put(transpose(m)[0][2]);
    float2x2 small = float2x2(1, 2, 3, 4);
    put(determinant(small));
    put(small[1][0]);
    // 27..29: control flow
    int sum = 0;
    for (int k = 0; k < 10; ++k)
    {
        if (k == 5)
            continue;
        if (k == 8)
            break;
        sum += k;
    }
    put(sum);
    int x = 0;
    switch ((int)b1 - 2)
    {
    case 1:
        x += 1;
    case 2:
        x += 2;
    case 3:
        x += 3;
        break;
    default:
        x += 100;
    }
    put(x);
    int n = 0;
    do { n += 3; } while (n < 10);
    put(n);
    // 30..33: functions
    float3 rgb;
    float alpha;
    split(float4(1, 2, 3, 4), rgb, alpha);
    put(alpha);
    put(rgb.z);
    put(scale(2));
    put(scale(2.0));
    // 34..49: intrinsics
    put(countbits(0xF0u));
    put(firstbithigh(0x100u));
    put(firstbitlow(0x100u));
    put(reversebits(1u));
    put(sign(-2.5));
    put(abs(-3));
    put(clamp(5, 0, 3));
    put(min(-1, 2u));
    put(lerp(2.0, 4.0, 0.25));
    put(saturate(1.5));
    put(step(1.0, 2.0));
    put(dot(int2(1, 2), int2(3, 4)));
    put(length(float3(2, 3, 6)));
    put(f16tof32(f32tof16(1.5)));
    put(round(2.5));
    put(frac(-0.25));
    // 50..58: conversions, tables, shifts, enums, namespaces
    put(table[(uint)b1 & 3]);
    put((int)-2.7);
    put((uint)3.9);
    put((float)(-3));
    put((int)(b1 > 1));
    float4 q = float4(1, 2, 3, 4);
    float2 t = (float2)q;
    put(t.y);
    put(-16 >> 2);
    put(0x80000000u >> 31);
    put((int)MODE_C);
    put(util::twice(b1));
    // 60: a bool read from a constant buffer
    put(flag ? 1 : 2);
    // 61..62: static globals with computed initializers
    put(UNIT.z);
    put(fromBuffer);
    // 63: a ternary takes the common type of its sides
    put(b1 > 0 ? 1 : 2.5);
    put(b1 < 0 ? 1 : 2.5);
    // 65..68: struct methods
    Counter ctr;
    ctr.count = 1;
    ctr.scale = 0.5;
    ctr.add(3);
    put(ctr.count);
    put(ctr.twiceScaled());
    ctr.reset();
    put(ctr.count);
    put(ctr.scale);
    // 69..72: sincos, modf, ldexp
    float sn, cs;
    sincos(0.0, sn, cs);
    put(sn + 2.0 * cs);
    float whole;
    put(modf(-2.75, whole));
    put(whole);
    put(ldexp(1.5, 3.0));
    // 73: continue and break inside a switch inside a loop
    int acc2 = 0;
    for (int s2 = 0; s2 < 6; s2++)
    {
        switch (s2)
        {
        case 1:
            continue;
        case 4:
            break;
        default:
            acc2 += 10;
        }
        acc2 += 1;
        if (s2 > 4)
            break;
    }
    put(acc2);
    // 74..75: a shift keeps its left operand's type
    int negative = -8 * (int)(b1 / 4.0);
    put(negative >> 1u);
    put(3u << 1);
    // 76: && in a loop condition
    int zc = 0;
    bool gg = true;
    for (int z = 0; z < 8 && gg; z++)
    {
        zc += 1;
        gg = z < 2;
    }
    put(zc);
    // 77..78: HLSL 2021 and() / select()
    bool2 both = and(bool2(true, b1 > 0), bool2(b1 > 0, false));
    put(both.x ? 1 : 0);
    put(select(b1 > 0, 5, 7) + select(bool2(false, true), int2(1, 2), int2(3, 4)).x);
    // 79..81: a ternary with a call runs only the chosen side; an int side
    // and a float side meet in the common type
    int tc = 0;
    float tv = b1 > 0 ? 1 : (bump(tc) ? 2.5 : 0.5);
    put(tv);
    put(tc);
    float tw = b1 < 0 ? 1 : (bump(tc) ? 2.5 : 0.5);
    put(tw + tc);
    // 82..83: cheap sides are selected whole: vectors and structs on a
    // scalar condition
    put((b1 > 0 ? float3(1, 2, 3) : float3(4, 5, 6)).y);
    Counter other;
    other.count = 9;
    other.scale = 2.0;
    Counter picked = b1 < 0 ? ctr : other;
    put(picked.count + picked.scale);
}
