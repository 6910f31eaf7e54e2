// Built-ins declared with inline SPIR-V carry the capability (and
// extension) the SPIR-V grammar gives them: SampleId needs
// SampleRateShading, FragStencilRefEXT needs StencilExportEXT; an integer
// built-in input of a pixel shader is `Flat` like any other.

[[vk::ext_builtin_input(/* SampleId */ 18)]]
static const int sample_id;

[[vk::ext_extension("SPV_EXT_shader_stencil_export")]]
[[vk::ext_builtin_output(/* FragStencilRefEXT */ 5014)]]
static int stencil_ref;

float4 main() : SV_Target
{
    stencil_ref = sample_id + 1;
    return float4(sample_id, 0, 0, 1);
}
