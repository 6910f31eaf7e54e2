// Forward declarations, `class` with access sections, static methods,
// out-of-line member definitions, `using` aliases and `using namespace`.
struct Surface;
class Packer;

namespace shading
{
    struct Surface
    {
        float3 albedo;
        float roughness;
    };

    float luminance(float3 c) { return dot(c, float3(0.2126, 0.7152, 0.0722)); }
}

using namespace shading;
using Color = float3;

class GbufferData
{
public:
    Color albedo;
    uint flags;

    uint pack();
    static GbufferData make(Color c, uint f);
    static uint channel(float v) { return uint(saturate(v) * 255.0); }

private:
    float weight() { return luminance(albedo); }
};

uint GbufferData::pack()
{
    return channel(albedo.r) | (channel(albedo.g) << 8) | (channel(albedo.b) << 16) | (flags << 24);
}

GbufferData GbufferData::make(Color c, uint f)
{
    GbufferData g;
    g.albedo = c;
    g.flags = f;
    return g;
}

RWStructuredBuffer<uint> packed : register(u0);

[numthreads(8, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    Surface s;
    s.albedo = float3(1, 0.5, 0);
    s.roughness = 0.5;
    GbufferData g = GbufferData::make(s.albedo, 3);
    packed[id.x] = g.pack() + uint(g.weight() > luminance(s.albedo));
}
