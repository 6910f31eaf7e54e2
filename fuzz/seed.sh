#!/usr/bin/env bash
# Seeds each target's corpus (fuzz/corpus/<target>, not committed) from the
# repository's own shaders, configs and pipeline descriptions.
set -euo pipefail
cd "$(dirname "$0")/.."
seed() {
    local target=$1
    shift
    mkdir -p "fuzz/corpus/$target"
    find "$@" -type f -print0 2>/dev/null | while IFS= read -r -d '' f; do
        cp "$f" "fuzz/corpus/$target/$(sha1sum "$f" | cut -c1-16)"
    done
}
for t in hlsl_preprocess hlsl_parse hlsl_compile; do
    seed "$t" shaders fixtures tests/hlsl tests/shaders -name '*.hlsl*'
done
seed wgsl shaders fixtures -name '*.wgsl'
seed spirv fixtures -name '*.spv'
seed spirv_decode fixtures -name '*.spv'
seed config . -path ./target -prune -o -path ./fuzz -prune -o -name 'rtlint.toml'
seed pipeline shaders fixtures tests -name '*.pipeline.toml'
# spirv_gen's inputs are generator choices: any bytes make a module.
mkdir -p fuzz/corpus/spirv_gen
for t in fuzz/corpus/*; do echo "$t: $(ls "$t" | wc -l) seeds"; done
