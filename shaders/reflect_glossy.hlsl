// Glossy GGX reflections in HLSL (rtlint's own compiler): the iterative
// bounce loop with each rough surface's reflection sampled from the GGX
// distribution of visible normals (Heitz 2018) with a per-pixel PCG hash the
// CPU reference reproduces bit for bit; shorter t_max off rough surfaces;
// params.flags >> 8 rays per pixel. Same math as reflect_glossy.wgsl.
#include "reflect_ggx.hlsli"

[shader("raygeneration")]
void raygen()
{
    uint2 id = DispatchRaysIndex().xy;
    uint samples = clamp(params.flags >> 8u, 1u, MAX_SAMPLES);
    // Every sample's light adds straight into the sum, scaled at the end.
    float3 sum = float3(0.0, 0.0, 0.0);
    for (uint sample = 0; sample < MAX_SAMPLES; sample++)
    {
        if (sample >= samples)
            break;
        glossy_sample(id, sample, sum);
    }
    image[id.y * params.width + id.x] = pack_rgba8(sum / float(samples));
}
