// The clicked pixel's ray tree drawn over the render: world-space line segments projected with
// the render camera's own projection (the inverse of its pixel-to-ray mapping), coloured by
// ray kind from the palette the tree views share.

struct Camera {
    clip_from_world: mat4x4<f32>,
    // 1 when colours must be converted to linear (an sRGB framebuffer encodes them itself).
    linearize: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> camera: Camera;

struct VertexIn {
    @location(0) position: vec3<f32>,
    // sRGB colour with alpha.
    @location(1) color: vec4<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec4<f32>,
};

@vertex
fn vs_main(in: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = camera.clip_from_world * vec4<f32>(in.position, 1.0);
    out.color = in.color;
    return out;
}

fn srgb_decode(c: vec3<f32>) -> vec3<f32> {
    let low = c / 12.92;
    let high = pow((c + 0.055) / 1.055, vec3<f32>(2.4));
    return select(high, low, c <= vec3<f32>(0.04045));
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    var rgb = in.color.rgb;
    if (camera.linearize == 1u) {
        rgb = srgb_decode(rgb);
    }
    return vec4<f32>(rgb, in.color.a);
}
