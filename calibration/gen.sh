#!/usr/bin/env bash
# Generates the stack-calibration pipelines: for each payload size, a leaf
# pipeline (closest-hit writes the payload) and a recursive one (closest-hit
# traces once more with the same payload, guarded by a constant depth), as
# GLSL, SPIR-V (glslang) and *.pipeline.toml. `rtlint stack --driver` on the
# NVIDIA machine compares the model with the driver on each (see README.md).
set -euo pipefail
cd "$(dirname "$0")"
rm -f *.rgen *.rchit *.rmiss *.spv *.pipeline.toml
for bytes in 4 8 16 32 48 64 96 128 160 192 224 256; do
    words=$((bytes / 4))
    payload="struct Payload { uint data[$words]; };"
    cat >p$bytes.rgen <<EOF
#version 460
#extension GL_EXT_ray_tracing : require
$payload
layout(location = 0) rayPayloadEXT Payload payload;
layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;
layout(set = 0, binding = 1) buffer Out { uint value[]; } result;
void main() {
    payload.data[0] = 0u;
    traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, vec3(0.0, 1.0, 4.0), 0.001, vec3(0.0, 0.0, -1.0), 100.0, 0);
    result.value[gl_LaunchIDEXT.y * gl_LaunchSizeEXT.x + gl_LaunchIDEXT.x] = payload.data[$words - 1] + payload.data[0];
}
EOF
    cat >p$bytes.rmiss <<EOF
#version 460
#extension GL_EXT_ray_tracing : require
$payload
layout(location = 0) rayPayloadInEXT Payload payload;
void main() {
    for (uint i = 0u; i < $words; i++) { payload.data[i] = 7u; }
}
EOF
    cat >p$bytes.leaf.rchit <<EOF
#version 460
#extension GL_EXT_ray_tracing : require
$payload
layout(location = 0) rayPayloadInEXT Payload payload;
void main() {
    for (uint i = 0u; i < $words; i++) { payload.data[i] = i + 1u; }
}
EOF
    cat >p$bytes.pass.rchit <<EOF
#version 460
#extension GL_EXT_ray_tracing : require
$payload
layout(location = 0) rayPayloadInEXT Payload payload;
layout(location = 1) rayPayloadEXT Payload next;
layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;
void main() {
    // Depth is kept in data[0]; one more level at most.
    if (payload.data[0] < 1u) {
        next.data[0] = payload.data[0] + 1u;
        traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, gl_WorldRayOriginEXT, 0.001, gl_WorldRayDirectionEXT, 100.0, 1);
        payload.data[$words - 1] = next.data[$words - 1] + 1u;
    } else {
        // The deepest level: the result is 1000 + the levels above it.
        payload.data[$words - 1] = 1000u;
    }
}
EOF
    for kind in leaf pass; do
        cat >p$bytes.$kind.pipeline.toml <<EOF
# Calibration: $bytes-byte payload, closest-hit $kind.
max_recursion_depth = $([ $kind = pass ] && echo 2 || echo 1)

[[raygen]]
file = "p$bytes.rgen.spv"

[[miss]]
file = "p$bytes.rmiss.spv"

[[hit_group]]
closest_hit = { file = "p$bytes.$kind.rchit.spv" }
EOF
    done
done
# Deep recursion with the 256-byte payload: 30 levels below raygen.
sed -e 's/payload.data\[0\] < 1u/payload.data[0] < 30u/' p256.pass.rchit >p256.deep.rchit
sed -e 's/p256.pass.rchit/p256.deep.rchit/' -e 's/^max_recursion_depth = 2/max_recursion_depth = 31/' \
    -e 's/closest-hit pass/closest-hit recursing 30 levels/' p256.pass.pipeline.toml >p256.deep.pipeline.toml

# Live state that cannot be recomputed: values made from the first trace's
# payload, kept across a second trace. In raygen (l*) and closest-hit (c*).
for k in 4 8 16 32; do
    decl=""
    use=""
    for i in $(seq 0 $((k - 1))); do
        decl="$decl    float v$i = float(payload.data[$((i % 4))]) * $i.5;
"
        use="$use + v$i"
    done
    cat >l$k.rgen <<EOF
#version 460
#extension GL_EXT_ray_tracing : require
struct Payload { uint data[4]; };
layout(location = 0) rayPayloadEXT Payload payload;
layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;
layout(set = 0, binding = 1) buffer Out { uint value[]; } result;
void main() {
    payload.data[0] = 0u;
    traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, vec3(0.0, 1.0, 4.0), 0.001, vec3(0.0, 0.0, -1.0), 100.0, 0);
$decl    traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, vec3(0.0, 1.0, 4.0), 0.001, vec3(0.0, 0.0, -1.0), 100.0, 0);
    result.value[gl_LaunchIDEXT.y * gl_LaunchSizeEXT.x + gl_LaunchIDEXT.x] = uint(0.0$use) + payload.data[1];
}
EOF
    cat >c$k.rchit <<EOF
#version 460
#extension GL_EXT_ray_tracing : require
struct Payload { uint data[4]; };
layout(location = 0) rayPayloadInEXT Payload payload;
layout(location = 1) rayPayloadEXT Payload next;
layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;
void main() {
$decl    if (payload.data[0] < 1u) {
        next.data[0] = payload.data[0] + 1u;
        traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, gl_WorldRayOriginEXT, 0.001, gl_WorldRayDirectionEXT, 100.0, 1);
        payload.data[3] = next.data[3] + uint(0.0$use);
    }
}
EOF
    printf '# Calibration: %s floats live across the second trace in raygen.\nmax_recursion_depth = 1\n\n[[raygen]]\nfile = "l%s.rgen.spv"\n\n[[miss]]\nfile = "p16.rmiss.spv"\n\n[[hit_group]]\nclosest_hit = { file = "p16.leaf.rchit.spv" }\n' "$k" "$k" >"l$k.pipeline.toml"
    printf '# Calibration: %s floats live across the trace in closest-hit.\nmax_recursion_depth = 2\n\n[[raygen]]\nfile = "p16.rgen.spv"\n\n[[miss]]\nfile = "p16.rmiss.spv"\n\n[[hit_group]]\nclosest_hit = { file = "c%s.rchit.spv" }\n' "$k" "$k" >"c$k.pipeline.toml"
done

# Live state of K independent values in ray generation: each comes from its
# own word of a 128-byte payload, so no compiler can recompute it from fewer.
# m*: across a second trace; n*: carried around a bounce loop.
for k in 6 9 10 11 12 13 14 16 20 24 32; do
    decl=""; use=""; upd=""; init=""
    for i in $(seq 0 $((k - 1))); do
        decl="$decl    float v$i = float(payload.data[$i]) * $i.5;
"
        init="$init    float v$i = 0.0;
"
        upd="$upd        v$i = v$i * 0.5 + float(payload.data[$i]);
"
        use="$use + v$i"
    done
    head=$(cat <<EOF
#version 460
#extension GL_EXT_ray_tracing : require
struct Payload { uint data[32]; };
layout(location = 0) rayPayloadEXT Payload payload;
layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;
layout(set = 0, binding = 1) buffer Out { uint value[]; } result;
EOF
)
    trace='traceRayEXT(tlas, gl_RayFlagsOpaqueEXT, 0xFF, 0, 0, 0, vec3(0.0, 1.0, 4.0), 0.001, vec3(0.0, 0.0, -1.0), 100.0, 0);'
    store='result.value[gl_LaunchIDEXT.y * gl_LaunchSizeEXT.x + gl_LaunchIDEXT.x]'
    printf '%s\nvoid main() {\n    payload.data[0] = 0u;\n    %s\n%s    %s\n    %s = uint(0.0%s) + payload.data[1];\n}\n' \
        "$head" "$trace" "$decl" "$trace" "$store" "$use" >m$k.rgen
    printf '%s\nvoid main() {\n%s    for (uint bounce = 0u; bounce < 3u; bounce++) {\n        payload.data[0] = bounce;\n        %s\n%s    }\n    %s = uint(0.0%s);\n}\n' \
        "$head" "$init" "$trace" "$upd" "$store" "$use" >n$k.rgen
    for kind in m n; do
        printf '# Calibration: %s independent values live in raygen (%s).\nmax_recursion_depth = 1\n\n[[raygen]]\nfile = "%s%s.rgen.spv"\n\n[[miss]]\nfile = "p128.rmiss.spv"\n\n[[hit_group]]\nclosest_hit = { file = "p128.leaf.rchit.spv" }\n' \
            "$k" "$([ $kind = m ] && echo 'across a second trace' || echo 'carried around a loop')" "$kind" "$k" >"$kind$k.pipeline.toml"
    done
done

for f in *.rgen *.rchit *.rmiss; do
    glslangValidator --target-env vulkan1.2 -V -g "$f" -o "$f.spv" >/dev/null
done
echo "generated $(ls *.pipeline.toml | wc -l) pipelines"
