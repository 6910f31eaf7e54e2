#version 460
#extension GL_EXT_ray_tracing : require
struct Payload { uint data[4]; };
layout(location = 0) rayPayloadInEXT Payload payload;
layout(location = 1) rayPayloadEXT Payload next;
layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;
void main() {
    float v0 = float(payload.data[0]) * 0.5;
    float v1 = float(payload.data[1]) * 1.5;
    float v2 = float(payload.data[2]) * 2.5;
    float v3 = float(payload.data[3]) * 3.5;
    if (payload.data[0] < 1u) {
        next.data[0] = payload.data[0] + 1u;
        traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, gl_WorldRayOriginEXT, 0.001, gl_WorldRayDirectionEXT, 100.0, 1);
        payload.data[3] = next.data[3] + uint(0.0 + v0 + v1 + v2 + v3);
    }
}
