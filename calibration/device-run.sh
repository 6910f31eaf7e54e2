#!/usr/bin/env bash
# Runs the stack calibration on the NVIDIA device machine (through the device
# tool, which carries .gl/ — the Vulkan loader packages — and .dev/ — release
# builds of rtlint, examples/stack_probe and benches/stack made on x86-64).
#   calibrate: `rtlint stack --driver --format json` on every pipeline, and the
#              model-vs-driver speed bench;
#   bisect:    the largest explicit stack a 256-byte-payload pipeline traces
#              with, then the default stack at each declared depth.
# Results go to $OUT (or ./out).
set -uo pipefail
out=${OUT:-out}
mkdir -p "$out"
# The device machine has no Vulkan loader of its own.
if ! ldconfig -p | grep -q libvulkan.so.1; then
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
fi
nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[ -f "$nvidia_icd" ] && export VK_DRIVER_FILES=${VK_DRIVER_FILES:-$nvidia_icd}
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null | tee "$out/gpu.txt"

case "${1:-calibrate}" in
calibrate)
    : >"$out/stack.jsonl"
    for p in calibration/*.pipeline.toml shaders/*.pipeline.toml fixtures/pipelines/*.pipeline.toml fixtures/RT0*/*.pipeline.toml; do
        if .dev/rtlint stack --driver --format json "$p" >"$out/one.json" 2>"$out/one.err"; then
            python3 -c 'import json,sys; print(json.dumps(json.load(open(sys.argv[1]))))' "$out/one.json" >>"$out/stack.jsonl"
        else
            echo "FAILED $p: $(cat "$out/one.err")" | tee -a "$out/failures.txt"
        fi
    done
    rm -f "$out/one.json" "$out/one.err"
    .dev/stack_bench --bench 2>&1 | tee "$out/bench.txt"
    ;;
bisect)
    p=calibration/p256.pass.pipeline.toml
    probe() { timeout 60 .dev/stack_probe "$p" "$1" "$2" 512 512 1001; }
    # Explicit stack sizes at depth 2: the largest that runs.
    lo=${LO:-5056}
    hi=${HI:-16384}
    probe 2 "$lo" | tee -a "$out/bisect.txt"
    probe 2 "$hi" | tee -a "$out/bisect.txt"
    while [ $((hi - lo)) -gt 64 ]; do
        mid=$(((lo + hi) / 2))
        if probe 2 "$mid" | tee -a "$out/bisect.txt" | grep -q 'result=ok'; then lo=$mid; else hi=$mid; fi
    done
    echo "largest explicit stack that ran: $lo; smallest that failed: $hi" | tee -a "$out/bisect.txt"
    # The driver's default at each declared depth.
    for d in 4 8 12 16 20 24 28 31; do
        probe "$d" default | tee -a "$out/defaults.txt"
    done
    ;;
deep)
    # 30 levels of real recursion with the 256-byte payload: the driver's
    # default stack, explicit sizes around what the chain needs, and the
    # explicit-size limit again at a small and a large dispatch.
    p=calibration/p256.deep.pipeline.toml
    for s in default 4096 5056 9088 12000 14702; do
        timeout 60 .dev/stack_probe "$p" 31 "$s" 512 512 1030 | tee -a "$out/deep.txt"
    done
    for size in 64 2048; do
        for s in 14702 14746; do
            timeout 60 .dev/stack_probe calibration/p256.pass.pipeline.toml 2 "$s" "$size" "$size" 1001 | sed "s/^/${size}x${size} /" | tee -a "$out/deep.txt"
        done
    done
    ;;
esac
