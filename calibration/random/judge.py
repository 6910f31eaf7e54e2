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
    m = re.search(r"/out/(s\d+)/", path)
    if m:
        return "random/" + m.group(1)
    return os.path.relpath(path, ROOT)


def model_reports(rtlint, paths):
    out = []
    for i in range(0, len(paths), 64):
        chunk = paths[i : i + 64]
        r = subprocess.run([rtlint, "stack", "--format", "json", *chunk], capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"rtlint failed:\n{r.stderr}")
        v = json.loads(r.stdout)
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
    chain = {}
    for r in csv.DictReader(open(args.csv)):
        driver[(r["pipeline"], r["group"], r["stage"])] = int(r["driver_bytes"])
        # Without an exact chain (recursion unbounded at compile time) the
        # driver's own default for the declared depth is the reference.
        ref = r["driver_exact_call_chain"] or r["driver_vulkan_default"]
        chain[r["pipeline"]] = int(ref) if ref else None
    sets = {}
    for r in csv.DictReader(open(args.manifest)):
        sets["random/s%03d" % int(r["seed"])] = r["set"]
    paths = []
    for p in sorted(chain):
        if p.startswith("random/"):
            paths.append(os.path.join(HERE, "out", p[7:], p[7:] + ".pipeline.toml"))
        elif os.path.exists(os.path.join(ROOT, p)):
            paths.append(os.path.join(ROOT, p))
    groups = {"fit": ([], []), "heldout": ([], []), "repository": ([], [])}
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
