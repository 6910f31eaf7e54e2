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
    float v4 = float(payload.data[0]) * 4.5;
    float v5 = float(payload.data[1]) * 5.5;
    float v6 = float(payload.data[2]) * 6.5;
    float v7 = float(payload.data[3]) * 7.5;
    float v8 = float(payload.data[0]) * 8.5;
    float v9 = float(payload.data[1]) * 9.5;
    float v10 = float(payload.data[2]) * 10.5;
    float v11 = float(payload.data[3]) * 11.5;
    float v12 = float(payload.data[0]) * 12.5;
    float v13 = float(payload.data[1]) * 13.5;
    float v14 = float(payload.data[2]) * 14.5;
    float v15 = float(payload.data[3]) * 15.5;
    if (payload.data[0] < 1u) {
        next.data[0] = payload.data[0] + 1u;
        traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, gl_WorldRayOriginEXT, 0.001, gl_WorldRayDirectionEXT, 100.0, 1);
        payload.data[3] = next.data[3] + uint(0.0 + v0 + v1 + v2 + v3 + v4 + v5 + v6 + v7 + v8 + v9 + v10 + v11 + v12 + v13 + v14 + v15);
    }
}
