#!/usr/bin/env bash
# Collects the driver's stack sizes for the random pipelines (gen.py) and
# every pipeline description of the repository on the NVIDIA machine of the
# device tool. It needs a folder DEV (first argument) holding an x86-64
# release `rtlint`, the generated pipelines under DEV/out/ and a copy of the
# repository's shaders/, fixtures/ and calibration/ under DEV/repo/; the
# device tool carries DEV and .gl/ (the Vulkan loader packages, see
# calibration/README.md). Writes to $OUT (or ./out):
#   driver.jsonl  one line per pipeline: `rtlint stack --driver --format json`
#   failures.txt  pipelines whose run failed, with rtlint's message
#   gpu.txt       the GPU and driver version
set -uo pipefail
dev=${1:?usage: device-run.sh DEV}
out=${OUT:-out}
mkdir -p "$out"
if ! ldconfig -p | grep -q libvulkan.so.1; then
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
fi
nvidia_icd=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
[ -f "$nvidia_icd" ] && export VK_DRIVER_FILES=${VK_DRIVER_FILES:-$nvidia_icd}
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null | tee "$out/gpu.txt"
rtlint=$(realpath "$dev/rtlint")
tmp=$(mktemp -d)
one() {
    p=$1
    key=k$(echo "$p" | tr '/.' '__')
    if timeout 60 "$rtlint" stack --driver --format json "$p" >"$tmp/$key.json" 2>"$tmp/$key.err"; then
        # One line per pipeline (strings in JSON hold no raw newline).
        { tr -d '\n' <"$tmp/$key.json"; echo; } >"$tmp/$key.line"
    else
        echo "FAILED $p (rc $?): $(tail -c 2000 "$tmp/$key.err" | tr '\n' ' ')" >"$tmp/$key.fail"
    fi
}
export -f one
export rtlint tmp
{
    find "$dev/out" -name '*.pipeline.toml'
    find "$dev/repo" -name '*.pipeline.toml'
} | sort | xargs -P 8 -I{} bash -c 'one "$@"' _ {}
cat "$tmp"/*.line >"$out/driver.jsonl" 2>/dev/null
cat "$tmp"/*.fail >"$out/failures.txt" 2>/dev/null
tar czf "$out/raw.tgz" -C "$tmp" . 2>/dev/null
echo "pipelines measured: $(wc -l <"$out/driver.jsonl"); failed: $(cat "$out/failures.txt" | wc -l)"
head -5 "$out/failures.txt"
