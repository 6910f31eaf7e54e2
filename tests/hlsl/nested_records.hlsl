// Static data members, nested structs and enums, out-of-line methods of a
// nested struct, struct inheritance, enum values built from earlier ones.
namespace sh
{
    enum Layout { Width = 4, Height = 2, Size = Width * Height };
}

struct L1
{
    static const uint NumCoefficients = 4;
    static const float Scale = 0.5;

    float c[NumCoefficients];

    static L1 Zero()
    {
        return (L1)0;
    }

    struct Packed
    {
        uint c[NumCoefficients / 2];
        L1 Unpack();
    };

    Packed Pack()
    {
        Packed p;
        p.c[0] = f32tof16(c[0]) | (f32tof16(c[1]) << 16);
        p.c[1] = f32tof16(c[2]) | (f32tof16(c[3]) << 16);
        return p;
    }

    float Sum()
    {
        float s = 0;
        for (uint i = 0; i < NumCoefficients; i++)
            s += c[i];
        return s * Scale;
    }
};

L1 L1::Packed::Unpack()
{
    L1 r = L1::Zero();
    r.c[0] = f16tof32(c[0]);
    r.c[1] = f16tof32(c[0] >> 16);
    r.c[2] = f16tof32(c[1]);
    r.c[3] = f16tof32(c[1] >> 16);
    return r;
}

struct BrdfValue
{
    float3 value;
    float pdf;

    float3 valueOverPdf() { return value / max(pdf, 1e-6); }
};

struct BrdfSample : BrdfValue
{
    float3 direction;
};

RWStructuredBuffer<float4> output : register(u0);

[numthreads(1, 1, 1)]
void Main(uint3 id : SV_DispatchThreadID)
{
    L1 sh = L1::Zero();
    sh.c[id.x % L1::NumCoefficients] = 1;
    L1 back = sh.Pack().Unpack();
    BrdfSample s;
    s.value = float3(1, 2, 3);
    s.pdf = 2;
    s.direction = float3(0, 0, 1);
    float cells[sh::Size];
    cells[0] = back.Sum();
    output[0] = float4(s.valueOverPdf() + s.direction, cells[0]);
}
