// HLSL 2021 and DXC conventions: `operator[]` on a struct, a struct
// declared inside a function, `sizeof` of a name, DXC's predefined macros
// for Vulkan (`__spirv__`, `__HLSL_VERSION`), bit fields in an unused struct.
#if !defined(__spirv__) || __HLSL_VERSION < 2021
#error "expected DXC's Vulkan macros"
#endif
#define arraysize(a) (sizeof(a) / sizeof(a[0]))

static const float3 directions[6] = {
    float3(1, 0, 0), float3(-1, 0, 0), float3(0, 1, 0),
    float3(0, -1, 0), float3(0, 0, 1), float3(0, 0, -1)
};

// Sized by its initializer at global scope.
static const float2 offsets[] = { float2(0, 1), float2(1, 0), float2(-1, 0) };

namespace sh
{
    static const float Pi = 3.141592654;
    // Computed at the start of the entry point, in its namespace.
    static const float SqrtPi = sqrt(Pi);
}

// A template and non-template overloads share a name.
template<typename T>
float max3(T v) { return max(v.x, max(v.y, v.z)); }
float max3(float a, float b, float c) { return max(a, max(b, c)); }

struct Unused
{
    uint material : 24;
    uint sampler : 8;
};

Texture2D<float> depth : register(t0);
RWStructuredBuffer<float4> output : register(u0);

struct LinearDepth
{
    float scale;
    float operator[](uint2 pixel) { return depth[pixel] * scale; }
};

[numthreads(8, 8, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    struct Sample
    {
        float3 direction;
        float weight;
    } best;
    best.direction = 0;
    best.weight = 0;
    LinearDepth d;
    d.scale = 2;
    for (uint i = 0; i < arraysize(directions); i++)
    {
        float w = d[id.xy + uint2(i, 0)];
        if (w > best.weight)
        {
            best.direction = directions[i];
            best.weight = w;
        }
    }
    float extra = offsets[2].x + sh::SqrtPi + max3(best.direction) + max3(1.0, 2.0, 3.0);
    output[id.x] = float4(best.direction, best.weight + sizeof(best) + extra);
}
