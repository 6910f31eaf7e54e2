#!/usr/bin/env bash
# Runs every fuzz target at the same time from prebuilt binaries, each in
# libFuzzer's fork mode with JOBS processes, for SECONDS; for a machine with
# many cores and no Rust toolchain (build here with `cargo +nightly fuzz
# build -O`, carry fuzz/target/x86_64-unknown-linux-gnu/release/<target>).
# Crashes, timeouts and out-of-memory inputs do not stop a run: each is kept
# under OUT/artifacts/<target>/ and counted. Prints one line per target:
# executions, CPU-seconds (JOBS × wall), the libFuzzer counters, artifacts.
#
#     fuzz/run-parallel.sh BIN_DIR SECONDS JOBS [OUT]
#
# JOBS may be one number for every target or `target=N,...` with a default
# of 1 (e.g. `hlsl_compile=3,wgsl=3,2` gives the rest 2).
set -uo pipefail
cd "$(dirname "$0")"
bin=$(realpath "$1")
seconds=$2
jobs_spec=$3
out=$(realpath -m "${4:-/tmp/rtlint-fuzz}")
targets=${TARGETS:-"hlsl_preprocess hlsl_parse hlsl_compile wgsl spirv spirv_decode spirv_gen config pipeline"}
mkdir -p "$out"
./seed.sh >/dev/null

jobs_for() {
    local t=$1 default=1 item
    if [[ $jobs_spec =~ ^[0-9]+$ ]]; then
        echo "$jobs_spec"
        return
    fi
    IFS=, read -ra items <<<"$jobs_spec"
    for item in "${items[@]}"; do
        if [[ $item == "$t="* ]]; then
            echo "${item#*=}"
            return
        elif [[ $item =~ ^[0-9]+$ ]]; then
            default=$item
        fi
    done
    echo "$default"
}

start=$(date +%s)
for t in $targets; do
    mkdir -p "$out/artifacts/$t"
    "$bin/$t" -fork="$(jobs_for "$t")" -ignore_crashes=1 -ignore_timeouts=1 \
        -ignore_ooms=1 -max_total_time="$seconds" -rss_limit_mb=4096 -timeout=20 \
        -max_len=65536 -artifact_prefix="$out/artifacts/$t/" "corpus/$t" \
        >"$out/$t.log" 2>&1 &
done
wait
wall=$(($(date +%s) - start))
echo "wall ${wall} s"
for t in $targets; do
    j=$(jobs_for "$t")
    # Fork mode's status lines: "#EXECS: cov: … oom/timeout/crash: O/T/C time: Ns job: …".
    last=$(grep -E '^#[0-9]+: cov:' "$out/$t.log" | tail -1)
    execs=$(sed -E 's/^#([0-9]+):.*/\1/' <<<"$last")
    counters=$(grep -oE 'oom/timeout/crash: [0-9]+/[0-9]+/[0-9]+' <<<"$last")
    echo "$t: jobs $j, ${execs:-?} executions, $((j * wall)) CPU-s, ${counters:-no status line}," \
        "corpus $(ls "corpus/$t" | wc -l), artifacts $(ls "$out/artifacts/$t" | wc -l)"
done
