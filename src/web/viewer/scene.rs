//! What the viewer shows, as plain data with no GPU in sight: one surface
//! with an optional scalar quantity, named line sets and point sets. The
//! renderer turns a [`Scene`] into buffers; tests check it natively.
//!
//! Everything arrives from JavaScript, so every constructor checks lengths,
//! indices and finiteness and returns a [`SceneError`] instead of panicking.

use glam::Vec3;
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use parry3d_f64::query::Ray;

use super::colormap::{Colormap, finite_range};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneError {
    #[error("{what}: length {len} is not a multiple of {multiple}")]
    Length {
        what: &'static str,
        len: usize,
        multiple: usize,
    },
    #[error("{what}: index {index} is out of range (there are {count} vertices)")]
    Index {
        what: &'static str,
        index: u32,
        count: usize,
    },
    #[error("{what}: expected {expected} values, got {got}")]
    Count {
        what: &'static str,
        expected: usize,
        got: usize,
    },
    #[error("{what}: coordinate {index} is not finite")]
    NonFinite { what: &'static str, index: usize },
    #[error("unknown colormap {0:?} (use viridis or violet-green)")]
    Colormap(String),
    #[error("there is no surface yet")]
    NoSurface,
}

/// Default surface colour when no scalar is shown (sRGB).
pub const PLAIN: [u8; 4] = [0xc8, 0xcd, 0xd8, 0xff];

/// A triangle mesh to draw: positions, per-vertex normals, triangles, and
/// a BVH over the triangles for [`Surface::pick`], built with the surface.
#[derive(Debug, Clone, Default)]
pub struct Surface {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    bvh: Bvh,
}

fn vec3s(what: &'static str, flat: &[f32]) -> Result<Vec<Vec3>, SceneError> {
    if flat.len() % 3 != 0 {
        return Err(SceneError::Length {
            what,
            len: flat.len(),
            multiple: 3,
        });
    }
    if let Some(i) = flat.iter().position(|x| !x.is_finite()) {
        return Err(SceneError::NonFinite { what, index: i });
    }
    Ok(flat.chunks_exact(3).map(Vec3::from_slice).collect())
}

fn check_indices(what: &'static str, indices: &[u32], count: usize) -> Result<(), SceneError> {
    match indices.iter().find(|&&i| i as usize >= count) {
        Some(&index) => Err(SceneError::Index { what, index, count }),
        None => Ok(()),
    }
}

impl Surface {
    /// From flat arrays: `positions` and `normals` are xyz triples,
    /// `indices` vertex triples (counter-clockwise seen from outside).
    pub fn new(positions: &[f32], indices: &[u32], normals: &[f32]) -> Result<Surface, SceneError> {
        let positions = vec3s("positions", positions)?;
        let normals = vec3s("normals", normals)?;
        if normals.len() != positions.len() {
            return Err(SceneError::Count {
                what: "normals",
                expected: positions.len(),
                got: normals.len(),
            });
        }
        if indices.len() % 3 != 0 {
            return Err(SceneError::Length {
                what: "triangle indices",
                len: indices.len(),
                multiple: 3,
            });
        }
        check_indices("triangle indices", indices, positions.len())?;
        let triangles: Vec<[u32; 3]> = indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        let bvh = triangle_bvh(&positions, &triangles);
        Ok(Surface {
            positions,
            normals,
            triangles,
            bvh,
        })
    }

    /// A bounding sphere: the box's centre and the farthest vertex from it
    /// (tighter than the box's half diagonal), or `None` when empty.
    pub fn bounding_sphere(&self) -> Option<(Vec3, f32)> {
        let first = *self.positions.first()?;
        let (lo, hi) = self
            .positions
            .iter()
            .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        let center = (lo + hi) * 0.5;
        let radius = self
            .positions
            .iter()
            .map(|p| p.distance_squared(center))
            .fold(0.0f32, f32::max)
            .sqrt();
        Some((center, radius.max(1e-6)))
    }

    /// The nearest intersection of a ray with the triangles (both sides
    /// count), through the BVH: only the triangles whose boxes the ray
    /// meets before the nearest hit so far are tested.
    pub fn pick(&self, origin: Vec3, dir: Vec3) -> Option<Hit> {
        if !origin.is_finite() || !dir.is_finite() {
            return None;
        }
        let ray = Ray::new(origin.as_dvec3(), dir.as_dvec3());
        let (triangle, _) = self.bvh.cast_ray(&ray, f64::MAX, |t, _| {
            self.ray_hits(origin, dir, t).map(|(t, _, _)| f64::from(t))
        })?;
        self.hit(origin, dir, triangle)
    }

    /// [`Surface::pick`] by testing every triangle in turn: the reference
    /// the BVH's answers are tested against.
    pub fn pick_exhaustive(&self, origin: Vec3, dir: Vec3) -> Option<Hit> {
        let mut best: Option<(u32, f32)> = None;
        for t in 0..self.triangles.len() as u32 {
            if let Some((distance, _, _)) = self.ray_hits(origin, dir, t) {
                if best.is_none_or(|(_, d)| distance < d) {
                    best = Some((t, distance));
                }
            }
        }
        self.hit(origin, dir, best?.0)
    }

    /// Where the ray meets triangle `t`: Möller–Trumbore's (t, u, v).
    fn ray_hits(&self, origin: Vec3, dir: Vec3, t: u32) -> Option<(f32, f32, f32)> {
        let [a, b, c] = self
            .triangles
            .get(t as usize)?
            .map(|i| self.positions[i as usize]);
        ray_triangle(origin, dir, a, b, c)
    }

    /// The hit of the ray on triangle `triangle`, with its nearest corner.
    fn hit(&self, origin: Vec3, dir: Vec3, triangle: u32) -> Option<Hit> {
        let (t, u, v) = self.ray_hits(origin, dir, triangle)?;
        let weights = [1.0 - u - v, u, v];
        let corner = (0..3).fold(0, |m, k| if weights[k] > weights[m] { k } else { m });
        Some(Hit {
            point: origin + dir * t,
            distance: t,
            triangle,
            vertex: self.triangles[triangle as usize][corner],
        })
    }
}

/// A BVH whose leaf `t` is triangle `t`'s bounding box, widened by a
/// little (1e-5 of the largest extent): a safety margin so that rounding
/// in the boxes' f64 ray test cannot drop a triangle that the f32 leaf
/// test hits (flat boxes of triangles in axis-aligned planes, rays
/// grazing a box). Widening only costs leaf tests, never an answer.
fn triangle_bvh(positions: &[Vec3], triangles: &[[u32; 3]]) -> Bvh {
    let (lo, hi) = positions
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        });
    let margin = if lo.is_finite() && hi.is_finite() {
        1e-5 * f64::from((hi - lo).max_element()) + 1e-12
    } else {
        0.0
    };
    let boxes: Vec<Aabb> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize].as_dvec3());
            Aabb::new(a.min(b).min(c), a.max(b).max(c)).loosened(margin)
        })
        .collect();
    Bvh::from_leaves(BvhBuildStrategy::Binned, &boxes)
}

/// Dihedral angle (degrees) above which smooth shading keeps an edge sharp:
/// fandisk's CAD creases stay creases, a scan's fine triangles stay smooth.
pub const CREASE_DEGREES: f32 = 30.0;

/// The surface as the GPU draws it: vertices split where a crease passes,
/// so each side of a sharp edge has its own smooth normal.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawMesh {
    /// For each drawn vertex, the surface vertex it copies (its colour, uv).
    pub source: Vec<u32>,
    pub normals: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl DrawMesh {
    /// Per-drawn-vertex values from per-surface-vertex ones.
    pub fn expand<T: Copy>(&self, values: &[T]) -> Option<Vec<T>> {
        self.source
            .iter()
            .map(|&v| values.get(v as usize).copied())
            .collect()
    }
}

impl Surface {
    /// Smooth normals split at creases. Vertices at the same position are
    /// welded first (a result surface gives every face its own corners);
    /// the corners around a welded vertex form one smooth fan across every
    /// edge of two triangles that [`EdgeTopology::sharp_edges`] (the
    /// crate's one dihedral-angle test) does not call sharp at `degrees`,
    /// and each fan gets the angle-weighted mean of its faces' normals.
    /// A fan whose normals cancel falls back to the given vertex normal.
    /// 180° never splits.
    ///
    /// [`EdgeTopology::sharp_edges`]: crate::mesh::EdgeTopology::sharp_edges
    pub fn split_at_creases(&self, degrees: f32) -> DrawMesh {
        use crate::mesh::EdgeTopology;
        use crate::mesh::TriMesh;
        use std::collections::{HashMap, HashSet};
        let mut weld_of = HashMap::new();
        let welded: Vec<u32> = self
            .positions
            .iter()
            .enumerate()
            .map(|(i, p)| {
                *weld_of
                    .entry(p.to_array().map(f32::to_bits))
                    .or_insert(i as u32)
            })
            .collect();
        let triangles: Vec<[u32; 3]> = self
            .triangles
            .iter()
            .map(|t| t.map(|v| welded[v as usize]))
            .collect();
        let face_normals: Vec<glam::DVec3> = triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.positions[v as usize].as_dvec3());
                (b - a).cross(c - a)
            })
            .collect();
        let mesh = TriMesh {
            positions: self.positions.iter().map(|p| p.as_dvec3()).collect(),
            triangles,
        };
        let sharp: HashSet<(u32, u32)> =
            EdgeTopology::sharp_edges(&mesh, &face_normals, f64::from(degrees), false)
                .into_iter()
                .map(|e| (e.a, e.b))
                .collect();
        // Corner 3t + k is triangle t's k-th corner.
        let mut fans = crate::mesh::UnionFind::new(3 * mesh.triangles.len());
        let mut sides: HashMap<(u32, u32), Vec<(u32, u32)>> = HashMap::new();
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if a == b {
                    continue;
                }
                let corner =
                    |v: u32| 3 * t as u32 + if v == tri[k] { k } else { (k + 1) % 3 } as u32;
                let key = (a.min(b), a.max(b));
                sides
                    .entry(key)
                    .or_default()
                    .push((corner(key.0), corner(key.1)));
            }
        }
        for (key, s) in &sides {
            if let [x, y] = s[..] {
                if !sharp.contains(key) {
                    for (c, d) in [(x.0, y.0), (x.1, y.1)] {
                        fans.union(c, d);
                    }
                }
            }
        }
        let mut fan_normal = vec![glam::DVec3::ZERO; 3 * mesh.triangles.len()];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let n = face_normals[t].normalize_or_zero();
            for k in 0..3 {
                let p = |j: usize| mesh.positions[tri[j % 3] as usize];
                let angle = (p(k + 1) - p(k)).angle_between(p(k + 2) - p(k));
                let root = fans.find((3 * t + k) as u32);
                if angle.is_finite() {
                    fan_normal[root as usize] += n * angle;
                }
            }
        }
        // One drawn vertex per (surface vertex, fan).
        let mut drawn: HashMap<(u32, u32), u32> = HashMap::new();
        let (mut source, mut normals) = (Vec::new(), Vec::new());
        let triangles = self
            .triangles
            .iter()
            .enumerate()
            .map(|(t, tri)| {
                std::array::from_fn(|k| {
                    let root = fans.find((3 * t + k) as u32);
                    *drawn.entry((tri[k], root)).or_insert_with(|| {
                        let n = fan_normal[root as usize].normalize_or_zero().as_vec3();
                        normals.push(if n == Vec3::ZERO {
                            self.normals[tri[k] as usize]
                        } else {
                            n
                        });
                        source.push(tri[k]);
                        (source.len() - 1) as u32
                    })
                })
            })
            .collect();
        DrawMesh {
            source,
            normals,
            triangles,
        }
    }
}

/// Where a pick ray met the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub point: Vec3,
    pub distance: f32,
    pub triangle: u32,
    /// The triangle's corner nearest to the point.
    pub vertex: u32,
}

/// Möller–Trumbore: (t, u, v) with t > 0, or `None`.
fn ray_triangle(o: Vec3, d: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Option<(f32, f32, f32)> {
    let e1 = b - a;
    let e2 = c - a;
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0).then_some((t, u, v))
}

/// A per-vertex scalar quantity on the surface, shown through a colormap.
#[derive(Debug, Clone, PartialEq)]
pub struct Scalar {
    pub name: String,
    pub values: Vec<f32>,
    pub min: f32,
    pub max: f32,
    pub colormap: Colormap,
}

impl Scalar {
    /// `min`/`max` that are not finite or not increasing are replaced by the
    /// values' own range. `vertex_count` must match `values`.
    pub fn new(
        name: &str,
        values: &[f32],
        vertex_count: usize,
        min: f32,
        max: f32,
        colormap: &str,
    ) -> Result<Scalar, SceneError> {
        if values.len() != vertex_count {
            return Err(SceneError::Count {
                what: "scalar values",
                expected: vertex_count,
                got: values.len(),
            });
        }
        let colormap =
            Colormap::from_name(colormap).ok_or_else(|| SceneError::Colormap(colormap.into()))?;
        let (min, max) = if min.is_finite() && max.is_finite() && min < max {
            (min, max)
        } else {
            finite_range(values)
        };
        Ok(Scalar {
            name: name.to_string(),
            values: values.to_vec(),
            min,
            max,
            colormap,
        })
    }

    /// One sRGB colour per vertex.
    pub fn colors(&self) -> Vec<[u8; 4]> {
        let scale = 1.0 / (self.max - self.min);
        self.values
            .iter()
            .map(|&v| {
                let [r, g, b] = self.colormap.sample((v - self.min) * scale);
                [r, g, b, 0xff]
            })
            .collect()
    }
}

/// Per-vertex (u, v) from two floats per vertex, all finite.
pub fn uv_pairs(flat: &[f32], vertex_count: usize) -> Result<Vec<[f32; 2]>, SceneError> {
    if flat.len() != 2 * vertex_count {
        return Err(SceneError::Count {
            what: "uv",
            expected: 2 * vertex_count,
            got: flat.len(),
        });
    }
    if let Some(index) = flat.iter().position(|x| !x.is_finite()) {
        return Err(SceneError::NonFinite { what: "uv", index });
    }
    Ok(flat.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
}

/// One RGBA colour per vertex (four bytes each).
pub fn vertex_colors(rgba: &[u8], vertex_count: usize) -> Result<Vec<[u8; 4]>, SceneError> {
    if rgba.len() != 4 * vertex_count {
        return Err(SceneError::Count {
            what: "vertex colours",
            expected: 4 * vertex_count,
            got: rgba.len(),
        });
    }
    Ok(rgba
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect())
}

/// Line segments with one colour each.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LineSet {
    pub segments: Vec<[Vec3; 2]>,
    pub colors: Vec<[u8; 4]>,
}

/// Accepts one RGBA colour for all or one per element.
fn colors_for(what: &'static str, rgba: &[u8], count: usize) -> Result<Vec<[u8; 4]>, SceneError> {
    match rgba.len() {
        4 => Ok(vec![[rgba[0], rgba[1], rgba[2], rgba[3]]; count]),
        n if n == 4 * count => Ok(rgba
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect()),
        n => Err(SceneError::Count {
            what,
            expected: 4 * count,
            got: n,
        }),
    }
}

impl LineSet {
    /// From segment endpoints, six floats per segment.
    pub fn from_segments(segments: &[f32], rgba: &[u8]) -> Result<LineSet, SceneError> {
        if segments.len() % 6 != 0 {
            return Err(SceneError::Length {
                what: "line segments",
                len: segments.len(),
                multiple: 6,
            });
        }
        let points = vec3s("line segments", segments)?;
        let segments: Vec<[Vec3; 2]> = points.chunks_exact(2).map(|p| [p[0], p[1]]).collect();
        let colors = colors_for("line colours", rgba, segments.len())?;
        Ok(LineSet { segments, colors })
    }

    /// From vertex index pairs over the surface (e.g. polygon edges), so a
    /// quad is drawn as its four edges and never with a diagonal.
    pub fn from_edges(
        surface: &Surface,
        edges: &[u32],
        rgba: &[u8],
    ) -> Result<LineSet, SceneError> {
        if edges.len() % 2 != 0 {
            return Err(SceneError::Length {
                what: "edge indices",
                len: edges.len(),
                multiple: 2,
            });
        }
        check_indices("edge indices", edges, surface.positions.len())?;
        let segments: Vec<[Vec3; 2]> = edges
            .chunks_exact(2)
            .map(|e| {
                [
                    surface.positions[e[0] as usize],
                    surface.positions[e[1] as usize],
                ]
            })
            .collect();
        let colors = colors_for("edge colours", rgba, segments.len())?;
        Ok(LineSet { segments, colors })
    }
}

/// Tangent glyphs (a cross field's two arms, the principal directions) at
/// sites on the surface, drawn at screen density: at most one glyph per
/// square cell of the screen, so they stay legible at any zoom.
///
/// The sites are the field mesh's vertices and, where one of its triangles
/// is too big on screen for the spacing, points of a barycentric lattice on
/// it with the field interpolated from the corners (see
/// [`GlyphSet::face_glyph`]). A lattice has 2^k subdivisions, so its points
/// stay where they are on the surface while zooming in only adds more.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GlyphSet {
    pub centres: Vec<Vec3>,
    /// `per_site` arms per site (unit directions), site after site.
    pub arms: Vec<Vec3>,
    /// One colour per arm.
    pub colors: Vec<[u8; 4]>,
    pub per_site: usize,
    /// The field mesh's triangles over the sites (may be empty: then the
    /// vertices are the only sites).
    pub faces: Vec<[u32; 3]>,
}

/// The most subdivisions of a triangle's edges: a triangle more than
/// `MAX_LATTICE / 2` glyph spacings across on screen gets sparser glyphs.
pub const MAX_LATTICE: u32 = 256;

/// A glyph's site: a vertex, or a barycentric point of a face.
#[derive(Debug, Clone, Copy)]
enum Site {
    Vertex(usize),
    Face(usize, [f32; 3]),
}

impl GlyphSet {
    /// From centred segments (six floats each), `per_site` consecutive
    /// ones making one glyph; one colour for all or one per segment; the
    /// field mesh's triangles as site index triples (or none).
    pub fn from_segments(
        segments: &[f32],
        rgba: &[u8],
        per_site: usize,
        triangles: &[u32],
    ) -> Result<GlyphSet, SceneError> {
        let lines = LineSet::from_segments(segments, rgba)?;
        let per_site = per_site.max(1);
        if lines.segments.len() % per_site != 0 {
            return Err(SceneError::Length {
                what: "glyph segments",
                len: lines.segments.len(),
                multiple: per_site,
            });
        }
        let centres: Vec<Vec3> = lines
            .segments
            .chunks_exact(per_site)
            .map(|g| (g[0][0] + g[0][1]) * 0.5)
            .collect();
        if triangles.len() % 3 != 0 {
            return Err(SceneError::Length {
                what: "glyph triangles",
                len: triangles.len(),
                multiple: 3,
            });
        }
        check_indices("glyph triangles", triangles, centres.len())?;
        let arms = lines
            .segments
            .iter()
            .map(|[a, b]| (*b - *a).normalize_or_zero())
            .collect();
        Ok(GlyphSet {
            centres,
            arms,
            colors: lines.colors,
            per_site,
            faces: triangles
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
        })
    }

    /// A site's side of the surface: its first two arms' cross product
    /// (`None` for glyphs of one arm, which are seen from both sides).
    fn normal(&self, site: usize) -> Option<Vec3> {
        let k = site * self.per_site;
        (self.per_site >= 2).then(|| self.arms[k].cross(self.arms[k + 1]))
    }

    /// The glyph at barycentric point `l` of face `f`: its position and
    /// arms with their colours. Each arm of the corner with the largest
    /// weight is matched, up to sign, to the most parallel arm of the same
    /// colour at every corner (so a cross field's arms may trade places
    /// from corner to corner while d1 stays d1), the matched arms are
    /// blended with the weights and put back into the tangent plane of the
    /// blended normal.
    fn face_glyph(&self, f: usize, l: [f32; 3]) -> (Vec3, Vec<(Vec3, [u8; 4])>) {
        let corners = self.faces[f].map(|v| v as usize);
        let centre = (0..3).map(|j| self.centres[corners[j]] * l[j]).sum();
        let r = (0..3).fold(0, |r, j| if l[j] > l[r] { j } else { r });
        let normal = (self.per_site >= 2).then(|| {
            (0..3)
                .filter_map(|j| self.normal(corners[j]).map(|n| n * l[j]))
                .sum::<Vec3>()
                .normalize_or_zero()
        });
        let arms = (0..self.per_site)
            .map(|k| {
                let reference = self.arms[corners[r] * self.per_site + k];
                let colour = self.colors[corners[r] * self.per_site + k];
                let mut sum = Vec3::ZERO;
                for j in 0..3 {
                    let own = corners[j] * self.per_site..(corners[j] + 1) * self.per_site;
                    let matched = own
                        .filter(|&m| self.colors[m] == colour)
                        .map(|m| self.arms[m])
                        .max_by(|a, b| a.dot(reference).abs().total_cmp(&b.dot(reference).abs()))
                        .unwrap_or(reference);
                    let sign = if matched.dot(reference) < 0.0 {
                        -1.0
                    } else {
                        1.0
                    };
                    sum += matched * (sign * l[j]);
                }
                if let Some(n) = normal {
                    sum -= n * n.dot(sum);
                }
                let arm = sum.normalize_or_zero();
                (if arm == Vec3::ZERO { reference } else { arm }, colour)
            })
            .collect();
        (centre, arms)
    }

    /// The glyphs seen through `view_proj` from `eye` on a `width` ×
    /// `height` pixel target: per cell of `spacing` pixels the site nearest
    /// the cell's centre that is in view and faces the eye (the first two
    /// arms' cross product, blended on faces; glyphs of one arm always do),
    /// each arm scaled to 0.4 `spacing` pixels either side (`fov_y` gives
    /// pixels per world unit at a site's view depth). A face gets lattice
    /// sites when its longest edge on screen is more than half the spacing,
    /// at most half a spacing apart. Returns the segments and how many
    /// glyphs.
    pub fn thin(
        &self,
        view_proj: glam::Mat4,
        eye: Vec3,
        fov_y: f32,
        (width, height): (f32, f32),
        spacing: f32,
    ) -> (LineSet, usize) {
        use std::collections::HashMap;
        let spacing = spacing.max(1.0);
        let clips: Vec<glam::Vec4> = self
            .centres
            .iter()
            .map(|c| view_proj * c.extend(1.0))
            .collect();
        // Pixel position of a clip-space point in front of the eye.
        let pixel = |clip: glam::Vec4| {
            (clip.w > 1e-6).then(|| {
                let ndc = clip.truncate() / clip.w;
                (
                    glam::Vec2::new((ndc.x + 1.0) * 0.5 * width, (1.0 - ndc.y) * 0.5 * height),
                    ndc.z,
                )
            })
        };
        // Per cell: site, squared distance to the cell centre, view depth.
        let mut best: HashMap<(i32, i32), (Site, f32, f32)> = HashMap::new();
        let mut offer = |site: Site, clip: glam::Vec4| {
            let Some((p, z)) = pixel(clip) else { return };
            if !(0.0..width).contains(&p.x)
                || !(0.0..height).contains(&p.y)
                || !(0.0..=1.0).contains(&z)
            {
                return;
            }
            let cell = (
                (p.x / spacing).floor() as i32,
                (p.y / spacing).floor() as i32,
            );
            let centre = (glam::Vec2::new(cell.0 as f32, cell.1 as f32) + 0.5) * spacing;
            let d = p.distance_squared(centre);
            let slot = best.entry(cell).or_insert((site, d, clip.w));
            if d < slot.1 {
                *slot = (site, d, clip.w);
            }
        };
        let faces_eye = |n: Option<Vec3>, at: Vec3| n.is_none_or(|n| n.dot(eye - at) > 0.0);
        for (i, &c) in self.centres.iter().enumerate() {
            if faces_eye(self.normal(i), c) {
                offer(Site::Vertex(i), clips[i]);
            }
        }
        let (w, h) = (width, height);
        for (f, face) in self.faces.iter().enumerate() {
            let v = face.map(|v| v as usize);
            let Some(px) = v
                .iter()
                .map(|&v| pixel(clips[v]).map(|p| p.0))
                .collect::<Option<Vec<_>>>()
            else {
                continue;
            };
            let (lo, hi) = (px[0].min(px[1]).min(px[2]), px[0].max(px[1]).max(px[2]));
            if hi.x < 0.0 || hi.y < 0.0 || lo.x >= w || lo.y >= h {
                continue;
            }
            if v.iter()
                .all(|&v| !faces_eye(self.normal(v), self.centres[v]))
            {
                continue;
            }
            let longest = px[0]
                .distance(px[1])
                .max(px[1].distance(px[2]))
                .max(px[2].distance(px[0]));
            let n = (2.0 * longest / spacing).ceil().min(MAX_LATTICE as f32) as u32;
            if n < 2 {
                continue;
            }
            let n = n.next_power_of_two().min(MAX_LATTICE);
            let normals = v.map(|v| self.normal(v));
            for i in 0..=n {
                for j in 0..=n - i {
                    let k = n - i - j;
                    if i == n || j == n || k == n {
                        continue; // a vertex
                    }
                    let l = [i as f32, j as f32, k as f32].map(|x| x / n as f32);
                    let at: Vec3 = (0..3).map(|m| self.centres[v[m]] * l[m]).sum();
                    let normal = normals[0].map(|_| {
                        (0..3)
                            .filter_map(|m| normals[m].map(|n| n * l[m]))
                            .sum::<Vec3>()
                    });
                    if faces_eye(normal, at) {
                        let clip = (0..3).map(|m| clips[v[m]] * l[m]).sum();
                        offer(Site::Face(f, l), clip);
                    }
                }
            }
        }
        let mut kept: Vec<(Site, f32)> = best.into_values().map(|(s, _, w)| (s, w)).collect();
        kept.sort_unstable_by_key(|k| match k.0 {
            Site::Vertex(i) => (0, i, [0; 3]),
            Site::Face(f, l) => (1, f, l.map(f32::to_bits)),
        });
        let world_per_px = 2.0 * (fov_y * 0.5).tan() / height.max(1.0);
        let mut lines = LineSet::default();
        for &(site, depth) in &kept {
            // Pixels per world unit go with the view depth (clip w).
            let half = 0.4 * spacing * world_per_px * depth;
            let (c, arms) = match site {
                Site::Vertex(i) => (
                    self.centres[i],
                    (i * self.per_site..(i + 1) * self.per_site)
                        .map(|k| (self.arms[k], self.colors[k]))
                        .collect(),
                ),
                Site::Face(f, l) => self.face_glyph(f, l),
            };
            for (arm, colour) in arms {
                let d = arm * half;
                lines.segments.push([c - d, c + d]);
                lines.colors.push(colour);
            }
        }
        (lines, kept.len())
    }
}

/// Round markers of one pixel size, one colour each.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointSet {
    pub points: Vec<Vec3>,
    pub colors: Vec<[u8; 4]>,
    pub size_px: f32,
}

impl PointSet {
    pub fn new(positions: &[f32], rgba: &[u8], size_px: f32) -> Result<PointSet, SceneError> {
        let points = vec3s("points", positions)?;
        let colors = colors_for("point colours", rgba, points.len())?;
        let size_px = if size_px.is_finite() && size_px > 0.0 {
            size_px
        } else {
            8.0
        };
        Ok(PointSet {
            points,
            colors,
            size_px,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Surface {
        Surface::new(
            &[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.],
            &[0, 1, 2, 0, 2, 3],
            &[0., 0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1.],
        )
        .unwrap()
    }

    #[test]
    fn rejects_bad_input_without_panicking() {
        assert!(matches!(
            Surface::new(&[0.0; 4], &[], &[0.0; 4]),
            Err(SceneError::Length { .. })
        ));
        assert!(matches!(
            Surface::new(&[0.0; 9], &[0, 1, 3], &[0.0; 9]),
            Err(SceneError::Index { index: 3, .. })
        ));
        assert!(matches!(
            Surface::new(&[f32::NAN, 0., 0.], &[], &[0.0; 3]),
            Err(SceneError::NonFinite { .. })
        ));
        assert!(Scalar::new("k", &[1.0], 4, 0.0, 1.0, "viridis").is_err());
        assert!(Scalar::new("k", &[1.0; 4], 4, 0.0, 1.0, "jet").is_err());
        assert!(LineSet::from_edges(&square(), &[0, 9], &[0, 0, 0, 255]).is_err());
        assert!(PointSet::new(&[0.0; 6], &[1, 2, 3], 5.0).is_err());
        assert!(matches!(
            uv_pairs(&[0.0; 5], 3),
            Err(SceneError::Count { .. })
        ));
        assert!(matches!(
            uv_pairs(&[0.0, f32::INFINITY], 1),
            Err(SceneError::NonFinite { index: 1, .. })
        ));
        assert_eq!(uv_pairs(&[1.0, 2.0], 1), Ok(vec![[1.0, 2.0]]));
        assert!(vertex_colors(&[1, 2, 3], 1).is_err());
        assert_eq!(vertex_colors(&[1, 2, 3, 4], 1), Ok(vec![[1, 2, 3, 4]]));
    }

    #[test]
    fn pick_finds_the_nearest_hit_and_corner() {
        let s = square();
        let hit = s.pick(Vec3::new(0.9, 0.2, 5.0), Vec3::NEG_Z).unwrap();
        assert!((hit.point - Vec3::new(0.9, 0.2, 0.0)).length() < 1e-5);
        assert_eq!(hit.triangle, 0);
        assert_eq!(hit.vertex, 1);
        assert!(s.pick(Vec3::new(2.0, 2.0, 5.0), Vec3::NEG_Z).is_none());
        assert!(
            s.pick(Vec3::new(0.5, 0.5, 5.0), Vec3::Z).is_none(),
            "behind the origin"
        );
    }

    #[test]
    fn scalar_range_and_colors() {
        let s = Scalar::new("k", &[0.0, 1.0, 2.0, f32::NAN], 4, f32::NAN, 0.0, "viridis").unwrap();
        assert_eq!((s.min, s.max), (0.0, 2.0));
        let c = s.colors();
        assert_eq!(c[0][..3], Colormap::Viridis.sample(0.0));
        assert_eq!(c[2][..3], Colormap::Viridis.sample(1.0));
    }

    #[test]
    fn edges_become_segments() {
        let l = LineSet::from_edges(&square(), &[0, 1, 1, 2], &[9, 9, 9, 255]).unwrap();
        assert_eq!(l.segments.len(), 2);
        assert_eq!(l.segments[1], [Vec3::X, Vec3::new(1.0, 1.0, 0.0)]);
        assert_eq!(l.colors, vec![[9, 9, 9, 255]; 2]);
    }

    /// A closed cube of 12 triangles with 8 shared corners (the unit cube
    /// of `mesh::generate`, each quad fanned from its first corner).
    fn cube() -> Surface {
        let (positions, quads) = crate::mesh::generate::unit_cube_quads();
        let p: Vec<f32> = positions
            .iter()
            .flat_map(|v| [v.x as f32, v.y as f32, v.z as f32])
            .collect();
        let t: Vec<u32> = quads
            .iter()
            .flat_map(|q| [q[0], q[1], q[2], q[0], q[2], q[3]])
            .collect();
        Surface::new(&p, &t, &[0.0; 24]).unwrap()
    }

    #[test]
    fn creases_split_the_smooth_normals() {
        let c = cube();
        let d = c.split_at_creases(CREASE_DEGREES);
        // Three faces meet at each corner: 24 drawn vertices, each with its face's axis normal.
        assert_eq!(d.source.len(), 24);
        for (t, tri) in d.triangles.iter().enumerate() {
            let [a, b, e] = c.triangles[t].map(|v| c.positions[v as usize]);
            let face = (b - a).cross(e - a).normalize();
            for &v in tri {
                assert!(
                    (d.normals[v as usize] - face).length() < 1e-5,
                    "{:?} vs {face:?}",
                    d.normals[v as usize]
                );
            }
        }
        // 180°: nothing is sharp; one normal per corner, the diagonal of the cube.
        let s = c.split_at_creases(180.0);
        assert_eq!(s.source.len(), 8);
        for (v, n) in s.normals.iter().enumerate() {
            let out = (c.positions[s.source[v] as usize] - Vec3::splat(0.5)).normalize();
            assert!(n.dot(out) > 0.99, "{n:?} vs {out:?}");
        }
        assert_eq!(d.expand(&[7u8; 8]).unwrap(), vec![7u8; 24]);
    }

    #[test]
    fn a_flat_square_and_welded_copies_stay_one_fan() {
        let d = square().split_at_creases(CREASE_DEGREES);
        assert_eq!(d.source.len(), 4);
        assert!(d.normals.iter().all(|n| (*n - Vec3::Z).length() < 1e-6));
        // The same two triangles with their own corners (a result surface):
        // the shared corners keep their own vertices but one normal.
        let p = [
            0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 0., 0., 1., 1., 0., 0., 1., 0.2,
        ];
        let s = Surface::new(&p, &[0, 1, 2, 3, 4, 5], &[0.0; 18]).unwrap();
        let d = s.split_at_creases(CREASE_DEGREES);
        assert_eq!(d.source, vec![0, 1, 2, 3, 4, 5]);
        assert!(
            (d.normals[0] - d.normals[3]).length() < 1e-6,
            "welded corner 0/3 share a fan"
        );
        assert!(
            (d.normals[2] - d.normals[4]).length() < 1e-6,
            "welded corner 2/4 share a fan"
        );
        assert!((d.normals[1] - Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn glyphs_thin_to_one_per_screen_cell() {
        // A 200 × 200 grid of crosses on the plane z = 0, seen from +z.
        let mut seg = Vec::new();
        for i in 0..200 {
            for j in 0..200 {
                let c = Vec3::new(i as f32 / 100.0 - 1.0, j as f32 / 100.0 - 1.0, 0.0);
                for d in [Vec3::X, Vec3::Y] {
                    seg.extend((c - d * 0.001).to_array());
                    seg.extend((c + d * 0.001).to_array());
                }
            }
        }
        let g = GlyphSet::from_segments(&seg, &[1, 2, 3, 255], 2, &[]).unwrap();
        assert_eq!(g.centres.len(), 40000);
        let mut cam = super::super::camera::OrbitCamera {
            aspect: 1.0,
            ..Default::default()
        };
        cam.fit(Vec3::ZERO, 1.0);
        cam.yaw = 0.0;
        cam.pitch = 0.0;
        let count = |cam: &super::super::camera::OrbitCamera, spacing: f32| {
            g.thin(
                cam.view_proj(),
                cam.eye(),
                cam.fov_y,
                (400.0, 400.0),
                spacing,
            )
            .1
        };
        let near = {
            let mut c = cam.clone();
            c.distance *= 0.5;
            c
        };
        let far = {
            let mut c = cam.clone();
            c.distance *= 2.0;
            c
        };
        // The plane covers the view up close: one glyph per 20-pixel cell.
        assert_eq!(count(&near, 20.0), 400);
        // Farther, the same cells over a smaller picture; doubling the spacing quarters them.
        let (a, b) = (count(&cam, 20.0), count(&cam, 40.0));
        assert!((3.0..5.0).contains(&(a as f32 / b as f32)), "{a} vs {b}");
        assert!(count(&far, 20.0) < a);
        // Seen from behind (−z), every glyph faces away.
        let mut back = cam.clone();
        back.yaw = std::f32::consts::PI;
        assert_eq!(count(&back, 20.0), 0);
        // Arms span 0.4 spacing either side on screen.
        let (lines, n) = g.thin(
            near.view_proj(),
            near.eye(),
            near.fov_y,
            (400.0, 400.0),
            20.0,
        );
        assert_eq!(lines.segments.len(), 2 * n);
        let [p, q] = lines.segments[0];
        let px = |v: Vec3| {
            let c = near.view_proj() * v.extend(1.0);
            c.truncate().truncate() / c.w * 200.0
        };
        assert!(
            ((px(q) - px(p)).length() - 16.0).abs() < 0.5,
            "{}",
            (px(q) - px(p)).length()
        );
    }

    #[test]
    fn big_faces_get_glyphs_between_their_vertices() {
        // One square of two triangles, z = 0, with a cross at each corner;
        // the corners list the same cross with their arms in another order
        // or sign, as a 4-symmetric field may.
        let corners = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
        ];
        let crosses = [
            [Vec3::X, Vec3::Y],
            [Vec3::Y, -Vec3::X],
            [-Vec3::X, -Vec3::Y],
            [-Vec3::Y, Vec3::X],
        ];
        let mut seg = Vec::new();
        for (c, arms) in corners.iter().zip(crosses) {
            for d in arms {
                seg.extend((*c - d * 0.01).to_array());
                seg.extend((*c + d * 0.01).to_array());
            }
        }
        let triangles = [0, 1, 2, 0, 2, 3];
        let g = GlyphSet::from_segments(&seg, &[9, 9, 9, 255], 2, &triangles).unwrap();
        let vertices_only = GlyphSet::from_segments(&seg, &[9, 9, 9, 255], 2, &[]).unwrap();
        let mut cam = super::super::camera::OrbitCamera {
            aspect: 1.0,
            ..Default::default()
        };
        cam.fit(Vec3::ZERO, 1.0);
        cam.yaw = 0.0;
        cam.pitch = 0.0;
        cam.distance *= 0.5;
        let thin =
            |g: &GlyphSet| g.thin(cam.view_proj(), cam.eye(), cam.fov_y, (400.0, 400.0), 20.0);
        // The square fills the view: one glyph in each of the 400 cells,
        // where its four vertices (all off screen) give none.
        assert_eq!(thin(&vertices_only).1, 0);
        let (lines, n) = thin(&g);
        assert_eq!(n, 400);
        // Every interpolated glyph is the same axis-aligned cross.
        for pair in lines.segments.chunks_exact(2) {
            let a = (pair[0][1] - pair[0][0]).normalize();
            let b = (pair[1][1] - pair[1][0]).normalize();
            assert!(a.x.abs().max(a.y.abs()) > 0.999 && a.z.abs() < 1e-4, "{a}");
            assert!(a.dot(b).abs() < 1e-3, "{a} {b}");
        }
        // Glyph centres sit near their cells' centres (lattice half a
        // spacing apart at most).
        let px = |v: Vec3| {
            let c = cam.view_proj() * v.extend(1.0);
            let ndc = c.truncate() / c.w;
            glam::Vec2::new((ndc.x + 1.0) * 200.0, (1.0 - ndc.y) * 200.0)
        };
        for pair in lines.segments.chunks_exact(2) {
            let p = px((pair[0][0] + pair[0][1]) * 0.5);
            let cell = (p / 20.0).floor() * 20.0 + glam::Vec2::splat(10.0);
            assert!(p.distance(cell) < 10.0, "{p} in the cell at {cell}");
        }
        // Seen from behind, nothing faces the eye.
        let mut back = cam.clone();
        back.yaw = std::f32::consts::PI;
        assert_eq!(
            g.thin(
                back.view_proj(),
                back.eye(),
                back.fov_y,
                (400.0, 400.0),
                20.0
            )
            .1,
            0
        );
        // Far away the square is small: its vertices are the only sites.
        let mut far = cam.clone();
        far.distance *= 40.0;
        let (_, n) = g.thin(far.view_proj(), far.eye(), far.fov_y, (400.0, 400.0), 20.0);
        assert!(n <= 4, "{n}");
    }

    #[test]
    fn principal_directions_keep_their_colours_between_vertices() {
        // d1 (red) along x, d2 (blue) along y at three corners, but listed
        // d2 first at one of them: matching by colour keeps d1 red.
        let corners = [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let red = [200, 0, 0, 255];
        let blue = [0, 0, 200, 255];
        let mut seg = Vec::new();
        let mut rgba = Vec::new();
        for (i, c) in corners.iter().enumerate() {
            let arms = if i == 1 {
                [(Vec3::Y, blue), (-Vec3::X, red)]
            } else {
                [(Vec3::X, red), (Vec3::Y, blue)]
            };
            for (d, colour) in arms {
                seg.extend((*c - d * 0.01).to_array());
                seg.extend((*c + d * 0.01).to_array());
                rgba.extend(colour);
            }
        }
        let g = GlyphSet::from_segments(&seg, &rgba, 2, &[0, 1, 2]).unwrap();
        let (glyph, arms) = g.face_glyph(0, [0.2, 0.6, 0.2]);
        assert!((glyph - Vec3::new(0.4, -0.6, 0.0)).length() < 1e-6);
        // The largest weight is corner 1's, d2 first there.
        assert_eq!(arms[0].1, blue);
        assert!(arms[0].0.y.abs() > 0.999, "{}", arms[0].0);
        assert_eq!(arms[1].1, red);
        assert!(arms[1].0.x.abs() > 0.999, "{}", arms[1].0);
        // Bad triangles are errors, not panics.
        assert!(matches!(
            GlyphSet::from_segments(&seg, &rgba, 2, &[0, 1, 3]),
            Err(SceneError::Index { .. })
        ));
        assert!(matches!(
            GlyphSet::from_segments(&seg, &rgba, 2, &[0, 1]),
            Err(SceneError::Length { .. })
        ));
    }
}
