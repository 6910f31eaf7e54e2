#!/usr/bin/env python3
"""Judges rtlint's stack model against the driver's numbers in
calibration/random/nvidia-h200.csv: the fitting seeds, the held-out seeds
(see gen.py) and the repository's own pipelines, each reported apart.

    calibration/random/judge.py [--rtlint target/release/rtlint] [--features out.csv]

Per shader: exact, within ±15 % (a 0 must be exactly 0), worst error, and
under-predictions; per pipeline: whether the recommended stack size is
below the exact call chain computed from the driver's own numbers (which
would hang the GPU). Needs the generated pipelines (gen.py) in
calibration/random/out.
"""
import argparse
import csv
import json
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def key(path):
    return os.path.relpath(path, ROOT)


def model_reports(rtlint, paths, extra=()):
    out = []
    for i in range(0, len(paths), 64):
        chunk = paths[i : i + 64]
        r = subprocess.run([rtlint, "stack", *extra, "--format", "json", *chunk], capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"rtlint failed:\n{r.stderr}")
        v = json.loads(r.stdout)
        if isinstance(v, dict) and "pipelines" in v:
            v = v["pipelines"]
        out.extend(v if isinstance(v, list) else [v])
    return out


def within(model, driver):
    if driver == 0:
        return model == 0
    return abs(model - driver) <= 0.15 * driver


def table(name, shaders, pipelines):
    n = len(shaders)
    nz = [s for s in shaders if s["driver"] > 0]

    def line(label, ss):
        if not ss:
            return f"| {name} | {label} | 0 | | | | | |"
        exact = sum(s["model"] == s["driver"] for s in ss)
        w = sum(within(s["model"], s["driver"]) for s in ss)
        under = [s for s in ss if s["model"] < s["driver"]]

        def rel(s):
            return (s["model"] - s["driver"]) / max(s["driver"], 1) * 100

        over = max(ss, key=rel)
        worst_under = min(under, key=rel) if under else None
        return (
            f"| {name} | {label} | {len(ss)} | {exact} ({exact / len(ss):.0%}) | {w} ({w / len(ss):.0%}) "
            f"| {rel(over):+.0f} % ({over['model']} vs {over['driver']}) "
            + (f"| {rel(worst_under):+.0f} % ({worst_under['model']} vs {worst_under['driver']}) " if worst_under else "| — ")
            + f"| {len(under)} |"
        )

    rows = [line("all shaders", shaders), line("non-zero shaders", nz)]
    safe = [p for p in pipelines if p["chain"] is not None]
    below = [p for p in safe if p["recommended"] is None or p["recommended"] < p["chain"]]
    return rows, len(pipelines), len(safe), below


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rtlint", default=os.path.join(ROOT, "target/release/rtlint"))
    ap.add_argument("--csv", default=os.path.join(HERE, "nvidia-h200.csv"))
    ap.add_argument("--manifest", default=os.path.join(HERE, "out/manifest.csv"))
    ap.add_argument("--features", help="write a per-shader CSV of features and figures here")
    args = ap.parse_args()
    driver = {}
    for r in csv.DictReader(open(args.csv)):
        driver[(r["pipeline"], r["group"], r["stage"])] = int(r["driver_bytes"])
    sets = {}
    for r in csv.DictReader(open(args.manifest)):
        s = "s%03d" % int(r["seed"])
        sets[f"calibration/random/out/{s}/{s}.pipeline.toml"] = r["set"]
    pipelines = sorted({k[0] for k in driver})
    paths = [os.path.join(ROOT, p) for p in pipelines if os.path.exists(os.path.join(ROOT, p))]
    # The exact call chain of the driver's own numbers (its default for the
    # declared depth where recursion is unbounded at compile time), through
    # rtlint's current call graph.
    chain = {}
    for rep in model_reports(args.rtlint, paths, ["--driver-numbers", args.csv]):
        d = rep.get("driver") or {}
        ref = d.get("exact_call_chain")
        chain[key(rep["pipeline"])] = ref if ref is not None else d.get("vulkan_default")
    groups = {"fit": ([], []), "heldout": ([], []), "heldout2": ([], []), "repository": ([], [])}
    feats = []
    for rep in model_reports(args.rtlint, paths):
        k = key(rep["pipeline"])
        g = sets.get(k, "repository")
        shaders, pipes = groups[g]
        for s in rep["shaders"]:
            d = driver.get((k, s["group"], s["stage"]))
            if d is None:
                continue
            shaders.append({"model": s["driver_model_bytes"], "driver": d})
            feats.append({"pipeline": k, "set": g, "group": s["group"], "stage": s["stage"],
                          "driver": d, "model": s["driver_model_bytes"], "full": s["model_bytes"], **s["breakdown"]})
        pipes.append({"name": k, "recommended": rep["recommended"], "chain": chain.get(k)})
    print("| set | shaders | count | exact | within ±15 % | worst over | worst under | under-predictions |")
    print("|---|---|---:|---:|---:|---|---|---:|")
    notes = []
    for g, (shaders, pipes) in groups.items():
        rows, n, measured, below = table(g, shaders, pipes)
        print("\n".join(rows))
        notes.append(
            f"{g}: {n} pipelines, {measured} with driver figures; recommended below the driver's exact chain (or default) on {len(below)}"
            + (": " + ", ".join(f"{p['name']} ({p['recommended']} < {p['chain']})" for p in below[:8]) if below else "")
        )
    print()
    for n in notes:
        print(n)
    if args.features:
        with open(args.features, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(feats[0].keys()))
            w.writeheader()
            w.writerows(feats)


if __name__ == "__main__":
    main()
