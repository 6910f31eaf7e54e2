// DXC's inline-SPIR-V instructions (`vk::ext_instruction`): an imported
// set's instruction, raw opcodes with and without a result, a pointer
// operand (`vk::ext_reference`) and a literal one (`vk::ext_literal`).

// GLSL.std.450 Sin (13).
[[vk::ext_instruction(13, "GLSL.std.450")]]
float spvSin(float x);

// OpReadClockKHR (5056), with ShaderClockKHR (5055); its scope an id.
[[vk::ext_extension("SPV_KHR_shader_clock")]]
[[vk::ext_capability(5055)]]
[[vk::ext_instruction(5056)]]
uint2 ReadClock(uint scope);

// OpCompositeExtract (81): the index is a literal operand.
[[vk::ext_instruction(81)]]
float Extract(float4 v, [[vk::ext_literal]] int index);

// OpLoad (61): the operand is the variable's pointer.
[[vk::ext_instruction(61)]]
float LoadOf([[vk::ext_reference]] float x);

// OpMemoryBarrier (225): no result. Workgroup scope (2); AcquireRelease
// (0x8) | WorkgroupMemory (0x100).
[[vk::ext_instruction(225)]]
void Barrier(uint scope, uint semantics);

// A void instruction of an imported set: `OpExtInst %void`. A
// non-semantic set is one spirv-val accepts without knowing it.
[[vk::ext_extension("SPV_KHR_non_semantic_info")]]
[[vk::ext_instruction(7, "NonSemantic.rtlint.test")]]
void Mark(uint value);

RWStructuredBuffer<float> output : register(u0);

[numthreads(8, 1, 1)]
void main(uint3 id : SV_DispatchThreadID)
{
    float x = (float)id.x;
    float s = spvSin(x);
    Barrier(2, 0x108);
    Mark(id.x);
    uint2 t = ReadClock(3);
    output[id.x] = s + Extract(float4(1, 2, 3, 4), 2) + LoadOf(x) + (float)(t.x & 1);
}
