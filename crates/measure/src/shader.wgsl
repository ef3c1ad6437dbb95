// Measurement shaders: a vertex shader and a fragment shader with an
// adjustable ALU loop, so the vertex and fragment costs can be varied
// independently (paper 000 Table 1's simple/complex shaders).
struct Params {
    vs_loops: u32,
    fs_loops: u32,
    layers: u32,
    pad: u32,
};

@group(0) @binding(0) var<uniform> params: Params;
// Depth slot of each instance (layer): a permutation of 0..layers.
@group(0) @binding(1) var<storage, read> order: array<u32>;

struct VOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) v: f32,
};

@vertex
fn vs_main(@location(0) xy: vec2<f32>, @builtin(instance_index) inst: u32) -> VOut {
    var acc = xy.x * 0.37 + xy.y * 0.11;
    for (var i = 0u; i < params.vs_loops; i = i + 1u) {
        acc = fract(acc * 1.61803 + 0.1234);
    }
    let slot = order[inst];
    let z = (f32(slot) + 0.5) / f32(max(params.layers, 1u));
    var o: VOut;
    // The loop result is kept alive through the varying (and a negligible offset).
    o.pos = vec4<f32>(xy.x * 2.0 - 1.0 + acc * 1e-7, 1.0 - xy.y * 2.0, z, 1.0);
    o.v = acc;
    return o;
}

@fragment
fn fs_main(in: VOut) -> @location(0) vec4<f32> {
    var acc = in.v + in.pos.x * 0.001;
    for (var i = 0u; i < params.fs_loops; i = i + 1u) {
        acc = fract(acc * 1.61803 + 0.1234);
    }
    return vec4<f32>(acc, in.v, 0.5, 1.0);
}
