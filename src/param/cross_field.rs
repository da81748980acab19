//! The per-face cross field in the filtered tangent planes: Ebke et al.
//! 2014, *Level-of-Detail Quad Meshing* (`../shared/seeds/000_…`), §4
//! (angle representation of Li et al. 2006 with the hinge axis
//! `ê_ij = n̂_i × n̂_j`, transition angles κ_ij, integer period jumps p_ij,
//! E_smooth of eq. (1) with uniform weights, alignment constraints projected
//! into the filtered planes, §4.3) and §4.5 (singularity indices with the
//! Gaussian curvature of the filtered normals' spherical polygons).
//!
//! Sign conventions: angles are counter-clockwise about n̂ from the face's
//! reference direction d_f; κ_ij = ∠_j(ê) − ∠_i(ê), so that a direction at
//! angle α in face i is at α + κ_ij in face j after the hinge map and
//! γ_ij = θ_i + κ_ij + (π/2)·p_ij − θ_j is the deviation of eq. (1). Around
//! an interior vertex, counter-clockwise, the index is
//! I(v) = (K(v) − Σκ)/(2π) − (1/4)·Σp (Ebke's formula with the edges
//! oriented the other way round).
//!
//! Deviations (the mixed-integer solve): instead of Bommes et al. 2009's
//! greedy rounding of one period jump at a time, (1) the convex relaxation
//! in the 4th-power representation z_f = e^{4iθ_f} (Knöppel et al. 2013's
//! smoothest field; inverse iteration where no face is constrained) gives
//! the θ, followed by a few unit-length (MBO) diffusion steps that
//! separate clustered zeros; (2) all p_ij are rounded at once to minimise each γ_ij; (3) θ is
//! re-solved exactly for E_smooth with those p (a sparse Laplacian); (2)–(3)
//! repeat (each step lowers E_smooth). Soft alignment constraints (the
//! smooth regions' a_min by default, see `Params::region_cross_weight`)
//! add w·A(f)·|z_f − z_target|² to the relaxation and w·A(f)·(θ_f −
//! θ_target − k_f·π/2)² to step (3), k_f rounded with the p in step (2):
//! a finite instead of Campen §4.1's ∞ weight. Faces on the boundary are aligned
//! with their boundary edge (MIQ's boundary alignment), so boundaries can
//! become integer isolines; so are faces on feature curves, and at every
//! vertex of the curves the period jumps of each sector between two
//! curves are rounded with the sum that makes the sector k·90° (k from
//! its surface angle), so corners get the cone their angles ask for,
//! at the corner vertex (MIQ §4–5's feature constraints; see
//! `corner_sectors`). Optionally, cones the rounding leaves less than a
//! given distance off the curves move onto their nearest curve vertex
//! (that vertex's sectors get the cone's quarter turns and the period
//! jumps are rounded again, `snap_cones`; `Params::feature_cone_snap`).

// Parallel per-face arrays read best indexed.
#![allow(clippy::needless_range_loop)]

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use faer::c64;
use glam::{DVec2, DVec3};

use super::solve::{NormalEquations, SpdFactor, SpdPattern};
use super::topology::{EdgeTopology, Fan};
use crate::mesh::{TriMesh, UnionFind};

/// Rounds of period-jump rounding and θ re-solve.
const ROUNDS: usize = 3;
/// Inverse-iteration steps of the unconstrained relaxation.
const INVERSE_ITERATIONS: usize = 30;
/// λ (against unit mean mass and dual weights) and steps of the unit-length iterations.
const UNIT_LAMBDA: f64 = 0.1;
const UNIT_STEPS: usize = 30;

/// What the cross field is computed from.
pub struct CrossFieldInput<'a> {
    pub mesh: &'a TriMesh,
    pub topology: &'a EdgeTopology,
    pub fans: &'a [Option<Fan>],
    /// Unit filtered normal per face (the face normals without filtering).
    pub normals: &'a [DVec3],
    /// Per face: a direction the cross must contain (projected into the
    /// filtered plane), or None.
    pub constraints: &'a [Option<DVec3>],
    /// Per face: a direction the cross should contain, a penalty
    /// `soft_weight · A(f) · (θ_f − θ_target)²` (modulo quarter turns) next
    /// to E_smooth instead of a fixed angle; faces with a hard constraint
    /// ignore it (empty: none).
    pub soft_constraints: &'a [Option<DVec3>],
    /// The soft constraints' weight against E_smooth's unit edge weights
    /// (areas normalised to mean 1).
    pub soft_weight: f64,
    /// Per face edge: on a feature curve (empty: none). At every interior
    /// vertex with two or more feature edges, the period jumps of each
    /// sector between consecutive feature edges make the sector k·90° in
    /// the map, k = max(1, round(sector angle / 90°)), so that the vertex
    /// gets the index 1 − Σk/4 ([`corner_sectors`]). Their faces should
    /// be constrained to the feature edges.
    pub feature_edges: &'a [[bool; 3]],
    /// S(f), the target edge length per face, and the distance in target
    /// edges below which a cone off the feature curves moves onto the
    /// nearest vertex of them (`snap_cones`; empty or 0: none moves).
    pub face_sizing: &'a [f64],
    pub snap_distance: f64,
    /// ln S per vertex, the sizing's log target edge (empty: one S
    /// everywhere). The field is smoothest in the sizing's metric S^{−2}g:
    /// see [`sizing_transport`].
    pub log_size: &'a [f64],
}

/// A cone: an interior vertex with nonzero index.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct Cone {
    pub vertex: u32,
    /// The index in quarter turns (+1: valence 3, −1: valence 5).
    pub quarters: i32,
}

impl Cone {
    pub fn index(&self) -> f64 {
        self.quarters as f64 / 4.0
    }
}

/// The cross field: per face an angle θ against the reference direction,
/// per interior edge the transition angle and the period jump.
#[derive(Debug, Clone, PartialEq)]
pub struct CrossField {
    /// The planes the crosses live in (unit filtered normals).
    pub normals: Vec<DVec3>,
    /// Per face: unit reference direction d_f ⊥ n̂_f.
    pub reference: Vec<DVec3>,
    pub theta: Vec<f64>,
    /// Per face and local edge: κ to the face across (0 on the boundary).
    pub kappa: Vec<[f64; 3]>,
    /// Per face and local edge: p to the face across (0 on the boundary).
    pub period_jump: Vec<[i32; 3]>,
    pub constrained: Vec<bool>,
    pub cones: Vec<Cone>,
    /// E_smooth = Σ γ² over interior edges.
    pub energy: f64,
    /// Largest distance of 4·I(v) from an integer before rounding (a
    /// consistency check of K against the κ: ≈ 0).
    pub index_residual: f64,
}

impl CrossField {
    /// The direction of arm 0 in face f (unit, in the filtered plane).
    pub fn arm(&self, f: usize, quarter_turns: i32) -> DVec3 {
        let a = self.theta[f] + FRAC_PI_2 * quarter_turns as f64;
        let (d, n) = (self.reference[f], self.normals[f]);
        d * a.cos() + n.cross(d) * a.sin()
    }

    pub fn index_sum(&self) -> f64 {
        self.cones.iter().map(Cone::index).sum()
    }
}

/// Signed angle of `x` about `n` from `d` (x need not be in the plane).
fn angle_from(d: DVec3, n: DVec3, x: DVec3) -> f64 {
    x.dot(n.cross(d)).atan2(x.dot(d))
}

fn wrap(a: f64) -> f64 {
    a - TAU * ((a + PI) / TAU).floor()
}

fn reference_directions(mesh: &TriMesh, normals: &[DVec3]) -> Vec<DVec3> {
    (0..mesh.triangles.len())
        .map(|f| {
            let [a, b, _] = mesh.corners(f);
            let n = normals[f];
            (b - a)
                .reject_from_normalized(n)
                .try_normalize()
                .unwrap_or_else(|| n.any_orthonormal_vector())
        })
        .collect()
}

/// κ per face-edge (antisymmetric across each interior edge).
fn transition_angles(input: &CrossFieldInput<'_>, reference: &[DVec3]) -> Vec<[f64; 3]> {
    let (mesh, top, n) = (input.mesh, input.topology, input.normals);
    let mut kappa = vec![[0.0; 3]; mesh.triangles.len()];
    for f in 0..mesh.triangles.len() {
        for e in 0..3 {
            let Some((g, ge)) = top.across(f, e) else {
                continue;
            };
            if g < f {
                continue;
            }
            let hinge = n[f].cross(n[g]);
            let hinge = if hinge.length() > 1e-9 {
                hinge
            } else {
                let t = mesh.triangles[f];
                mesh.positions[t[(e + 1) % 3] as usize] - mesh.positions[t[e] as usize]
            };
            let k =
                wrap(angle_from(reference[g], n[g], hinge) - angle_from(reference[f], n[f], hinge));
            kappa[f][e] = k;
            kappa[g][ge] = -k;
        }
    }
    kappa
}

/// The sizing's turn of the transport across each interior edge (None
/// when ln S is constant or absent).
///
/// A map whose unit is S(x) and whose isolines follow the cross at θ is
/// conformal exactly when ln S + iθ is holomorphic (its derivative is
/// e^{−ln S − iθ} in a local frame), i.e. ∇θ = J∇ln S (Cauchy–Riemann; J
/// the quarter turn about n̂). Across the edge a → b of face f (counter-
/// clockwise in f) the dual edge runs ⊥ to it, to the right, so the cross
/// turns by −(ln S_b − ln S_a) · |dual| / |edge| = −w_ab (ln S_b − ln S_a),
/// w the cotangent weight of [`super::conformal::half_cotangents`]. Around
/// a vertex these sum to −(L ln S)(v): the transport is the Levi-Civita
/// one of S^{−2}g, whose curvature is K − L ln S, so the field's cones
/// gather where the sizing changes (a cone pair where the size steps
/// down) and [`super::conformal::cone_metric_factor`] gets the sizing it
/// is asked for instead of shearing the map into it. The cones' indices
/// are those of the true transport (the κ without this turn), whose
/// holonomy differs from the sizing metric's by exactly this sum.
fn sizing_transport(input: &CrossFieldInput<'_>) -> Option<Vec<[f64; 3]>> {
    let (mesh, top, ln_s) = (input.mesh, input.topology, input.log_size);
    if ln_s.len() != mesh.positions.len() || ln_s.iter().all(|&x| x == ln_s[0]) {
        return None;
    }
    let h = super::conformal::half_cotangents(mesh);
    let mut turn = vec![[0.0; 3]; mesh.triangles.len()];
    for (f, t) in mesh.triangles.iter().enumerate() {
        for e in 0..3 {
            if let Some((g, ge)) = top.across(f, e) {
                let (a, b) = (t[e] as usize, t[(e + 1) % 3] as usize);
                turn[f][e] = -(h[f][e] + h[g][ge]) * (ln_s[b] - ln_s[a]);
            }
        }
    }
    Some(turn)
}

/// Dual-edge weights |e| / |c_f − c_g| (normalised to mean 1) and face
/// areas (normalised to mean 1).
fn dual_weights(mesh: &TriMesh, topology: &EdgeTopology) -> (Vec<[f64; 3]>, Vec<f64>) {
    let nf = mesh.triangles.len();
    let centroid = |f: usize| {
        let [a, b, c] = mesh.corners(f);
        (a + b + c) / 3.0
    };
    let mut weight = vec![[0.0; 3]; nf];
    let (mut sum, mut count) = (0.0, 0usize);
    for f in 0..nf {
        let t = mesh.triangles[f];
        for e in 0..3 {
            if let Some((g, _)) = topology.across(f, e) {
                let len =
                    mesh.positions[t[e] as usize].distance(mesh.positions[t[(e + 1) % 3] as usize]);
                let w = len
                    / centroid(f)
                        .distance(centroid(g))
                        .max(1e-12 * len.max(1e-300));
                let w = if w.is_finite() {
                    w.clamp(1e-3, 1e3)
                } else {
                    1.0
                };
                weight[f][e] = w;
                sum += w;
                count += 1;
            }
        }
    }
    let mean = if count > 0 { sum / count as f64 } else { 1.0 };
    for w in weight.iter_mut().flatten() {
        *w /= mean;
    }
    let area: Vec<f64> = (0..nf).map(|f| mesh.face_area(f)).collect();
    let mean_area = (area.iter().sum::<f64>() / nf.max(1) as f64).max(1e-300);
    let mass = area.iter().map(|a| (a / mean_area).max(1e-6)).collect();
    (weight, mass)
}

/// Face components of the dual graph (connected across interior edges).
pub(crate) fn face_components(topology: &EdgeTopology) -> Vec<u32> {
    let nf = topology.face_count();
    let mut uf = UnionFind::new(nf);
    for f in 0..nf {
        for e in 0..3 {
            if let Some((g, _)) = topology.across(f, e) {
                uf.union(f as u32, g as u32);
            }
        }
    }
    (0..nf as u32).map(|f| uf.find(f)).collect()
}

struct Relaxation<'a> {
    topology: &'a EdgeTopology,
    kappa: &'a [[f64; 3]],
    /// Fixed θ per face.
    fixed: &'a [Option<f64>],
    /// Soft target angle per face (None where fixed or unconstrained).
    soft: &'a [Option<f64>],
    soft_weight: f64,
    components: &'a [u32],
    /// Per face-edge: the relaxation's dual-edge weight |e| / |c_f − c_g|.
    weight: &'a [[f64; 3]],
    /// Per face: area (the relaxation's mass).
    mass: &'a [f64],
}

/// The relaxation's Hermitian system over the free faces' z (one complex
/// unknown per face, `var[f]` is `usize::MAX` for fixed faces): the
/// connection Laplacian of Σ w_ij |r_ij z_i − z_j|² with r_ij = e^{4iκ_ij}
/// (Knöppel et al. 2013), the fixed faces' terms on the right-hand side.
/// Lower-triangle triplets, right-hand side, `var`, unknowns.
type Hermitian = (Vec<(usize, usize, c64)>, Vec<c64>, Vec<usize>, usize);

fn relaxation_system(r: &Relaxation<'_>) -> Hermitian {
    let nf = r.fixed.len();
    let mut var = vec![usize::MAX; nf];
    let mut n = 0;
    for f in 0..nf {
        if r.fixed[f].is_none() {
            var[f] = n;
            n += 1;
        }
    }
    let z_fixed = |f: usize| {
        r.fixed[f].map(|t| {
            let z = DVec2::from_angle(4.0 * t);
            c64::new(z.x, z.y)
        })
    };
    let mut triplets = Vec::new();
    let mut rhs = vec![c64::new(0.0, 0.0); n];
    let mut degree = vec![0.0f64; nf];
    for f in 0..nf {
        for e in 0..3 {
            let Some((g, _)) = r.topology.across(f, e) else {
                continue;
            };
            if g < f {
                continue;
            }
            degree[f] += 1.0;
            degree[g] += 1.0;
            let rot = DVec2::from_angle(4.0 * r.kappa[f][e]);
            let rot = c64::new(rot.x, rot.y);
            let w = r.weight[f][e];
            match (z_fixed(f), z_fixed(g)) {
                (None, None) => {
                    let (i, j) = (var[f], var[g]);
                    triplets.push((i, i, c64::new(w, 0.0)));
                    triplets.push((j, j, c64::new(w, 0.0)));
                    // (Az)_g ∋ −w r z_f, (Az)_f ∋ −w r̄ z_g.
                    let off = -rot * w;
                    if j > i {
                        triplets.push((j, i, off));
                    } else {
                        triplets.push((i, j, off.conj()));
                    }
                }
                (None, Some(zg)) => {
                    triplets.push((var[f], var[f], c64::new(w, 0.0)));
                    rhs[var[f]] += rot.conj() * zg * w;
                }
                (Some(zf), None) => {
                    triplets.push((var[g], var[g], c64::new(w, 0.0)));
                    rhs[var[g]] += rot * zf * w;
                }
                (Some(_), Some(_)) => {}
            }
        }
    }
    for f in 0..nf {
        if let (Some(t), true) = (r.soft[f], var[f] != usize::MAX) {
            let w = r.soft_weight * r.mass[f];
            let z = DVec2::from_angle(4.0 * t);
            triplets.push((var[f], var[f], c64::new(w, 0.0)));
            rhs[var[f]] += c64::new(z.x, z.y) * w;
        }
    }
    let mean_degree = degree.iter().sum::<f64>() / nf.max(1) as f64;
    let shift = 1e-8 * mean_degree.max(1.0);
    triplets.extend((0..n).map(|i| (i, i, c64::new(shift, 0.0))));
    (triplets, rhs, var, n)
}

/// The relaxation's system, factorized once for all starts: the
/// smoothness matrix L (inverse iteration) and L + λM (the unit-length
/// steps).
struct RelaxedSystem {
    /// The dual graph's pattern (with the full diagonal), its symbolic
    /// factorization reused by the angle system when that has the same
    /// unknowns.
    pattern: SpdPattern,
    rhs: Vec<c64>,
    var: Vec<usize>,
    factor: SpdFactor<c64>,
    unit_factor: SpdFactor<c64>,
}

impl RelaxedSystem {
    fn new(r: &Relaxation<'_>) -> Option<RelaxedSystem> {
        let (triplets, rhs, var, n) = relaxation_system(r);
        let mut unit = triplets.clone();
        for (f, &v) in var.iter().enumerate() {
            if v != usize::MAX {
                unit.push((v, v, c64::new(UNIT_LAMBDA * r.mass[f], 0.0)));
            }
        }
        // One pattern (L has the full diagonal), one symbolic analysis.
        let pattern = SpdPattern::new(n, &unit)?;
        let factor = pattern.factor(&triplets).ok()?;
        let unit_factor = pattern.factor(&unit).ok()?;
        Some(RelaxedSystem {
            pattern,
            rhs,
            var,
            factor,
            unit_factor,
        })
    }
}

/// Step (1): the smoothest field in the 4th-power representation, from
/// each start (`true`: pseudo-random z, `false`: z = 1 in the reference
/// frames); the starts run together, one triangular pass per step.
fn relaxed_angles(
    r: &Relaxation<'_>,
    sys: &RelaxedSystem,
    starts: &[bool],
) -> Option<Vec<Vec<f64>>> {
    let nf = r.fixed.len();
    let var = &sys.var;
    let n = sys.rhs.len();
    let mut constrained_component = vec![false; nf];
    for f in 0..nf {
        if r.fixed[f].is_some() || r.soft[f].is_some() {
            constrained_component[r.components[f] as usize] = true;
        }
    }
    // Inverse iteration for components without constraints, normalised
    // per component after every solve; the random start is a fixed
    // pseudo-random z per face, so that symmetric meshes do not pick a
    // symmetric (and clustered) element of a degenerate lowest eigenspace.
    let mut xs: Vec<Vec<c64>> = starts
        .iter()
        .map(|&random| {
            let mut rng = rand_pcg::Pcg32::new(0x853c_49e6_748f_ea9b, 0xda3e_39cb_94b9_5bdb);
            let mut next = || rand_core::RngCore::next_u32(&mut rng) as f64 / u32::MAX as f64 - 0.5;
            (0..n)
                .map(|_| {
                    if random {
                        let re = next();
                        c64::new(re, next())
                    } else {
                        c64::new(1.0, 0.0)
                    }
                })
                .collect()
        })
        .collect();
    // With every component constrained the right-hand side does not
    // depend on z: one solve is the minimiser.
    let iterations = if has_free_component(r) {
        INVERSE_ITERATIONS
    } else {
        1
    };
    for _ in 0..iterations {
        let b: Vec<Vec<c64>> = xs
            .iter()
            .map(|x| {
                let mut b = sys.rhs.clone();
                for f in 0..nf {
                    if var[f] != usize::MAX && !constrained_component[r.components[f] as usize] {
                        b[var[f]] += x[var[f]] * r.mass[f];
                    }
                }
                b
            })
            .collect();
        xs = sys.factor.solve(&b)?;
        for x in &mut xs {
            normalise_free_components(x, var, r.components, &constrained_component);
        }
    }
    unit_length_iterations(sys, r.mass, &mut xs)?;
    Some(
        xs.iter()
            .map(|x| {
                (0..nf)
                    .map(|f| match r.fixed[f] {
                        Some(t) => t,
                        None => x[var[f]].im.atan2(x[var[f]].re) / 4.0,
                    })
                    .collect()
            })
            .collect(),
    )
}

/// Towards unit |z| (the relaxation spreads clustered zeros over
/// degenerate eigenspaces, e.g. the round sphere's): a few steps of
/// z ← (L + λM)⁻¹(λM·z/|z| + b), diffusion with re-normalisation per face
/// (the MBO scheme of Viertel & Osting 2019 for cross fields).
fn unit_length_iterations(sys: &RelaxedSystem, mass: &[f64], xs: &mut Vec<Vec<c64>>) -> Option<()> {
    if sys.rhs.is_empty() {
        return Some(());
    }
    for _ in 0..UNIT_STEPS {
        let b: Vec<Vec<c64>> = xs
            .iter()
            .map(|x| {
                let mut b = sys.rhs.clone();
                for (f, &v) in sys.var.iter().enumerate() {
                    if v != usize::MAX {
                        let z = DVec2::new(x[v].re, x[v].im)
                            .try_normalize()
                            .unwrap_or(DVec2::X);
                        b[v] += c64::new(z.x, z.y) * (UNIT_LAMBDA * mass[f]);
                    }
                }
                b
            })
            .collect();
        *xs = sys.unit_factor.solve(&b)?;
    }
    Some(())
}

fn normalise_free_components(
    x: &mut [c64],
    var: &[usize],
    components: &[u32],
    constrained: &[bool],
) {
    let mut norm = vec![0.0f64; components.len()];
    for (f, &v) in var.iter().enumerate() {
        if v != usize::MAX && !constrained[components[f] as usize] {
            norm[components[f] as usize] += x[v].re * x[v].re + x[v].im * x[v].im;
        }
    }
    for (f, &v) in var.iter().enumerate() {
        let c = components[f] as usize;
        if v != usize::MAX && !constrained[c] && norm[c] > 0.0 {
            x[v] *= norm[c].sqrt().recip();
        }
    }
}

/// Step (2): each p_ij minimising |γ_ij| for the current θ.
fn round_period_jumps(topology: &EdgeTopology, kappa: &[[f64; 3]], theta: &[f64]) -> Vec<[i32; 3]> {
    let mut p = vec![[0i32; 3]; theta.len()];
    for f in 0..theta.len() {
        for e in 0..3 {
            if let Some((g, _)) = topology.across(f, e) {
                p[f][e] = ((theta[g] - theta[f] - kappa[f][e]) / FRAC_PI_2).round() as i32;
            }
        }
    }
    p
}

/// Step (3): θ minimising E_smooth for fixed p (one θ per unconstrained
/// component is held at its value in the first θ as the gauge). The
/// matrix depends only on which faces are fixed, so it is factorized once
/// and every round only changes the right-hand side.
struct AngleSystem {
    /// The fixed angle per face (constraints and gauges).
    fixed: Vec<Option<f64>>,
    /// Unknown index per free face (`usize::MAX` when fixed).
    var: Vec<usize>,
    /// Number of unknowns.
    n: usize,
    factor: SpdFactor,
}

impl AngleSystem {
    /// `relaxed`: the relaxation's unknowns and pattern, reused when the
    /// unknowns are the same (no gauge face added): the angle system's
    /// entries lie in the relaxation's pattern (the same dual edges).
    fn new(
        r: &Relaxation<'_>,
        theta: &[f64],
        relaxed: (&[usize], &SpdPattern),
    ) -> Option<AngleSystem> {
        let nf = theta.len();
        let mut fixed: Vec<Option<f64>> = r.fixed.to_vec();
        let mut has_fixed = vec![false; nf];
        for f in 0..nf {
            has_fixed[r.components[f] as usize] |= fixed[f].is_some() || r.soft[f].is_some();
        }
        for f in 0..nf {
            let c = r.components[f] as usize;
            if !has_fixed[c] {
                fixed[f] = Some(theta[f]);
                has_fixed[c] = true;
            }
        }
        let mut var = vec![usize::MAX; nf];
        let mut n = 0;
        for f in 0..nf {
            if fixed[f].is_none() {
                var[f] = n;
                n += 1;
            }
        }
        // The matrix does not depend on p: factorize it with p = 0.
        let eq = equations(r, &fixed, &var, n, &vec![[0; 3]; nf], &vec![0; nf]);
        let factor = if var == relaxed.0 {
            relaxed.1.factor(&eq.triplets).ok()?
        } else {
            SpdFactor::new(n, &eq.triplets)?
        };
        Some(AngleSystem {
            fixed,
            var,
            n,
            factor,
        })
    }

    /// The gauge angles (of components without constraints) from `theta`:
    /// the matrix depends only on which faces are fixed, not on their
    /// angles.
    fn gauge(&mut self, r: &Relaxation<'_>, theta: &[f64]) {
        for f in 0..theta.len() {
            if r.fixed[f].is_none() && self.fixed[f].is_some() {
                self.fixed[f] = Some(theta[f]);
            }
        }
    }

    /// θ for the period jumps `p` and the soft constraints' quarter-turn
    /// offsets `k` (θ_f → θ_target + k_f·π/2).
    fn solve(&self, r: &Relaxation<'_>, p: &[[i32; 3]], k: &[i32]) -> Option<Vec<f64>> {
        let eq = equations(r, &self.fixed, &self.var, self.n, p, k);
        let x = self.factor.solve(&[eq.rhs])?.pop()?;
        Some(
            (0..self.fixed.len())
                .map(|f| self.fixed[f].unwrap_or_else(|| x[self.var[f]]))
                .collect(),
        )
    }
}

/// The normal equations of θ_f − θ_g = −κ − (π/2) p over the dual edges,
/// the fixed faces' angles moved to the right-hand side, and of the soft
/// constraints θ_f = θ_target + (π/2) k_f.
fn equations(
    r: &Relaxation<'_>,
    fixed: &[Option<f64>],
    var: &[usize],
    n: usize,
    p: &[[i32; 3]],
    k: &[i32],
) -> NormalEquations {
    let mut eq = NormalEquations::new(n);
    for f in 0..fixed.len() {
        if let (Some(t), None) = (r.soft[f], fixed[f]) {
            let w = (r.soft_weight * r.mass[f]).sqrt();
            eq.row(w, &[(var[f], 1.0)], t + FRAC_PI_2 * k[f] as f64);
        }
    }
    for f in 0..fixed.len() {
        for e in 0..3 {
            let Some((g, _)) = r.topology.across(f, e) else {
                continue;
            };
            if g < f {
                continue;
            }
            let mut b = -r.kappa[f][e] - FRAC_PI_2 * p[f][e] as f64;
            let mut entries = Vec::with_capacity(2);
            for (face, c) in [(f, 1.0), (g, -1.0)] {
                match fixed[face] {
                    Some(t) => b -= c * t,
                    None => entries.push((var[face], c)),
                }
            }
            eq.row(1.0, &entries, b);
        }
    }
    eq
}

fn smoothness_energy(
    topology: &EdgeTopology,
    kappa: &[[f64; 3]],
    p: &[[i32; 3]],
    theta: &[f64],
) -> f64 {
    let mut e_smooth = 0.0;
    for f in 0..theta.len() {
        for e in 0..3 {
            if let Some((g, _)) = topology.across(f, e) {
                if g > f {
                    let gamma = theta[f] + kappa[f][e] + FRAC_PI_2 * p[f][e] as f64 - theta[g];
                    e_smooth += gamma * gamma;
                }
            }
        }
    }
    e_smooth
}

/// Some component has no constrained face.
fn has_free_component(r: &Relaxation<'_>) -> bool {
    let nf = r.fixed.len();
    let mut constrained = vec![false; nf];
    for f in 0..nf {
        constrained[r.components[f] as usize] |= r.fixed[f].is_some() || r.soft[f].is_some();
    }
    (0..nf).any(|f| r.components[f] as usize == f && !constrained[f])
}

/// Steps (2)–(3), repeated; the period jumps at feature corners are
/// rounded with their sectors' sums ([`enforce_sectors`]).
fn round_and_resolve(
    r: &Relaxation<'_>,
    system: &AngleSystem,
    sectors: &[Sector],
    mut theta: Vec<f64>,
) -> Option<(Vec<f64>, Vec<[i32; 3]>)> {
    let round = |theta: &[f64]| {
        let mut p = round_period_jumps(r.topology, r.kappa, theta);
        enforce_sectors(r.topology, r.kappa, theta, sectors, &mut p);
        p
    };
    let mut p = round(&theta);
    let mut k = round_soft_offsets(r, &theta);
    for _ in 0..ROUNDS {
        theta = system.solve(r, &p, &k)?;
        p = round(&theta);
        k = round_soft_offsets(r, &theta);
    }
    theta = system.solve(r, &p, &k)?;
    Some((theta, p))
}

/// One sector of a feature vertex's fan between two consecutive feature
/// edges: the interior edges crossed counter-clockwise, (face, local
/// edge), and the sum of their period jumps that makes it `quarters`
/// quarter turns in the map.
#[derive(Debug, Clone, PartialEq)]
pub struct Sector {
    pub vertex: u32,
    pub edges: Vec<(usize, usize)>,
    pub quarters: i32,
    pub period_jump_sum: i32,
}

/// The sectors of every interior vertex with at least two feature edges
/// (Bommes et al. 2009 §4–5: the feature curves are integer isolines,
/// so at a corner each sector between two of them spans a whole number
/// k ≥ 1 of quarter turns in the map, and the vertex is a cone of index
/// 1 − Σk/4; on a straight curve k = 2 + 2, no cone).
///
/// A sector runs from feature edge a, in its first face F₁, to the next
/// feature edge b counter-clockwise; its edges are the crossings from F₁
/// up to and including b's, into the next sector's first face F_b. Let β
/// be the counter-clockwise angle from a to b by the transport of the κ
/// (the representative nearest the sector's surface angle α). The cross
/// carried from F₁ along the sector arrives rotated by
/// ρ = θ_b − θ₁ − Σκ − (π/2)·Σp against the transport; it turns a onto b
/// after k quarter turns when ρ = β − k·π/2, which gives Σp (θ₁, θ_b are
/// the fixed angles of the constrained faces; a sector whose end face is
/// unconstrained is skipped). With the filtered normals β is not α (a
/// cube corner's sectors are 120° in the filtered planes), which is why
/// the plain rounding of p puts corner cones a ring or two away.
fn corner_sectors(
    input: &CrossFieldInput<'_>,
    reference: &[DVec3],
    kappa: &[[f64; 3]],
    fixed: &[Option<f64>],
    shift: &std::collections::HashMap<u32, i32>,
) -> (Vec<Sector>, Vec<u32>) {
    let (mesh, features) = (input.mesh, input.feature_edges);
    let mut out = Vec::new();
    let mut curve = Vec::new();
    if features.is_empty() {
        return (out, curve);
    }
    let sharp = |f: usize, e: usize| features.get(f).is_some_and(|s| s[e]);
    for (v, fan) in input.fans.iter().enumerate() {
        let Some(fan) = fan.as_ref().filter(|f| f.closed) else {
            continue;
        };
        let corners: Vec<(usize, usize)> = fan
            .corners
            .iter()
            .map(|&(f, i)| (f as usize, i as usize))
            .collect();
        let m = corners.len();
        // Crossing j goes from corner j to corner j + 1 over local edge
        // i + 2 of corner j's face.
        let cuts: Vec<usize> = (0..m)
            .filter(|&j| sharp(corners[j].0, (corners[j].1 + 2) % 3))
            .collect();
        if cuts.len() < 2 {
            continue;
        }
        curve.push(v as u32);
        let mut quarters: Vec<i32> = Vec::with_capacity(cuts.len());
        let mut angles: Vec<f64> = Vec::with_capacity(cuts.len());
        let p = |f: usize, i: usize| mesh.positions[mesh.triangles[f][i] as usize];
        for (c, &s) in cuts.iter().enumerate() {
            let next = cuts[(c + 1) % cuts.len()];
            let len = (next + m - s - 1) % m + 1;
            let alpha: f64 = (1..=len)
                .map(|k| {
                    let (f, i) = corners[(s + k) % m];
                    (p(f, (i + 1) % 3) - p(f, i)).angle_between(p(f, (i + 2) % 3) - p(f, i))
                })
                .sum();
            angles.push(alpha);
            quarters.push(((alpha / FRAC_PI_2).round() as i32).max(1));
        }
        shift_quarters(&mut quarters, &angles, shift.get(&(v as u32)).copied());
        let mut here: Vec<(f64, Sector)> = Vec::with_capacity(cuts.len());
        for (c, &s) in cuts.iter().enumerate() {
            let next = cuts[(c + 1) % cuts.len()];
            let len = (next + m - s - 1) % m + 1; // faces s + 1 ..= next
            let faces: Vec<(usize, usize)> = (1..=len).map(|k| corners[(s + k) % m]).collect();
            let (f1, i1) = faces[0];
            let (fb, ib) = corners[(next + 1) % m];
            let (Some(t1), Some(tb)) = (fixed[f1], fixed[fb]) else {
                continue;
            };
            let alpha = angles[c];
            let edges: Vec<(usize, usize)> = faces.iter().map(|&(f, i)| (f, (i + 2) % 3)).collect();
            let sum_kappa: f64 = edges.iter().map(|&(f, e)| kappa[f][e]).sum();
            let ea = p(f1, (i1 + 1) % 3) - p(f1, i1);
            let eb = p(fb, (ib + 1) % 3) - p(fb, ib);
            let a1 = angle_from(reference[f1], input.normals[f1], ea);
            let ab = angle_from(reference[fb], input.normals[fb], eb);
            let raw = ab - a1 - sum_kappa;
            let beta = raw + TAU * ((alpha - raw) / TAU).round();
            let k = quarters[c];
            let sum_p = (tb - t1 - sum_kappa - (beta - FRAC_PI_2 * k as f64)) / FRAC_PI_2;
            here.push((
                sum_p,
                Sector {
                    vertex: v as u32,
                    edges,
                    quarters: k,
                    period_jump_sum: sum_p.round() as i32,
                },
            ));
        }
        // The sectors' real sums add up to an integer (the θ telescope and
        // Σκ ≡ K(v)); rounding them one by one could miss it by one (end
        // faces whose cross is turned against their edge, as in a sector
        // of one face aligned with its other feature edge), so they are
        // rounded with that total (largest remainders first).
        if here.len() == cuts.len() {
            let total = here.iter().map(|h| h.0).sum::<f64>().round() as i32;
            for h in &mut here {
                h.1.period_jump_sum = h.0.floor() as i32;
            }
            let mut d = total - here.iter().map(|h| h.1.period_jump_sum).sum::<i32>();
            let mut order: Vec<usize> = (0..here.len()).collect();
            order.sort_by(|&i, &j| {
                (here[j].0 - here[j].0.floor()).total_cmp(&(here[i].0 - here[i].0.floor()))
            });
            for &i in order.iter().cycle().take(here.len() * 4) {
                if d <= 0 {
                    break;
                }
                here[i].1.period_jump_sum += 1;
                d -= 1;
            }
        }
        out.extend(here.into_iter().map(|h| h.1));
    }
    out.sort_by_key(|s| s.edges.len());
    (out, curve)
}

/// A feature vertex's sector quarters with `q` more cone quarters (a cone
/// moved onto it, [`snap_cones`]): Σk − q (at least one per sector), the
/// sectors whose angles are nearest fewer (more) quarters losing (gaining)
/// them.
fn shift_quarters(k: &mut [i32], angles: &[f64], q: Option<i32>) {
    let Some(q) = q else { return };
    let sum: i32 = k.iter().sum();
    let target = (sum - q).max(k.len() as i32);
    for _ in 0..(sum - target).abs() {
        let excess = |k: &[i32], i: usize| k[i] as f64 - angles[i] / FRAC_PI_2;
        let i = if target < sum {
            (0..k.len())
                .filter(|&i| k[i] > 1)
                .max_by(|&i, &j| excess(k, i).total_cmp(&excess(k, j)))
        } else {
            (0..k.len()).min_by(|&i, &j| excess(k, i).total_cmp(&excess(k, j)))
        };
        let Some(i) = i else { break };
        k[i] += if target < sum { -1 } else { 1 };
    }
}

/// The period jumps of each sector's edges: the integers nearest their
/// real values (θ_g − θ_f − κ)/(π/2) with the sector's sum (the largest
/// rounding residuals move first); the other side of each edge gets −p.
/// Neighbouring feature vertices share edges (every feature edge between
/// two of them): the sectors go in order of their edge count (as
/// [`corner_sectors`] sorts them) and each one moves only edges no
/// earlier sector has used, when it has any.
fn enforce_sectors(
    topology: &EdgeTopology,
    kappa: &[[f64; 3]],
    theta: &[f64],
    sectors: &[Sector],
    p: &mut [[i32; 3]],
) {
    let mut used = std::collections::HashSet::new();
    let key = |f: usize, e: usize| match topology.across(f, e) {
        Some((g, ge)) => (f, e).min((g, ge)),
        None => (f, e),
    };
    for s in sectors {
        let mut real: Vec<(f64, usize)> = Vec::with_capacity(s.edges.len());
        let mut sum = 0;
        for (j, &(f, e)) in s.edges.iter().enumerate() {
            let Some((g, _)) = topology.across(f, e) else {
                continue;
            };
            sum += p[f][e];
            if !used.contains(&key(f, e)) {
                let x = (theta[g] - theta[f] - kappa[f][e]) / FRAC_PI_2;
                real.push((x - p[f][e] as f64, j));
            }
        }
        if real.is_empty() {
            // Every edge is an earlier sector's: move them anyway.
            for (j, &(f, e)) in s.edges.iter().enumerate() {
                if let Some((g, _)) = topology.across(f, e) {
                    let x = (theta[g] - theta[f] - kappa[f][e]) / FRAC_PI_2;
                    real.push((x - p[f][e] as f64, j));
                }
            }
        }
        if real.is_empty() {
            continue;
        }
        let mut d = s.period_jump_sum - sum;
        // Up: the edges rounded down the most first; down: the reverse.
        real.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        if d < 0 {
            real.reverse();
        }
        let step = d.signum();
        let mut at = 0;
        while d != 0 {
            let (f, e) = s.edges[real[at % real.len()].1];
            p[f][e] += step;
            d -= step;
            at += 1;
        }
        for &(f, e) in &s.edges {
            used.insert(key(f, e));
            if let Some((g, ge)) = topology.across(f, e) {
                p[g][ge] = -p[f][e];
            }
        }
    }
}

/// Per face: the quarter turns k nearest θ_f − θ_target (soft constraints).
fn round_soft_offsets(r: &Relaxation<'_>, theta: &[f64]) -> Vec<i32> {
    (0..theta.len())
        .map(|f| r.soft[f].map_or(0, |t| ((theta[f] - t) / FRAC_PI_2).round() as i32))
        .collect()
}

/// Computes the cross field; None when a sparse factorization fails.
pub fn cross_field(input: &CrossFieldInput<'_>) -> Option<CrossField> {
    let nf = input.mesh.triangles.len();
    let normals = input.normals.to_vec();
    let reference = reference_directions(input.mesh, &normals);
    let kappa = transition_angles(input, &reference);
    // The solve's transport: κ turned by the sizing (the cones, the
    // feature sectors and the output keep the true κ).
    let solve_kappa = match sizing_transport(input) {
        Some(turn) => kappa
            .iter()
            .zip(&turn)
            .map(|(k, t)| std::array::from_fn(|e| k[e] + t[e]))
            .collect(),
        None => kappa.clone(),
    };
    let angle = |c: &[Option<DVec3>], f: usize| {
        let d = c.get(f).copied().flatten()?;
        let d = d.reject_from_normalized(normals[f]);
        (d.length() > 1e-12).then(|| angle_from(reference[f], normals[f], d))
    };
    let fixed: Vec<Option<f64>> = (0..nf).map(|f| angle(input.constraints, f)).collect();
    let soft_weight = input.soft_weight.max(0.0);
    let soft: Vec<Option<f64>> = (0..nf)
        .map(|f| {
            let t = angle(input.soft_constraints, f);
            t.filter(|_| fixed[f].is_none() && soft_weight > 0.0)
        })
        .collect();
    let components = face_components(input.topology);
    let (weight, mass) = dual_weights(input.mesh, input.topology);
    let r = Relaxation {
        topology: input.topology,
        kappa: &solve_kappa,
        fixed: &fixed,
        soft: &soft,
        soft_weight,
        components: &components,
        weight: &weight,
        mass: &mass,
    };
    // Two starts of the relaxation where it matters (unconstrained
    // components): z = 1 in the reference frames, and pseudo-random z;
    // the lower E_smooth after rounding wins.
    let free = has_free_component(&r);
    let starts: &[bool] = if free { &[false, true] } else { &[false] };
    let system = RelaxedSystem::new(&r)?;
    let relaxed = relaxed_angles(&r, &system, starts)?;
    let mut angles: Option<AngleSystem> = None;
    let mut shift = std::collections::HashMap::new();
    let mut snapped = std::collections::HashSet::new();
    let mut field = None;
    for _ in 0..=SNAP_ROUNDS {
        let (sectors, curve) = corner_sectors(input, &reference, &kappa, &fixed, &shift);
        let mut best: Option<(f64, Vec<f64>, Vec<[i32; 3]>)> = None;
        for theta in &relaxed {
            let angles = match &mut angles {
                Some(a) => {
                    a.gauge(&r, theta);
                    a
                }
                None => angles.insert(AngleSystem::new(&r, theta, (&system.var, &system.pattern))?),
            };
            let (theta, p) = round_and_resolve(&r, angles, &sectors, theta.clone())?;
            let energy = smoothness_energy(input.topology, &solve_kappa, &p, &theta);
            if best.as_ref().is_none_or(|b| energy < b.0) {
                best = Some((energy, theta, p));
            }
        }
        let (energy, theta, p) = best?;
        let mut f = CrossField {
            normals: normals.clone(),
            reference: reference.clone(),
            theta,
            kappa: kappa.clone(),
            period_jump: p,
            constrained: fixed.iter().map(Option::is_some).collect(),
            cones: Vec::new(),
            energy,
            index_residual: 0.0,
        };
        let (cones, residual) = cones(&f, input.fans);
        f.cones = cones;
        f.index_residual = residual;
        let moved = snap_cones(input, &f.cones, &curve, &mut shift, &mut snapped);
        field = Some(f);
        if !moved {
            break;
        }
    }
    field
}

/// Rounds of [`snap_cones`] and re-rounding.
const SNAP_ROUNDS: usize = 3;

/// Cones of the field off the feature curves (at no vertex of a feature
/// edge) but nearer a vertex of them with two or more feature edges than
/// `snap_distance` target edges move onto that vertex: `shift` gives it
/// their quarters (MIQ puts cones on the curves: one at an integer point
/// less than half a unit from a curve's integer isoline is rounded onto it
/// and the ring between them folds). Each cone moves once (`snapped`);
/// returns whether one did.
fn snap_cones(
    input: &CrossFieldInput<'_>,
    cones: &[Cone],
    curve: &[u32],
    shift: &mut std::collections::HashMap<u32, i32>,
    snapped: &mut std::collections::HashSet<u32>,
) -> bool {
    if curve.is_empty() || input.face_sizing.is_empty() || input.snap_distance <= 0.0 {
        return false;
    }
    // Cones on a curve (at a vertex of a feature edge, its end too) stay.
    let mut on_curve: std::collections::HashSet<u32> = curve.iter().copied().collect();
    for (f, e) in input.feature_edges.iter().enumerate() {
        for k in (0..3).filter(|&k| e[k]) {
            let t = input.mesh.triangles[f];
            on_curve.extend([t[k], t[(k + 1) % 3]]);
        }
    }
    let position = |v: u32| input.mesh.positions[v as usize];
    let mut moved = false;
    for c in cones {
        if on_curve.contains(&c.vertex) || snapped.contains(&c.vertex) {
            continue;
        }
        let Some(fan) = input.fans[c.vertex as usize].as_ref() else {
            continue;
        };
        let sizing = fan
            .corners
            .iter()
            .map(|&(f, _)| input.face_sizing[f as usize])
            .sum::<f64>()
            / fan.corners.len().max(1) as f64;
        let p = position(c.vertex);
        let Some((w, d)) = curve
            .iter()
            .map(|&w| (w, position(w).distance(p)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
        else {
            continue;
        };
        if d < input.snap_distance * sizing {
            *shift.entry(w).or_insert(0) += c.quarters;
            snapped.insert(c.vertex);
            moved = true;
        }
    }
    moved
}

/// Signed area of the spherical polygon of unit vectors `n` (in order),
/// fanned from their normalised mean (Van Oosterom & Strackee per
/// triangle).
pub fn spherical_polygon_area(n: &[DVec3]) -> f64 {
    let Some(c) = n.iter().copied().sum::<DVec3>().try_normalize() else {
        return 0.0;
    };
    let m = n.len();
    (0..m)
        .map(|k| {
            let (a, b) = (n[k], n[(k + 1) % m]);
            let num = c.dot(a.cross(b));
            let den = 1.0 + c.dot(a) + a.dot(b) + b.dot(c);
            2.0 * num.atan2(den)
        })
        .sum()
}

/// The cones (§4.5) and the largest distance of 4·I(v) from an integer.
fn cones(field: &CrossField, fans: &[Option<Fan>]) -> (Vec<Cone>, f64) {
    let mut cones = Vec::new();
    let mut residual = 0.0f64;
    let mut normals = Vec::new();
    for (v, fan) in fans.iter().enumerate() {
        let Some(fan) = fan.as_ref().filter(|f| f.closed) else {
            continue;
        };
        normals.clear();
        let (mut sum_kappa, mut sum_p) = (0.0, 0i32);
        for &(f, i) in &fan.corners {
            let (f, e) = (f as usize, (i as usize + 2) % 3);
            sum_kappa += field.kappa[f][e];
            sum_p += field.period_jump[f][e];
            normals.push(field.normals[f]);
        }
        let k = spherical_polygon_area(&normals);
        let quarters = 4.0 * (k - sum_kappa) / TAU - sum_p as f64;
        let q = quarters.round();
        residual = residual.max((quarters - q).abs());
        if q != 0.0 {
            cones.push(Cone {
                vertex: v as u32,
                quarters: q as i32,
            });
        }
    }
    (cones, residual)
}
