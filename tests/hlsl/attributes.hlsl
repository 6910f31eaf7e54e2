// Attributes: the hints (no effect on the module) and the Vulkan ones.
struct [raypayload] Payload
{
    float4 color : read(caller) : write(closesthit, miss);
};

[[vk::image_format("rgba8")]] RWTexture2D<float4> ldr : register(u0);
[[vk::image_format("unknown")]] RWTexture2D<float4> hdr[] : register(u1, space1);
[[vk::image_format("r11g11b10f")]] RWTexture2D<float3> packed : register(u2);
[[vk::binding(3, 0)]] RWStructuredBuffer<uint> counters;
[[vk::ext_extension("SPV_KHR_shader_clock")]] [[vk::ext_capability(5055)]]
RWStructuredBuffer<uint> clocks : register(u4);

[noinline]
float3 tonemap(float3 c)
{
    return c / (1 + c);
}

[RootSignature("DescriptorTable(UAV(u0, numDescriptors = 3))")]
[NumThreads(8, 8, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    float3 sum = 0;
    [fastopt] for (uint i = 0; i < 4; i++)
    {
        [allow_uav_condition] while (counters[i] > 100)
        {
            counters[i] -= 100;
        }
        sum += hdr[NonUniformResourceIndex(i)][id.xy].rgb;
    }
    [call] switch (id.x & 1)
    {
    case 0:
        sum *= 0.5;
        break;
    default:
        break;
    }
    [forcecase] switch (id.y & 1)
    {
    case 0:
        sum *= 2;
        break;
    default:
        break;
    }
    [branch] if (sum.x > 0) { packed[id.xy] = sum; }
    [flatten] if (sum.y > 0) { sum.y = 1; }
    [unroll(2)] for (uint j = 0; j < 2; j++) { sum += j; }
    [loop] for (uint k = 0; k < 2; k++) { sum -= k; }
    ldr[id.xy] = float4(tonemap(sum), 1);
}

struct HitRecord
{
    float4 tint;
};
[[vk::shader_record_nv]] ConstantBuffer<HitRecord> record;

[shader("closesthit")]
void Tinted(inout Payload p, in BuiltInTriangleIntersectionAttributes a)
{
    p.color = record.tint;
}
