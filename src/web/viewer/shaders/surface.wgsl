// The input surface: per-vertex normals (split at creases) and colours (plain or from a scalar
// field's colormap), lit by a headlight so every view is readable. With
// flags.w = 1 (the parametrization layer) the per-vertex (u, v) of an
// integer-grid map is drawn as a checkerboard of unit squares (one unit =
// one target edge) with the integer isolines as dark lines.

struct Globals {
    view_proj: mat4x4<f32>,
    // Camera position (xyz).
    eye: vec4<f32>,
    // Target width and height in pixels, line width in pixels, overlay offset toward the eye (world units).
    viewport: vec4<f32>,
    // x: 1 when the render target is sRGB (colours are given in sRGB and must be linearised);
    // y: 1 for flat shading; z: how far markers are lifted toward the eye;
    // w: 1 to draw the (u, v) checkerboard.
    flags: vec4<f32>,
};

@group(0) @binding(0) var<uniform> globals: Globals;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec4<f32>,
    @location(3) uv: vec2<f32>,
};

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) color: vec4<f32>,
    @location(3) uv: vec2<f32>,
};

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = globals.view_proj * vec4<f32>(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.color = v.color;
    out.uv = v.uv;
    return out;
}

fn to_target(c: vec3<f32>) -> vec4<f32> {
    if (globals.flags.x > 0.5) {
        return vec4<f32>(pow(c, vec3<f32>(2.2)), 1.0);
    }
    return vec4<f32>(c, 1.0);
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let to_eye = normalize(globals.eye.xyz - in.world);
    // The triangle's own normal, from screen-space derivatives (uniform
    // control flow: before any branch), turned toward the eye.
    var face = cross(dpdx(in.world), dpdy(in.world));
    if (length(face) > 1e-20) {
        face = normalize(face);
    } else {
        face = to_eye;
    }
    if (dot(face, to_eye) < 0.0) {
        face = -face;
    }
    // Smooth vertex normals; the viewer split them at creases (scene.rs,
    // split_at_creases), so a CAD edge keeps its step. Flat: the face's.
    var n = face;
    let len = length(in.normal);
    if (len > 1e-12 && globals.flags.y < 0.5) {
        n = in.normal / len;
        if (!front) {
            n = -n;
        }
    }
    // The integer grid: squares alternate light and dark by the parity of
    // floor(u) + floor(v); isolines u, v ∈ ℤ about a pixel wide (the
    // derivative comes before any branch).
    let uv_width = max(fwidth(in.uv), vec2<f32>(1e-6));
    var base = in.color.rgb;
    if (globals.flags.w > 0.5) {
        let cell = vec2<i32>(floor(in.uv));
        if (((cell.x + cell.y) & 1) != 0) {
            base = base * 0.55;
        }
        let to_line = abs(fract(in.uv - vec2<f32>(0.5)) - vec2<f32>(0.5)) / uv_width;
        let line = 1.0 - clamp(min(to_line.x, to_line.y) - 0.5, 0.0, 1.0);
        base = mix(base, vec3<f32>(0.1, 0.12, 0.18), 0.85 * line);
    }
    // Back faces (holes, inconsistent orientation) are darker.
    var tint = 1.0;
    if (!front) {
        tint = 0.7;
    }
    // Soft light: a headlight from above left plus a sky/ground ambient
    // term, and a faint broad highlight (faces seen head-on do not blow out).
    let key = normalize(to_eye + vec3<f32>(-0.3, 0.5, 0.0));
    let diffuse = 0.6 * max(dot(n, key), 0.0) + 0.25 * max(dot(n, to_eye), 0.0);
    let ambient = 0.22 + 0.08 * n.y;
    let half_vector = normalize(key + to_eye);
    let specular = pow(max(dot(n, half_vector), 0.0), 24.0) * 0.05;
    let color = base * tint * (ambient + diffuse) + vec3<f32>(specular);
    return to_target(color);
}
