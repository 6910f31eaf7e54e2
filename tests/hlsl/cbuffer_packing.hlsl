// HLSL constant-buffer packing that std140 would lay out differently: the
// float after an array shares the array's last row. Needs scalar block layout.
cbuffer Packed : register(b0)
{
    float3 a;     // 0
    float b;      // 12
    float c[3];   // 16, 32, 48
    float d;      // 52
    float2 e;     // 56
    float3x3 m;   // 64
    float tail;   // 108
};

RWStructuredBuffer<float> outBuf : register(u1);

// Plain globals go to the implicit $Globals constant buffer.
float3 globalTint;
float globalScale;
uint globalCount;

[numthreads(1, 1, 1)]
void Main()
{
    outBuf[0] = a.x + b + c[2] + d + e.y + m[2][2] + tail;
    outBuf[1] = globalTint.y * globalScale + (float)globalCount;
}
