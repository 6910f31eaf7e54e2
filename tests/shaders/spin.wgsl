// Runs for as long as it is told (an LCG the compiler cannot fold), to test
// fence timeouts.
struct Params {
    iterations: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<storage, read_write> out: array<u32>;
@group(0) @binding(1) var<uniform> params: Params;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>) {
    var x = gid.x;
    for (var i = 0u; i < params.iterations; i++) {
        x = x * 1664525u + 1013904223u;
    }
    out[gid.x] = x;
}
