// Line layers (polygon edges, principal directions, cross-field arms): each
// instance is one segment, drawn as a screen-space quad of constant pixel
// width (WebGPU has no wide lines), pulled slightly toward the eye so lines
// on the surface are not hidden by it.

struct Globals {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    viewport: vec4<f32>,
    flags: vec4<f32>,
};

@group(0) @binding(0) var<uniform> globals: Globals;

struct SegmentIn {
    @location(0) a: vec3<f32>,
    @location(1) b: vec3<f32>,
    @location(2) color: vec4<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec4<f32>,
};

fn toward_eye(p: vec3<f32>) -> vec3<f32> {
    let d = globals.eye.xyz - p;
    let len = max(length(d), 1e-12);
    return p + d / len * globals.viewport.w;
}

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, s: SegmentIn) -> VertexOut {
    // Six corners, two triangles: which end (0 = a, 1 = b) and which side.
    let k = vertex % 6u;
    let end = f32((0x32u >> k) & 1u);
    let side = select(-1.0, 1.0, ((0x2Cu >> k) & 1u) == 1u);

    let ca = globals.view_proj * vec4<f32>(toward_eye(s.a), 1.0);
    let cb = globals.view_proj * vec4<f32>(toward_eye(s.b), 1.0);
    let half_size = globals.viewport.xy * 0.5;
    let sa = ca.xy / max(ca.w, 1e-6) * half_size;
    let sb = cb.xy / max(cb.w, 1e-6) * half_size;
    var dir = sb - sa;
    if (length(dir) < 1e-6) {
        dir = vec2<f32>(1.0, 0.0);
    }
    dir = normalize(dir);
    let normal = vec2<f32>(-dir.y, dir.x);
    let c = mix(ca, cb, end);
    let offset = normal * side * globals.viewport.z * 0.5 / half_size * c.w;

    var out: VertexOut;
    out.clip = vec4<f32>(c.xy + offset, c.zw);
    out.color = s.color;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    if (globals.flags.x > 0.5) {
        return vec4<f32>(pow(in.color.rgb, vec3<f32>(2.2)), 1.0);
    }
    return vec4<f32>(in.color.rgb, 1.0);
}
