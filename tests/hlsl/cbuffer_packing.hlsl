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

// A struct starts a row, and the member after it uses the space left in the
// struct's last row (as DXC's and Slang's D3D layouts do): `after` is at 72.
struct Camera
{
    float3 origin;   // 0
    float3 forward;  // 16
    float3 right;    // 32
    float3 up;       // 48
    float2 range;    // 64 (ends at 72)
};

cbuffer AfterStruct : register(b2)
{
    Camera camera;   // 0
    uint after;      // 72
    uint next;       // 76
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
    outBuf[2] = camera.range.y + after + next;
}
