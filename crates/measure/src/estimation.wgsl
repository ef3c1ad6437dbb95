// Estimation study shaders (estimation_device.rs): each draw is one object,
// a mesh in [0,1]^2 placed on the target by its entry in `objects`
// (selected by the draw's first instance), with its own vertex- and
// fragment-shader ALU loop counts (the loop of shader.wgsl).
struct Object {
    offset: vec2<f32>,
    scale: vec2<f32>,
    vs_loops: u32,
    fs_loops: u32,
    pad0: u32,
    pad1: u32,
};

@group(0) @binding(0) var<storage, read> objects: array<Object>;

struct VOut {
    @builtin(position) pos: vec4<f32>,
    @location(0) v: f32,
    @location(1) @interpolate(flat) fs_loops: u32,
};

@vertex
fn vs_main(@location(0) xy: vec2<f32>, @builtin(instance_index) inst: u32) -> VOut {
    let o = objects[inst];
    var acc = xy.x * 0.37 + xy.y * 0.11;
    for (var i = 0u; i < o.vs_loops; i = i + 1u) {
        acc = fract(acc * 1.61803 + 0.1234);
    }
    let p = o.offset + xy * o.scale;
    var out: VOut;
    // The loop result is kept alive through the varying (and a negligible offset).
    out.pos = vec4<f32>(p.x + acc * 1e-7, p.y, 0.5, 1.0);
    out.v = acc;
    out.fs_loops = o.fs_loops;
    return out;
}

@fragment
fn fs_main(in: VOut) -> @location(0) vec4<f32> {
    var acc = in.v + in.pos.x * 0.001;
    for (var i = 0u; i < in.fs_loops; i = i + 1u) {
        acc = fract(acc * 1.61803 + 0.1234);
    }
    return vec4<f32>(acc, in.v, 0.5, 1.0);
}
