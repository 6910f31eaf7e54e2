#version 460
#extension GL_EXT_ray_tracing : require
struct Payload { uint data[24]; };
layout(location = 0) rayPayloadInEXT Payload payload;
layout(location = 1) rayPayloadEXT Payload next;
layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;
void main() {
    // Depth is kept in data[0]; one more level at most.
    if (payload.data[0] < 1u) {
        next.data[0] = payload.data[0] + 1u;
        traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, gl_WorldRayOriginEXT, 0.001, gl_WorldRayDirectionEXT, 100.0, 1);
        payload.data[24 - 1] = next.data[24 - 1] + 1u;
    } else {
        // The deepest level: the result is 1000 + the levels above it.
        payload.data[24 - 1] = 1000u;
    }
}
