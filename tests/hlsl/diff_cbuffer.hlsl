// Differential test (tests/hlsl_differential.rs): HLSL constant-buffer
// packing. The test fills the buffer with each word's own index, so every
// value read back names the word the compiler placed it at.
struct Inner
{
    float2 uv;
    float w;
};

cbuffer Packed : register(b0)
{
    float3 a;
    float b;               // shares a's row
    float c[3];            // each element starts a row
    float d;               // shares the last element's row
    float2 e;
    float3 f;              // would cross a row: starts the next one
    float2 g;
    Inner inner;           // a struct starts a row
    float h;
    float3x3 m;            // column-major: one row per column
    row_major float2x3 r;  // one row per row
    int2 k;
    uint tail;
};

RWStructuredBuffer<float> outBuf : register(u1);

static uint slot = 0;

void put(float v)
{
    outBuf[slot] = v;
    slot += 1;
}

[numthreads(1, 1, 1)]
void Main()
{
    put(a.x);
    put(a.y);
    put(a.z);
    put(b);
    for (uint i = 0; i < 3; i++)
        put(c[i]);
    put(d);
    put(e.x);
    put(e.y);
    put(f.x);
    put(f.z);
    put(g.y);
    put(inner.uv.y);
    put(inner.w);
    put(h);
    for (uint row = 0; row < 3; row++)
        for (uint col = 0; col < 3; col++)
            put(m[row][col]);
    for (uint rr = 0; rr < 2; rr++)
        for (uint rc = 0; rc < 3; rc++)
            put(r[rr][rc]);
    put(asfloat(k.x));
    put(asfloat(k.y));
    put(asfloat(tail));
    put(-1.0);
}
