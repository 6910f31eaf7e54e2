#!/usr/bin/env bash
# Runs every cargo-fuzz target for SECONDS each (default 300), one after
# another, seeded by fuzz/seed.sh; prints each target's executions and time.
# A crash leaves its input in fuzz/artifacts/<target>/: minimise it
# (`cargo +nightly fuzz tmin <target> <file>`) and add it under
# fuzz/regressions/<target>/, which tests/fuzz_regressions.rs replays.
set -uo pipefail
cd "$(dirname "$0")"
seconds=${1:-300}
targets=${TARGETS:-"hlsl_preprocess hlsl_parse hlsl_compile wgsl spirv spirv_decode spirv_gen config pipeline"}
./seed.sh >/dev/null
for t in $targets; do
    log=$(mktemp)
    cargo +nightly fuzz run -O "$t" "corpus/$t" -- -max_total_time="$seconds" \
        -rss_limit_mb=4096 -timeout=20 -max_len=65536 >"$log" 2>&1
    rc=$?
    runs=$(grep -o 'Done [0-9]* runs in [0-9]* second' "$log" | tail -1)
    echo "$t: exit $rc; ${runs:-no summary (crash?)}; corpus $(ls "corpus/$t" | wc -l)"
    if [ $rc -ne 0 ]; then
        grep -E 'panicked|ERROR|SUMMARY|Test unit written' "$log" | head -5
    fi
    rm -f "$log"
done
