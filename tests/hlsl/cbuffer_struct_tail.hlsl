// A struct in a constant buffer starts a row, and the member after it uses
// the space left in the struct's last row (as DXC's and Slang's D3D layouts
// do): `after` is at 72, not 80. Needs scalar block layout.
struct Camera
{
    float3 origin;   // 0
    float3 forward;  // 16
    float3 right;    // 32
    float3 up;       // 48
    float2 range;    // 64 (ends at 72)
};

cbuffer AfterStruct : register(b0)
{
    Camera camera;   // 0
    uint after;      // 72
    uint next;       // 76
};

RWStructuredBuffer<float> outBuf : register(u1);

[numthreads(1, 1, 1)]
void Main()
{
    outBuf[0] = camera.range.y + after + next;
}
