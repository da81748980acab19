// Point layers (feature vertices, singularities, the picked point): each
// instance is a round marker of a fixed pixel size, shaded like a small ball
// and pulled toward the eye so it sits on top of the surface.

struct Globals {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    viewport: vec4<f32>,
    flags: vec4<f32>,
};

@group(0) @binding(0) var<uniform> globals: Globals;

struct PointIn {
    @location(0) position: vec3<f32>,
    @location(1) color: vec4<f32>,
    // Diameter in pixels.
    @location(2) size: f32,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec4<f32>,
    @location(1) uv: vec2<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) vertex: u32, p: PointIn) -> VertexOut {
    let k = vertex % 6u;
    let x = select(-1.0, 1.0, ((0x32u >> k) & 1u) == 1u);
    let y = select(-1.0, 1.0, ((0x2Cu >> k) & 1u) == 1u);

    let d = globals.eye.xyz - p.position;
    let len = max(length(d), 1e-12);
    let lifted = p.position + d / len * max(globals.viewport.w * 2.0, globals.flags.z);
    let c = globals.view_proj * vec4<f32>(lifted, 1.0);
    let offset = vec2<f32>(x, y) * p.size / globals.viewport.xy * c.w;

    var out: VertexOut;
    out.clip = vec4<f32>(c.xy + offset, c.zw);
    out.color = p.color;
    out.uv = vec2<f32>(x, y);
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let r2 = dot(in.uv, in.uv);
    if (r2 > 1.0) {
        discard;
    }
    // A white ring inside a dark rim keeps markers visible on any colour
    // map, light or dark.
    var color = in.color.rgb * (0.7 + 0.3 * sqrt(1.0 - r2));
    if (r2 > 0.45) {
        color = vec3<f32>(1.0);
    }
    if (r2 > 0.75) {
        color = vec3<f32>(0.08, 0.09, 0.12);
    }
    if (globals.flags.x > 0.5) {
        color = pow(color, vec3<f32>(2.2));
    }
    return vec4<f32>(color, 1.0);
}
