// Hybrid screen-space + ray-traced reflections in HLSL (rtlint's own
// compiler), two ray generation passes that verify runs in turn:
// `gbuffer_pass` traces the primary rays and writes, per pixel, position,
// view depth, facing normal, reflectivity, the surface's own light,
// roughness and albedo; `resolve_pass` marches each reflection over the
// G-buffer's depth (thickness test, confidence) and traces one ray only
// where the march misses, leaves the screen or is not confident. `paths`
// records which (0 none, 1 screen space, 2 ray). Depth 1: rays start in
// ray generation only. Reflections are mirror-like and one bounce deep.
#include "reflect_shadow.hlsli"

// What the closest hit reports: the distance and the surface's index.
struct HitInfo
{
    float t;
    uint surface;
};

struct GTexel
{
    // xyz: where the primary ray hit; w: view depth, negative on a miss
    float4 position_depth;
    // xyz: the normal facing the camera; w: reflectivity
    float4 normal_reflectivity;
    // xyz: the surface's own light (the sky on a miss); w: roughness
    float4 local_roughness;
    float4 albedo;
};
RWStructuredBuffer<uint> paths : register(u6);
RWStructuredBuffer<GTexel> gbuffer : register(u7);

static const uint PATH_NONE = 0;
static const uint PATH_SCREEN = 1;
static const uint PATH_RAY = 2;
static const uint SSR_STEPS = 64;
static const float SSR_STEP = 0.1;
static const float SSR_THICKNESS = 0.25;
static const float SSR_MIN_CONFIDENCE = 0.5;

// The closest surface along a ray; t < 0 on a miss.
HitInfo closest(float3 origin, float3 dir)
{
    RayDesc ray;
    ray.Origin = origin;
    ray.Direction = dir;
    ray.TMin = params.ray.x;
    ray.TMax = params.ray.y;
    HitInfo hit = (HitInfo)0;
    TraceRay(tlas, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, hit);
    return hit;
}

// A surface's own light, as the iterative shader's first bounce: ambient,
// plus the light where the shadow ray from `from` reaches it; without a
// light, the headlight.
float3 local_light(Surface s, float3 n, float3 dir, float3 from)
{
    float3 base = (1.0 - s.normal_reflectivity.w) * s.albedo_roughness.xyz;
    if ((params.flags & FLAG_LIGHT) == 0)
        return base * max(dot(n, -dir), 0.0);
    float3 c = base * params.light.w;
    float ndl = dot(n, params.light.xyz);
    if (ndl > 0.0 && shadow_ray(from) > 0.0)
        c += base * ndl;
    return c;
}

[shader("raygeneration")]
void gbuffer_pass()
{
    uint2 id = DispatchRaysIndex().xy;
    float3 dir = camera_dir(id);
    HitInfo hit = closest(params.camera.xyz, dir);
    GTexel g = (GTexel)0;
    if (hit.t < 0.0)
    {
        g.position_depth = float4(0.0, 0.0, 0.0, -1.0);
        g.local_roughness = float4(sky(dir), 0.0);
    }
    else
    {
        float3 p = params.camera.xyz + dir * hit.t;
        float3 n = facing(surfaces[hit.surface].normal_reflectivity.xyz, dir);
        float3 local = local_light(surfaces[hit.surface], n, dir, offset_ray(p, n));
        // The record is filled after the shadow ray, from the buffer,
        // rather than kept across it.
        Surface s = surfaces[hit.surface];
        g.position_depth = float4(p, -(p - params.camera.xyz).z);
        g.normal_reflectivity = float4(n, s.normal_reflectivity.w);
        g.local_roughness = float4(local, s.albedo_roughness.w);
        g.albedo = float4(s.albedo_roughness.xyz, 0.0);
    }
    gbuffer[id.y * params.width + id.x] = g;
}

// Marches from `p` along `r` in fixed steps, projecting each onto the
// screen: the first step behind the depth buffer by less than the
// thickness decides. True, with that texel's light in `found`, when it is
// confident (away from the screen's edge, facing the ray); false when the
// march misses, leaves the screen or is not confident.
bool march(float3 p, float3 r, out float3 found)
{
    found = float3(0.0, 0.0, 0.0);
    float2 size = float2(params.width, params.height);
    for (uint i = 1; i <= SSR_STEPS; i++)
    {
        float3 rel = p + r * (float(i) * SSR_STEP) - params.camera.xyz;
        float z = -rel.z;
        if (!(z > 1e-3))
            return false;
        // The camera's projection: direction (u, -v, -1.5).
        float u = 1.5 * rel.x / z;
        float v = -1.5 * rel.y / z;
        float2 pixel = (float2(u, v) + 1.0) * 0.5 * size;
        if (!(pixel.x >= 0.0 && pixel.x < size.x && pixel.y >= 0.0 && pixel.y < size.y))
            return false;
        uint2 texel = uint2(pixel);
        GTexel t = gbuffer[texel.y * params.width + texel.x];
        if (t.position_depth.w < 0.0)
            continue;
        float behind = z - t.position_depth.w;
        if (behind > 0.0 && behind < SSR_THICKNESS)
        {
            float edge = clamp((1.0 - max(abs(u), abs(v))) * 8.0, 0.0, 1.0);
            float facing_ray = clamp(dot(t.normal_reflectivity.xyz, -r) * 4.0, 0.0, 1.0);
            found = t.local_roughness.xyz;
            return min(edge, facing_ray) >= SSR_MIN_CONFIDENCE;
        }
    }
    return false;
}

[shader("raygeneration")]
void resolve_pass()
{
    uint2 id = DispatchRaysIndex().xy;
    uint index = id.y * params.width + id.x;
    GTexel g = gbuffer[index];
    float3 color = g.local_roughness.xyz;
    float reflectivity = g.normal_reflectivity.w;
    uint path = PATH_NONE;
    if (g.position_depth.w >= 0.0 && reflectivity > params.ray.z)
    {
        float3 n = g.normal_reflectivity.xyz;
        float3 r = reflect(camera_dir(id), n);
        float3 found = float3(0.0, 0.0, 0.0);
        path = PATH_SCREEN;
        // Ray only (FLAG_RAY_ONLY): every reflection is traced, none marched.
        bool screen = false;
        if ((params.flags & FLAG_RAY_ONLY) == 0)
            screen = march(g.position_depth.xyz, r, found);
        if (!screen)
        {
            path = PATH_RAY;
            float3 from = offset_ray(g.position_depth.xyz, n);
            HitInfo hit = closest(from, r);
            if (hit.t < 0.0)
            {
                found = sky(r);
            }
            else
            {
                Surface s = surfaces[hit.surface];
                float3 hn = facing(s.normal_reflectivity.xyz, r);
                found = local_light(s, hn, r, offset_ray(from + r * hit.t, hn));
            }
        }
        color += reflectivity * found;
    }
    paths[index] = path;
    image[index] = pack_rgba8(color);
}

[shader("miss")]
void miss(inout HitInfo hit)
{
    hit.t = -1.0;
}

[shader("closesthit")]
void closest_hit(inout HitInfo hit, in BuiltInTriangleIntersectionAttributes attr)
{
    hit.t = RayTCurrent();
    hit.surface = InstanceID() + PrimitiveIndex();
}

[shader("anyhit")]
void any_hit(inout HitInfo hit, in BuiltInTriangleIntersectionAttributes attr)
{
    if (!alpha_keeps(InstanceID() + PrimitiveIndex(), attr.barycentrics))
        IgnoreHit();
}
