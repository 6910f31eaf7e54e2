// Procedural spheres: the intersection shader reports hits with a user
// attribute struct that the closest-hit shader reads back.
struct SphereAttributes
{
    float3 normal;
    float t;
};

struct Payload
{
    float3 color;
    float distance;
};

struct Sphere
{
    float3 center;
    float radius;
};

StructuredBuffer<Sphere> spheres : register(t0, space1);

bool hitSphere(Sphere s, float3 o, float3 d, out float t)
{
    float3 oc = o - s.center;
    float b = dot(oc, d);
    float c = dot(oc, oc) - s.radius * s.radius;
    float disc = b * b - c;
    t = 0;
    if (disc < 0)
        return false;
    float sq = sqrt(disc);
    t = -b - sq;
    if (t < RayTMin())
        t = -b + sq;
    return t >= RayTMin() && t <= RayTCurrent();
}

[shader("intersection")]
void SphereIntersection()
{
    Sphere s = spheres[PrimitiveIndex()];
    float3 o = ObjectRayOrigin();
    float3 d = normalize(ObjectRayDirection());
    float t;
    if (hitSphere(s, o, d, t))
    {
        SphereAttributes attr;
        attr.normal = normalize(o + t * d - s.center);
        attr.t = t;
        ReportHit(t, 0, attr);
    }
}

[shader("closesthit")]
void SphereHit(inout Payload p, in SphereAttributes attr)
{
    float3x4 toWorld = ObjectToWorld3x4();
    float3 n = normalize(mul((float3x3)toWorld, attr.normal));
    float4x3 toWorld43 = ObjectToWorld4x3();
    float3 origin = mul(float4(0, 0, 0, 1), toWorld43);
    p.color = n * 0.5 + 0.5;
    p.distance = RayTCurrent() + length(origin) * 0.0 + (float)GeometryIndex() + (float)InstanceIndex();
}
