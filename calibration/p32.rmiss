#version 460
#extension GL_EXT_ray_tracing : require
struct Payload { uint data[8]; };
layout(location = 0) rayPayloadInEXT Payload payload;
void main() {
    for (uint i = 0u; i < 8; i++) { payload.data[i] = 7u; }
}
