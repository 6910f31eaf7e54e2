#!/usr/bin/env python3
"""Random but valid ray-tracing pipelines for judging the stack model.

Each seed gives one pipeline, the same on every run: payloads of 4 to 512
bytes, hit attributes up to 32 bytes, callables with callable data (some
calling another callable), any-hit and intersection shaders, function-local
arrays, live state straight-line or carried around a bounce loop, guarded
recursion, shadow rays, and one to three miss shaders. Even seeds are GLSL
(compiled with glslangValidator), odd seeds HLSL (named as .hlsl in the
description; rtlint compiles it). Seeds below --split are the fitting set,
the rest the held-out set.

    calibration/random/gen.py [--seeds 640] [--split 320] [--first N] [--out DIR]

writes DIR/sNNN/sNNN.pipeline.toml and its shaders, and DIR/manifest.csv with the
knobs of every seed. DIR defaults to calibration/random/out (not committed:
run this script to get it back).
"""

import argparse
import csv
import os
import random
import shutil
import subprocess
import sys


def pick_bytes(rng, lo, hi):
    """Log-uniform bytes in [lo, hi], a multiple of 4."""
    import math

    v = math.exp(rng.uniform(math.log(lo), math.log(hi)))
    return max(lo, min(hi, int(round(v / 4)) * 4))


# Seeds from here on form a second held-out set, generated after the model
# was last changed (2026-12-01) and judged once: the first held-out set had
# been seen by then, so only this one still tells how the model generalises.
SECOND_HELDOUT = 480


def knobs(seed, split):
    rng = random.Random(seed)
    k = {"seed": seed, "set": "fit" if seed < split else "heldout" if seed < SECOND_HELDOUT else "heldout2"}
    k["lang"] = "glsl" if seed % 2 == 0 else "hlsl"
    k["payload"] = pick_bytes(rng, 4, 512)
    k["rg_mode"] = rng.choice(["single", "straight", "loop"])
    k["rg_live"] = rng.randint(1, 32) if k["rg_mode"] != "single" else 0
    k["rg_live_src"] = rng.choice(["payload", "buffer"])
    k["rg_bounces"] = rng.randint(2, 6)
    k["rg_array"] = rng.randint(4, 32) if rng.random() < 0.3 else 0
    k["rg_callable"] = rng.random() < 0.2
    k["ch_kind"] = rng.choice(["leaf", "shadow", "recursive", "callable", "shadow_callable", "recursive_shadow"])
    k["ch_live"] = rng.randint(0, 24)
    k["ch_array"] = rng.randint(4, 32) if rng.random() < 0.35 else 0
    k["shadow"] = rng.choice([4, 8, 16])
    k["rec_bound"] = rng.randint(1, 4)
    k["calldata"] = pick_bytes(rng, 4, 128)
    k["call_nested"] = rng.random() < 0.3
    k["call_array"] = rng.randint(4, 24) if rng.random() < 0.3 else 0
    k["anyhit"] = rng.random() < 0.3
    k["procedural"] = rng.random() < 0.3
    k["attrs"] = rng.choice([4, 8, 12, 16, 20, 24, 28, 32])
    k["proc_kind"] = rng.choice(["leaf", "shadow"])
    k["miss_trace"] = rng.random() < 0.15
    k["extra_miss"] = rng.random() < 0.3
    # How values live across calls are used afterwards: folded into one sum
    # (a compiler can add them up before the call) or each on its own.
    k["rg_use"] = rng.choice(["sum", "each"])
    k["ch_use"] = rng.choice(["sum", "each"])
    uses_shadow = "shadow" in k["ch_kind"] or k["miss_trace"] or (
        k["procedural"] and k["proc_kind"] == "shadow"
    )
    k["uses_shadow"] = uses_shadow
    k["uses_callable"] = k["rg_callable"] or "callable" in k["ch_kind"]
    rec = k["rec_bound"] if "recursive" in k["ch_kind"] else 0
    k["depth"] = 1 + rec + (1 if uses_shadow else 0)
    return k


# --- GLSL ---------------------------------------------------------------

GLSL_HEAD = "#version 460\n#extension GL_EXT_ray_tracing : require\n"


def g_structs(k):
    w = k["payload"] // 4
    s = f"struct Payload {{ uint data[{w}]; }};\n"
    s += f"struct Shadow {{ uint data[{k['shadow'] // 4}]; }};\n"
    s += f"struct CallData {{ uint data[{k['calldata'] // 4}]; }};\n"
    s += f"struct Attr {{ float a[{k['attrs'] // 4}]; }};\n"
    return s


G_RES = (
    "layout(set = 0, binding = 0) uniform accelerationStructureEXT tlas;\n"
    "layout(set = 0, binding = 1) buffer Out { uint value[]; } result;\n"
    "layout(set = 0, binding = 2) readonly buffer Values { float v[]; } values;\n"
)


def g_trace(payload_loc, miss, flags, origin="vec3(0.0, 1.0, 4.0)", direction="vec3(0.0, 0.0, -1.0)"):
    return f"traceRayEXT(tlas, {flags}, 0xFF, 0, 0, {miss}, {origin}, 0.001, {direction}, 100.0, {payload_loc});"


def primary_flags(k):
    return "gl_RayFlagsNoneEXT" if k["anyhit"] else "gl_RayFlagsOpaqueEXT"


SHADOW_FLAGS_G = "gl_RayFlagsTerminateOnFirstHitEXT | gl_RayFlagsSkipClosestHitShaderEXT | gl_RayFlagsOpaqueEXT"


def g_raygen(k):
    w = k["payload"] // 4
    n = k["rg_live"]
    a = k["rg_array"]
    s = GLSL_HEAD + g_structs(k)
    s += "layout(location = 0) rayPayloadEXT Payload payload;\n"
    if k["rg_callable"]:
        s += "layout(location = 0) callableDataEXT CallData cd;\n"
    s += G_RES + "void main() {\n"
    s += "    uint idx = gl_LaunchIDEXT.y * gl_LaunchSizeEXT.x + gl_LaunchIDEXT.x;\n"
    tr = g_trace(0, 0, primary_flags(k))
    use = "0.0" + "".join(f" + v{i}" for i in range(n))
    arr_use = f" + arr[payload.data[0] % {a}u]" if a else ""
    call = ""
    if k["rg_callable"]:
        call = "    cd.data[0] = idx;\n    executeCallableEXT(0, 0);\n"
    call_use = f" + cd.data[{k['calldata'] // 4 - 1}]" if k["rg_callable"] else ""
    if k["rg_mode"] in ("single", "straight"):
        s += f"    payload.data[0] = 0u;\n    {tr}\n"
        for i in range(n):
            src = f"float(payload.data[{i % w}])" if k["rg_live_src"] == "payload" else f"values.v[idx + {i}u]"
            s += f"    float v{i} = {src} * {i}.5 + float(payload.data[{(i * 7) % w}]);\n"
        if a:
            s += f"    float arr[{a}];\n    for (uint i = 0u; i < {a}u; i++) {{ arr[i] = float(payload.data[i % {w}u]) + float(i); }}\n"
        s += call
        if k["rg_mode"] == "straight":
            s += f"    payload.data[0] = 0u;\n    {tr}\n"
        s += f"    result.value[idx] = uint({use}{arr_use}) + payload.data[{1 % w}]{call_use};\n"
        if k["rg_use"] == "each":
            s += "".join(f"    result.value[idx + {i + 1}u] = uint(v{i});\n" for i in range(n))
    else:
        for i in range(n):
            init = "0.0" if k["rg_live_src"] == "payload" else f"values.v[idx + {i}u]"
            s += f"    float v{i} = {init};\n"
        if a:
            s += f"    float arr[{a}];\n    for (uint i = 0u; i < {a}u; i++) {{ arr[i] = values.v[i]; }}\n"
        s += f"    for (uint bounce = 0u; bounce < {k['rg_bounces']}u; bounce++) {{\n"
        s += f"        payload.data[0] = 0u;\n        {g_trace(0, 0, primary_flags(k), direction='vec3(0.0, float(bounce) * 0.1, -1.0)')}\n"
        for i in range(n):
            s += f"        v{i} = v{i} * 0.5 + float(payload.data[{i % w}]) * {i}.5;\n"
        if a:
            s += f"        arr[bounce % {a}u] += float(payload.data[{w - 1}]);\n"
        s += "    " + call.replace("\n    ", "\n        ") if call else ""
        s += "    }\n"
        s += f"    result.value[idx] = uint({use}{arr_use}){call_use};\n"
    return s + "}\n"


def g_miss(k, trace):
    w = k["payload"] // 4
    s = GLSL_HEAD + g_structs(k)
    s += "layout(location = 0) rayPayloadInEXT Payload payload;\n"
    if trace:
        s += "layout(location = 2) rayPayloadEXT Shadow shadow;\n" + G_RES
    s += "void main() {\n"
    if trace:
        s += f"    shadow.data[0] = 1u;\n    {g_trace(2, 1, SHADOW_FLAGS_G, 'gl_WorldRayOriginEXT', 'vec3(0.0, 1.0, 0.0)')}\n"
    s += f"    for (uint i = 1u; i < {w}u; i++) {{ payload.data[i] = 7u{' + shadow.data[0]' if trace else ''}; }}\n"
    return s + "}\n"


def g_shadow_miss(k):
    s = GLSL_HEAD + g_structs(k)
    s += "layout(location = 0) rayPayloadInEXT Shadow shadow;\nvoid main() {\n    shadow.data[0] = 0u;\n}\n"
    return s


def g_closest_hit(k, kind, procedural):
    w = k["payload"] // 4
    cw = k["calldata"] // 4
    n = k["ch_live"]
    a = k["ch_array"]
    s = GLSL_HEAD + g_structs(k)
    s += "layout(location = 0) rayPayloadInEXT Payload payload;\n"
    rec = "recursive" in kind
    shadow = "shadow" in kind
    call = "callable" in kind
    if rec:
        s += "layout(location = 1) rayPayloadEXT Payload next;\n"
    if shadow:
        s += "layout(location = 2) rayPayloadEXT Shadow shadow;\n"
    if call:
        s += "layout(location = 0) callableDataEXT CallData cd;\n"
    s += "hitAttributeEXT Attr attr;\n" if procedural else "hitAttributeEXT vec2 bary;\n"
    s += G_RES + "void main() {\n"
    attr = "attr.a[0]" if procedural else "bary.x"
    for i in range(n):
        s += f"    float v{i} = float(payload.data[{(i + 1) % w}]) * {i}.25 + values.v[gl_PrimitiveID + {i}] + {attr};\n"
    if a:
        s += f"    float arr[{a}];\n    for (uint i = 0u; i < {a}u; i++) {{ arr[i] = float(payload.data[i % {w}u]) * {attr}; }}\n"
    if w > 1:
        s += f"    for (uint i = 1u; i < {w}u; i++) {{ payload.data[i] = payload.data[i] * 3u + i; }}\n"
    if call:
        s += f"    cd.data[0] = payload.data[0];\n    executeCallableEXT(0, 0);\n"
    if shadow:
        s += f"    shadow.data[0] = 1u;\n    {g_trace(2, 1, SHADOW_FLAGS_G, 'gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT', 'vec3(0.0, 1.0, 0.0)')}\n"
    if rec:
        s += f"    if (payload.data[0] < {k['rec_bound']}u) {{\n"
        s += "        next.data[0] = payload.data[0] + 1u;\n"
        s += f"        {g_trace(1, 0, primary_flags(k), 'gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT', 'reflect(gl_WorldRayDirectionEXT, vec3(0.0, 1.0, 0.0))')}\n"
        s += f"        payload.data[{w - 1}] += next.data[{w - 1}] + 1u;\n    }}\n"
    use = "0.0" + "".join(f" + v{i}" for i in range(n))
    if a:
        use += f" + arr[payload.data[{w - 1}] % {a}u]"
    extra = ""
    if shadow:
        extra += " + shadow.data[0]"
    if call:
        extra += f" + cd.data[{cw - 1}]"
    s += f"    payload.data[{w - 1}] += uint({use}){extra};\n"
    if k["ch_use"] == "each":
        s += "".join(f"    payload.data[{i % w}] += uint(v{i});\n" for i in range(n))
    return s + "}\n"


def g_any_hit(k):
    s = GLSL_HEAD + g_structs(k)
    s += "layout(location = 0) rayPayloadInEXT Payload payload;\nvoid main() {\n"
    s += "    if (gl_PrimitiveID % 2 == 1) { ignoreIntersectionEXT; }\n}\n"
    return s


def g_intersection(k):
    h = k["attrs"] // 4
    s = GLSL_HEAD + g_structs(k) + "hitAttributeEXT Attr attr;\nvoid main() {\n"
    s += f"    for (int i = 0; i < {h}; i++) {{ attr.a[i] = gl_ObjectRayOriginEXT.x + float(i); }}\n"
    s += "    reportIntersectionEXT(1.0, 0u);\n}\n"
    return s


def g_callable(k, nested):
    cw = k["calldata"] // 4
    a = k["call_array"]
    s = GLSL_HEAD + g_structs(k)
    s += "struct Inner { uint data[4]; };\n"
    s += "layout(location = 0) callableDataInEXT CallData cd;\n"
    if nested:
        s += "layout(location = 1) callableDataEXT Inner inner;\n"
    s += "void main() {\n"
    if a:
        s += f"    float arr[{a}];\n    for (uint i = 0u; i < {a}u; i++) {{ arr[i] = float(cd.data[i % {cw}u]); }}\n"
    if nested:
        s += "    inner.data[0] = cd.data[0];\n    executeCallableEXT(1, 1);\n"
    s += f"    cd.data[{cw - 1}] = cd.data[0] * 3u + 1u"
    if a:
        s += f" + uint(arr[cd.data[0] % {a}u])"
    if nested:
        s += " + inner.data[3]"
    return s + ";\n}\n"


def g_inner_callable(k):
    s = GLSL_HEAD + "struct Inner { uint data[4]; };\n"
    s += "layout(location = 1) callableDataInEXT Inner inner;\nvoid main() {\n    inner.data[3] = inner.data[0] + 5u;\n}\n"
    return s


# --- HLSL ---------------------------------------------------------------


def h_structs(k):
    s = f"struct Payload {{ uint data[{k['payload'] // 4}]; }};\n"
    s += f"struct Shadow {{ uint data[{k['shadow'] // 4}]; }};\n"
    s += f"struct CallData {{ uint data[{k['calldata'] // 4}]; }};\n"
    s += f"struct Attr {{ float a[{k['attrs'] // 4}]; }};\n"
    s += "struct Inner { uint data[4]; };\n"
    s += "RaytracingAccelerationStructure tlas : register(t0);\n"
    s += "RWStructuredBuffer<uint> result : register(u1);\n"
    s += "StructuredBuffer<float> values : register(t2);\n"
    return s


def h_flags(k):
    return "RAY_FLAG_NONE" if k["anyhit"] else "RAY_FLAG_FORCE_OPAQUE"


SHADOW_FLAGS_H = "RAY_FLAG_ACCEPT_FIRST_HIT_AND_END_SEARCH | RAY_FLAG_SKIP_CLOSEST_HIT_SHADER | RAY_FLAG_FORCE_OPAQUE"


def h_trace(payload, miss, flags, origin="float3(0.0, 1.0, 4.0)", direction="float3(0.0, 0.0, -1.0)", indent="    "):
    return (
        f"{indent}{{\n{indent}    RayDesc ray;\n{indent}    ray.Origin = {origin};\n{indent}    ray.TMin = 0.001;\n"
        f"{indent}    ray.Direction = {direction};\n{indent}    ray.TMax = 100.0;\n"
        f"{indent}    TraceRay(tlas, {flags}, 0xFF, 0, 0, {miss}, ray, {payload});\n{indent}}}\n"
    )


def h_raygen(k):
    w = k["payload"] // 4
    n = k["rg_live"]
    a = k["rg_array"]
    cw = k["calldata"] // 4
    s = '[shader("raygeneration")]\nvoid RayGen()\n{\n'
    s += "    uint2 id = DispatchRaysIndex().xy;\n    uint idx = id.y * DispatchRaysDimensions().x + id.x;\n"
    s += "    Payload payload;\n"
    if k["rg_callable"]:
        s += "    CallData cd;\n"
    use = "0.0" + "".join(f" + v{i}" for i in range(n))
    arr_use = f" + arr[payload.data[0] % {a}]" if a else ""
    call = "    cd.data[0] = idx;\n    CallShader(0, cd);\n" if k["rg_callable"] else ""
    call_use = f" + cd.data[{cw - 1}]" if k["rg_callable"] else ""
    if k["rg_mode"] in ("single", "straight"):
        s += "    payload.data[0] = 0;\n" + h_trace("payload", 0, h_flags(k))
        for i in range(n):
            src = f"(float)payload.data[{i % w}]" if k["rg_live_src"] == "payload" else f"values[idx + {i}]"
            s += f"    float v{i} = {src} * {i}.5 + (float)payload.data[{(i * 7) % w}];\n"
        if a:
            s += f"    float arr[{a}];\n    for (uint i = 0; i < {a}; i++) {{ arr[i] = (float)payload.data[i % {w}] + (float)i; }}\n"
        s += call
        if k["rg_mode"] == "straight":
            s += "    payload.data[0] = 0;\n" + h_trace("payload", 0, h_flags(k))
        s += f"    result[idx] = (uint)({use}{arr_use}) + payload.data[{1 % w}]{call_use};\n"
        if k["rg_use"] == "each":
            s += "".join(f"    result[idx + {i + 1}] = (uint)v{i};\n" for i in range(n))
    else:
        for i in range(n):
            init = "0.0" if k["rg_live_src"] == "payload" else f"values[idx + {i}]"
            s += f"    float v{i} = {init};\n"
        if a:
            s += f"    float arr[{a}];\n    for (uint i = 0; i < {a}; i++) {{ arr[i] = values[i]; }}\n"
        s += f"    for (uint bounce = 0; bounce < {k['rg_bounces']}; bounce++)\n    {{\n"
        s += "        payload.data[0] = 0;\n"
        s += h_trace("payload", 0, h_flags(k), direction="float3(0.0, (float)bounce * 0.1, -1.0)", indent="        ")
        for i in range(n):
            s += f"        v{i} = v{i} * 0.5 + (float)payload.data[{i % w}] * {i}.5;\n"
        if a:
            s += f"        arr[bounce % {a}] += (float)payload.data[{w - 1}];\n"
        if call:
            s += "    " + call.replace("\n    ", "\n        ")
        s += "    }\n"
        s += f"    result[idx] = (uint)({use}{arr_use}){call_use};\n"
    return s + "}\n"


def h_miss(k, trace):
    w = k["payload"] // 4
    s = '[shader("miss")]\nvoid Miss(inout Payload payload)\n{\n'
    if trace:
        s += "    Shadow shadow;\n    shadow.data[0] = 1;\n"
        s += h_trace("shadow", 1, SHADOW_FLAGS_H, "WorldRayOrigin()", "float3(0.0, 1.0, 0.0)")
    s += f"    for (uint i = 1; i < {w}; i++) {{ payload.data[i] = 7{' + shadow.data[0]' if trace else ''}; }}\n"
    return s + "}\n"


def h_shadow_miss(k):
    return '[shader("miss")]\nvoid ShadowMiss(inout Shadow shadow)\n{\n    shadow.data[0] = 0;\n}\n'


def h_closest_hit(k, kind, procedural, name):
    w = k["payload"] // 4
    cw = k["calldata"] // 4
    n = k["ch_live"]
    a = k["ch_array"]
    rec = "recursive" in kind
    shadow = "shadow" in kind
    call = "callable" in kind
    attr_t = "Attr" if procedural else "BuiltInTriangleIntersectionAttributes"
    s = f'[shader("closesthit")]\nvoid {name}(inout Payload payload, in {attr_t} attr)\n{{\n'
    at = "attr.a[0]" if procedural else "attr.barycentrics.x"
    for i in range(n):
        s += f"    float v{i} = (float)payload.data[{(i + 1) % w}] * {i}.25 + values[PrimitiveIndex() + {i}] + {at};\n"
    if a:
        s += f"    float arr[{a}];\n    for (uint i = 0; i < {a}; i++) {{ arr[i] = (float)payload.data[i % {w}] * {at}; }}\n"
    if w > 1:
        s += f"    for (uint i = 1; i < {w}; i++) {{ payload.data[i] = payload.data[i] * 3 + i; }}\n"
    if call:
        s += "    CallData cd;\n    cd.data[0] = payload.data[0];\n    CallShader(0, cd);\n"
    if shadow:
        s += "    Shadow shadow;\n    shadow.data[0] = 1;\n"
        s += h_trace("shadow", 1, SHADOW_FLAGS_H, "WorldRayOrigin() + WorldRayDirection() * RayTCurrent()", "float3(0.0, 1.0, 0.0)")
    if rec:
        s += f"    if (payload.data[0] < {k['rec_bound']})\n    {{\n        Payload next;\n"
        s += "        next.data[0] = payload.data[0] + 1;\n"
        s += h_trace(
            "next",
            0,
            h_flags(k),
            "WorldRayOrigin() + WorldRayDirection() * RayTCurrent()",
            "reflect(WorldRayDirection(), float3(0.0, 1.0, 0.0))",
            indent="        ",
        )
        s += f"        payload.data[{w - 1}] += next.data[{w - 1}] + 1;\n    }}\n"
    use = "0.0" + "".join(f" + v{i}" for i in range(n))
    if a:
        use += f" + arr[payload.data[{w - 1}] % {a}]"
    extra = ""
    if shadow:
        extra += " + shadow.data[0]"
    if call:
        extra += f" + cd.data[{cw - 1}]"
    s += f"    payload.data[{w - 1}] += (uint)({use}){extra};\n"
    if k["ch_use"] == "each":
        s += "".join(f"    payload.data[{i % w}] += (uint)v{i};\n" for i in range(n))
    return s + "}\n"


def h_any_hit(k):
    return (
        '[shader("anyhit")]\nvoid AnyHit(inout Payload payload, in BuiltInTriangleIntersectionAttributes attr)\n{\n'
        "    if (PrimitiveIndex() % 2 == 1) { IgnoreHit(); }\n}\n"
    )


def h_intersection(k):
    h = k["attrs"] // 4
    s = '[shader("intersection")]\nvoid Intersect()\n{\n    Attr attr;\n'
    s += f"    for (int i = 0; i < {h}; i++) {{ attr.a[i] = ObjectRayOrigin().x + (float)i; }}\n"
    return s + "    ReportHit(1.0, 0, attr);\n}\n"


def h_callable(k, nested):
    cw = k["calldata"] // 4
    a = k["call_array"]
    s = '[shader("callable")]\nvoid Callable(inout CallData cd)\n{\n'
    if a:
        s += f"    float arr[{a}];\n    for (uint i = 0; i < {a}; i++) {{ arr[i] = (float)cd.data[i % {cw}]; }}\n"
    if nested:
        s += "    Inner inner;\n    inner.data[0] = cd.data[0];\n    CallShader(1, inner);\n"
    s += f"    cd.data[{cw - 1}] = cd.data[0] * 3 + 1"
    if a:
        s += f" + (uint)arr[cd.data[0] % {a}]"
    if nested:
        s += " + inner.data[3]"
    return s + ";\n}\n"


def h_inner_callable(k):
    return '[shader("callable")]\nvoid InnerCallable(inout Inner inner)\n{\n    inner.data[3] = inner.data[0] + 5;\n}\n'


# --- pipelines ----------------------------------------------------------


def describe(k, shader):
    """The pipeline description; `shader(stage_key)` gives (file, entry)."""

    def ref(key):
        f, e = shader(key)
        return f'file = "{f}"' + (f'\nentry = "{e}"' if e else "")

    def inline(key):
        f, e = shader(key)
        return f'{{ file = "{f}"' + (f', entry = "{e}"' if e else "") + " }"

    t = f"# Random pipeline, seed {k['seed']} ({k['set']}): {k['lang']}, {k['payload']}-byte payload,\n"
    t += f"# raygen {k['rg_mode']}, closest hit {k['ch_kind']}. Generated by calibration/random/gen.py.\n"
    t += f"max_recursion_depth = {k['depth']}\n"
    if k["procedural"]:
        t += "instance_sbt_offsets = [0, 1]\n"
    t += f"\n[[raygen]]\n{ref('rgen')}\n\n[[miss]]\n{ref('miss')}\n"
    if k["uses_shadow"]:
        t += f"\n[[miss]]\n{ref('shadow_miss')}\n"
    if k["extra_miss"]:
        t += f"\n[[miss]]\n{ref('shadow_miss')}\n"
    t += f'\n[[hit_group]]\ntype = "triangles"\nclosest_hit = {inline("chit")}\n'
    if k["anyhit"]:
        t += f"any_hit = {inline('ahit')}\n"
    if k["procedural"]:
        t += f'\n[[hit_group]]\ntype = "procedural"\nclosest_hit = {inline("pchit")}\nintersection = {inline("isect")}\n'
    if k["uses_callable"]:
        t += f"\n[[callable]]\n{ref('call')}\n"
        if k["call_nested"]:
            t += f"\n[[callable]]\n{ref('inner')}\n"
    return t


def write_glsl(k, d):
    files = {
        "rgen": ("main.rgen", g_raygen(k)),
        "miss": ("main.rmiss", g_miss(k, k["miss_trace"])),
        "shadow_miss": ("shadow.rmiss", g_shadow_miss(k)),
        "chit": ("main.rchit", g_closest_hit(k, k["ch_kind"], False)),
        "ahit": ("main.rahit", g_any_hit(k)),
        "pchit": ("proc.rchit", g_closest_hit(k, k["proc_kind"], True)),
        "isect": ("main.rint", g_intersection(k)),
        "call": ("main.rcall", g_callable(k, k["call_nested"])),
        "inner": ("inner.rcall", g_inner_callable(k)),
    }
    used = set()
    toml = describe(k, lambda key: (used.add(key), (files[key][0] + ".spv", None))[1])
    for key in sorted(used):
        name, text = files[key]
        with open(os.path.join(d, name), "w") as f:
            f.write(text)
        r = subprocess.run(
            ["glslangValidator", "--target-env", "vulkan1.2", "-V", name, "-o", name + ".spv"],
            cwd=d,
            capture_output=True,
            text=True,
        )
        if r.returncode != 0:
            sys.exit(f"seed {k['seed']}: glslang failed on {name}:\n{r.stdout}{r.stderr}")
    return toml


def write_hlsl(k, d):
    entries = {
        "rgen": ("RayGen", h_raygen(k)),
        "miss": ("Miss", h_miss(k, k["miss_trace"])),
        "shadow_miss": ("ShadowMiss", h_shadow_miss(k)),
        "chit": ("ClosestHit", h_closest_hit(k, k["ch_kind"], False, "ClosestHit")),
        "ahit": ("AnyHit", h_any_hit(k)),
        "pchit": ("ProceduralHit", h_closest_hit(k, k["proc_kind"], True, "ProceduralHit")),
        "isect": ("Intersect", h_intersection(k)),
        "call": ("Callable", h_callable(k, k["call_nested"])),
        "inner": ("InnerCallable", h_inner_callable(k)),
    }
    used = []
    toml = describe(k, lambda key: (used.append(key), ("main.hlsl", entries[key][0]))[1])
    text = f"// Random pipeline, seed {k['seed']}: generated by calibration/random/gen.py.\n" + h_structs(k)
    for key in dict.fromkeys(used):
        text += "\n" + entries[key][1]
    with open(os.path.join(d, "main.hlsl"), "w") as f:
        f.write(text)
    return toml


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=640)
    ap.add_argument("--split", type=int, default=320)
    ap.add_argument("--first", type=int, default=0, help="keep the seeds below this one already in --out")
    ap.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "out"))
    args = ap.parse_args()
    manifest = os.path.join(args.out, "manifest.csv")
    rows = []
    if args.first > 0:
        rows = [r for r in csv.DictReader(open(manifest)) if int(r["seed"]) < args.first]
        for seed in range(args.first, args.seeds):
            shutil.rmtree(os.path.join(args.out, f"s{seed:03}"), ignore_errors=True)
    else:
        if os.path.isdir(args.out):
            shutil.rmtree(args.out)
        os.makedirs(args.out)
    for seed in range(args.first, args.seeds):
        k = knobs(seed, args.split)
        d = os.path.join(args.out, f"s{seed:03}")
        os.makedirs(d)
        toml = write_glsl(k, d) if k["lang"] == "glsl" else write_hlsl(k, d)
        with open(os.path.join(d, f"s{seed:03}.pipeline.toml"), "w") as f:
            f.write(toml)
        rows.append(k)
    with open(manifest, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    print(f"generated {len(rows)} pipelines in {args.out} ({sum(r['set'] == 'fit' for r in rows)} fitting)")


if __name__ == "__main__":
    main()
