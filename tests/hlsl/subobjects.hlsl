// A DXR library with its state-object subobjects: shader and pipeline
// configs, hit groups, export associations and root signatures.
struct [raypayload] Payload
{
    float3 color : read(caller) : write(closesthit, miss);
    uint depth : read(closesthit) : write(caller);
};

static const uint MAX_DEPTH = 3;

GlobalRootSignature Globals =
{
    "DescriptorTable(UAV(u0)), "
    "SRV(t0)"
};
LocalRootSignature Locals = { "RootConstants(num32BitConstants = 4, b1)" };
TriangleHitGroup Opaque = { "", "ShadeHit" };
ProceduralPrimitiveHitGroup Spheres = { "SphereAny", "ShadeHit", "SphereHit" };
RaytracingShaderConfig ShaderConfig = { 16, 8 };
RaytracingPipelineConfig1 PipelineConfig = { MAX_DEPTH, RAYTRACING_PIPELINE_FLAG_SKIP_PROCEDURAL_PRIMITIVES };
SubobjectToExportsAssociation ConfigExports = { "ShaderConfig", "Gen; Background;ShadeHit" };

RaytracingAccelerationStructure scene : register(t0);
RWTexture2D<float4> image : register(u0);

[shader("raygeneration")]
void Gen()
{
    RayDesc ray;
    ray.Origin = float3(0, 0, -1);
    ray.Direction = float3(0, 0, 1);
    ray.TMin = 0.001;
    ray.TMax = 100.0;
    Payload p;
    p.color = 0;
    p.depth = 0;
    TraceRay(scene, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, p);
    image[DispatchRaysIndex().xy] = float4(p.color, 1);
}

[shader("miss")]
void Background(inout Payload p)
{
    p.color = float3(0.1, 0.2, 0.4);
}

[shader("closesthit")]
void ShadeHit(inout Payload p, in BuiltInTriangleIntersectionAttributes a)
{
    p.color = float3(a.barycentrics, 0);
}
