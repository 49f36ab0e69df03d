// Shows the linear float render: exposure, an optional tonemap, then the sRGB transfer
// function (skipped when the framebuffer encodes sRGB itself). Image modes other than the
// render are already display colours in linear space: they skip exposure and tonemap.

struct Params {
    exposure: f32,
    // 0: clamp, 1: Reinhard, 2: ACES (Narkowicz's fit).
    tonemap: u32,
    // 1 when this shader must apply the sRGB transfer (a non-sRGB framebuffer).
    encode_srgb: u32,
    // 1 for image modes: no exposure, no tonemap.
    raw: u32,
    // 1: bilinear between the four nearest pixels (a non-integer scale); 0: nearest pixel.
    bilinear: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
};

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var image: texture_2d<f32>;

struct VertexOut {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

// One triangle that covers the viewport; uv (0,0) is the image's top-left corner.
@vertex
fn vs_main(@builtin(vertex_index) index: u32) -> VertexOut {
    let uv = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    var out: VertexOut;
    out.position = vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0);
    out.uv = uv;
    return out;
}

fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let low = c * 12.92;
    let high = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(high, low, c <= vec3<f32>(0.0031308));
}

fn aces(c: vec3<f32>) -> vec3<f32> {
    return (c * (2.51 * c + 0.03)) / (c * (2.43 * c + 0.59) + 0.14);
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let size = textureDimensions(image);
    var c: vec3<f32>;
    if (params.bilinear == 1u) {
        // Bilinear by hand: the float texture is not filterable on every adapter.
        let f = in.uv * vec2<f32>(size) - vec2<f32>(0.5);
        let base = floor(f);
        let t = f - base;
        let last = vec2<i32>(size) - vec2<i32>(1);
        let a = clamp(vec2<i32>(base), vec2<i32>(0), last);
        let b = clamp(vec2<i32>(base) + vec2<i32>(1), vec2<i32>(0), last);
        let top = mix(textureLoad(image, a, 0).rgb, textureLoad(image, vec2<i32>(b.x, a.y), 0).rgb, t.x);
        let bottom = mix(textureLoad(image, vec2<i32>(a.x, b.y), 0).rgb, textureLoad(image, b, 0).rgb, t.x);
        c = mix(top, bottom, t.y);
    } else {
        // Nearest pixel at whole scales: pixel values read as they are.
        let p = min(vec2<u32>(in.uv * vec2<f32>(size)), size - vec2<u32>(1u, 1u));
        c = textureLoad(image, p, 0).rgb;
    }
    if (params.raw == 0u) {
        c = c * params.exposure;
        if (params.tonemap == 1u) {
            c = c / (vec3<f32>(1.0) + c);
        } else if (params.tonemap == 2u) {
            c = aces(c);
        }
    }
    // NaN fails every comparison; max() with 0 turns it into 0 on common hardware, and the
    // clamp keeps the rest in range.
    c = clamp(max(c, vec3<f32>(0.0)), vec3<f32>(0.0), vec3<f32>(1.0));
    if (params.encode_srgb == 1u) {
        c = srgb_encode(c);
    }
    return vec4<f32>(c, 1.0);
}
