#version 460
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(location = 0) rayPayloadInEXT Payload p;

void main() {
    p.kind = 2u;
    p.primitive = uint(gl_PrimitiveID);
    p.custom = uint(gl_InstanceCustomIndexEXT);
    p.t = gl_HitTEXT;
}
