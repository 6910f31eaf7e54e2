#!/bin/sh
# Rebuilds the committed SPIR-V. naga's WGSL IR has no intersection stage,
# no ignoreIntersection and no SBT offsets (FIELD-NOTES), so these stages are
# GLSL, built with glslang 12 from scripts/setup; the .spv files are
# committed so the tests need no compiler.
set -e
cd "$(dirname "$0")"
for s in probe.rgen probe.rmiss triangle.rchit triangle.rahit sphere.rint sphere.rchit; do
    glslangValidator --target-env spirv1.4 -V "$s" -o "$s.spv"
    spirv-val --target-env vulkan1.3 "$s.spv"
done
