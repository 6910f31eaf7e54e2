// The glossy GGX path shared by reflect_glossy.hlsl and
// reflect_adaptive.hlsl: the iterative bounce loop with each rough
// surface's reflection sampled from the GGX distribution of visible normals
// (Heitz 2018) with a per-pixel PCG hash the CPU reference reproduces bit
// for bit, and a shorter t_max off rough surfaces. Also the pipelines' miss,
// closest-hit and any-hit shaders.
#pragma once
#include "reflect_shadow.hlsli"

// What the closest hit reports: the distance and the surface's index; the
// ray generation shader reads the surface itself.
struct HitInfo
{
    float t;
    uint surface;
};

// Rays per pixel are params.flags >> 8, from 1 to this.
static const uint MAX_SAMPLES = 16;

// PCG hash (Jarzynski & Olano 2020).
uint pcg(uint v)
{
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// A uniform number in [0, 1) with 24 bits, advancing the seed.
float rand(inout uint seed)
{
    seed = pcg(seed);
    return float(seed >> 8u) * (1.0 / 16777216.0);
}

// A GGX visible normal for the view `ve` (tangent space, z up) and roughness
// `alpha` (Heitz 2018).
float3 sample_vndf(float3 ve, float alpha, float u1, float u2)
{
    // A grazing view (ve.z = 0) with alpha = 0 would normalise zero.
    float3 vh = normalize(float3(alpha * ve.x, alpha * ve.y, max(ve.z, 1e-7)));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    float3 t1 = float3(1.0, 0.0, 0.0);
    if (lensq > 0.0)
        t1 = float3(-vh.y, vh.x, 0.0) * rsqrt(lensq);
    float3 t2 = cross(vh, t1);
    float r = sqrt(u1);
    float phi = 6.2831855 * u2;
    float p1 = r * cos(phi);
    float s = 0.5 * (1.0 + vh.z);
    float p2 = (1.0 - s) * sqrt(1.0 - p1 * p1) + s * (r * sin(phi));
    float3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return normalize(float3(alpha * nh.x, alpha * nh.y, max(0.0, nh.z)));
}

// Path number `sample` of pixel `id`: its light is added into `sum` term
// by term (the rounding, which the CPU follows, depends on it).
void glossy_sample(uint2 id, uint sample, inout float3 sum)
{
    uint seed = pcg(id.y * params.width + id.x) ^ pcg(sample + 0x9E3779B9u);
    float3 origin = params.camera.xyz;
    float3 dir = camera_dir(id);
    float t_max = params.ray.y;
    float throughput = 1.0;
    for (uint bounce = 0; bounce <= params.max_bounces; bounce++)
    {
        RayDesc ray;
        ray.Origin = origin;
        ray.Direction = dir;
        ray.TMin = params.ray.x;
        ray.TMax = t_max;
        HitInfo hit = (HitInfo)0;
        TraceRay(tlas, RAY_FLAG_NONE, 0xFF, 0, 1, 0, ray, hit);
        if (hit.t < 0.0)
        {
            sum += throughput * sky(dir);
            break;
        }
        // The shadow ray first, from the next origin: across it only the
        // path's own state stays live; the surface is read again after it.
        float3 n = facing(surfaces[hit.surface].normal_reflectivity.xyz, dir);
        origin = offset_ray(origin + dir * hit.t, n);
        float visible = 0.0;
        if ((params.flags & FLAG_LIGHT) != 0 && dot(n, params.light.xyz) > 0.0)
            visible = shadow_ray(origin);
        Surface s = surfaces[hit.surface];
        n = facing(s.normal_reflectivity.xyz, dir);
        float3 base = throughput * (1.0 - s.normal_reflectivity.w) * s.albedo_roughness.xyz;
        throughput *= s.normal_reflectivity.w;
        float roughness = s.albedo_roughness.w;
        float ndl = dot(n, params.light.xyz);
        float headlight = max(dot(n, -dir), 0.0);
        if (roughness > 0.0)
        {
            // Tangent frame (Duff et al. 2017), the view in it, a visible
            // normal, and the reflection about it weighted by G1(l).
            float sgn = select(n.z >= 0.0, 1.0, -1.0);
            float a = -1.0 / (sgn + n.z);
            float b = n.x * n.y * a;
            float3 tx = float3(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
            float3 ty = float3(b, sgn + n.y * n.y * a, -n.y);
            float alpha = roughness * roughness;
            float3 ve = float3(dot(-dir, tx), dot(-dir, ty), dot(-dir, n));
            float u1 = rand(seed);
            float u2 = rand(seed);
            float3 m = sample_vndf(ve, alpha, u1, u2);
            dir = reflect(dir, tx * m.x + ty * m.y + n * m.z);
            float nl = dot(n, dir);
            if (nl > 0.0)
            {
                float a2 = alpha * alpha;
                throughput *= 2.0 * nl / (nl + sqrt(a2 + (1.0 - a2) * nl * nl));
            }
            else
            {
                throughput = 0.0;
            }
            t_max = params.knobs.x / (1.0 + 64.0 * roughness);
        }
        else
        {
            dir = reflect(dir, n);
            t_max = params.knobs.x;
        }
        if ((params.flags & FLAG_LIGHT) != 0)
        {
            sum += base * params.light.w;
            if (ndl > 0.0 && visible > 0.0)
                sum += base * ndl;
        }
        else
        {
            sum += base * headlight;
        }
        // Too rough to be worth a ray: the environment answers instead of
        // the reflection ray the next bounce would trace.
        if (roughness > params.knobs.y && bounce < params.max_bounces)
        {
            sum += throughput * sky(dir);
            break;
        }
        if (!(throughput > params.ray.z))
            break;
    }
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
