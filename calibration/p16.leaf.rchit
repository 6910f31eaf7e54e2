#version 460
#extension GL_EXT_ray_tracing : require
struct Payload { uint data[4]; };
layout(location = 0) rayPayloadInEXT Payload payload;
void main() {
    for (uint i = 0u; i < 4; i++) { payload.data[i] = i + 1u; }
}
