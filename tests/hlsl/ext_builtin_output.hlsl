// Stencil export through DXC's inline-SPIR-V attributes: a built-in output
// (FragStencilRefEXT, 5014) with its extension and capability
// (StencilExportEXT, 5013).
[[vk::ext_extension("SPV_EXT_shader_stencil_export")]]
[[vk::ext_capability(5013)]]
[[vk::ext_builtin_output(5014)]]
static int gl_FragStencilRefARB;

Texture2D<float> mask : register(t0);

[shader("pixel")]
float4 Stencil(float4 pos : SV_Position) : SV_Target
{
    gl_FragStencilRefARB = mask.Load(int3(pos.xy, 0)) > 0.5 ? 2 : 1;
    return float4(1, 0, 0, 1);
}

// Does not write it: no capability, no extension, no variable.
[shader("pixel")]
float4 Plain(float4 pos : SV_Position) : SV_Target
{
    return pos;
}
