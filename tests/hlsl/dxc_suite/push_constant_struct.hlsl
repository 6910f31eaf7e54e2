// `[[vk::push_constant]]` on a global of struct type (DXC's documented
// form) is a push-constant block, laid out as one, not a `$Globals`
// member (compiled with -enable-16bit-types).

struct Light {
    uint16_t      id;
    uint16_t2     flags;
    float16_t2x3  basis;
};

struct Push {
    Light  light;
    float4 tint;
};

[[vk::push_constant]]
Push push;

float4 main() : SV_Target
{
    return push.tint * push.light.id + float4(push.light.basis[1], 1);
}
