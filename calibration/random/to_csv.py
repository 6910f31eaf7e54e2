#!/usr/bin/env python3
"""Turns device-run.sh's driver.jsonl into the measurement CSV kept in the
repository: one row per shader with the driver's stack size, and per
pipeline the call-chain and default figures computed from the driver's
numbers.

    calibration/random/to_csv.py driver.jsonl > calibration/random/nvidia-h200.csv
"""
import csv
import json
import re
import sys


def key(path):
    """The description's path in the repository:
    `.dev-stack/out/s012/s012.pipeline.toml` → `calibration/random/out/s012/s012.pipeline.toml`;
    `.dev-stack/repo/fixtures/x.pipeline.toml` → `fixtures/x.pipeline.toml`."""
    m = re.search(r"/out/(s\d+)/", path)
    if m:
        return f"calibration/random/out/{m.group(1)}/{m.group(1)}.pipeline.toml"
    return re.sub(r"^.*?/repo/", "", path)


def main():
    w = csv.writer(sys.stdout, lineterminator="\n")
    w.writerow(["pipeline", "group", "stage", "entry", "driver_bytes", "driver_exact_call_chain", "driver_vulkan_default"])
    rows = []
    for line in open(sys.argv[1]):
        v = json.loads(line)
        # One report per line, or (newer rtlint) {"pipelines": [...]}.
        for r in v.get("pipelines", [v]):
            d = r.get("driver") or {}
            for s in r["shaders"]:
                rows.append(
                    [key(r["pipeline"]), s["group"], s["stage"], s["entry"], s["driver_bytes"],
                     d.get("exact_call_chain"), d.get("vulkan_default")]
                )
    rows.sort(key=lambda x: (x[0], x[1], x[2]))
    w.writerows(["" if v is None else v for v in row] for row in rows)


if __name__ == "__main__":
    main()
