//! Dual loops through anchors: Campen & Kobbelt 2014, §5.4 (constructing
//! discrete elastica: shortest paths between consecutive anchors' candidate
//! g-edges, a metagraph and its minimum-weight cycle), §5.7 (the boundary
//! node ∂ for dual curves) and §6.2 (strip compatibility: g′-nodes within 45°
//! of a committed strip's direction inside it are disabled).
//!
//! Deviations:
//! - Searches between anchors are A* towards the next anchor (heuristic
//!   0.9 × straight-line distance, a lower bound of the length term), and
//!   stop as soon as the smallest open key reaches the best closing cost
//!   (early termination).
//! - Targets are reached *through an arc* (`x → b` with `x` arriving at the
//!   anchor vertex), so a loop from a node back to itself is never the empty
//!   path (the paper's footnote 2).
//! - g′ weights are reversal-symmetric (up to rounding), so the backward
//!   search into a node is a forward search from the reversed nodes. A loop
//!   through one anchor (the hover query) is found by a *bidirectional*
//!   search: forward from the anchor's out-edge and forward from the
//!   out-edges whose reverse closes into it, meeting at `y` / `reverse(y)`,
//!   stopping when twice the smallest open distance reaches the best loop
//!   (exact: tested against plain Dijkstra). The hover query first ranks
//!   the directions with one labelled search of this kind from all out-edges
//!   at once (approximate: a node keeps only its cheapest source), then runs
//!   the exact search through the best few. Likewise the distance *to*
//!   ∂ is the distance *from* ∂ of the reversed node: one Dijkstra from all
//!   boundary g-edges per mesh (cached until the covered strips change)
//!   serves every dual-curve query; it is settled lazily, only as far as
//!   the queries' cost bounds need (the hover query doubles a radius until
//!   a dual curve or a loop below it exists), and fully in the design
//!   tool's idle time (`prepare_fields`), so that no hover grows it.
//! - §5.7 connects ∂ to "all g-edges incident to a boundary vertex" (E∂).
//!   Taken literally, every g-edge within k rings of the boundary is at
//!   distance 0 from ∂ in both directions, so an anchor near the boundary
//!   gets a one-node, zero-cost "dual curve" that never crosses the surface.
//!   Here E∂ is directed: ∂ → b only for g-edges b that *start* at a
//!   boundary vertex and end at an interior one, and a → ∂ only for g-edges
//!   a that *end* at a boundary vertex coming from an interior one (the
//!   reverses of the former). A dual curve therefore starts on the boundary,
//!   leaves it into the interior, and ends by arriving at the boundary; it
//!   has at least two nodes and one g′-arc (no single g-edge both leaves and
//!   arrives), hence positive length and cost, and its end nodes carry the
//!   §5.6 orthogonality weight (`q` at their boundary vertex, charged on the
//!   first and last arcs). g-edges with both ends on the boundary (along it,
//!   or chords across a part narrower than k rings) never end a curve, so a
//!   part with no interior vertex has no dual curve.
//! - The hover searches (the labelled ranking and the bidirectional loop)
//!   and the searches through several anchors
//!   pop from a radix heap ([`super::radix_heap`]) keyed by the distance's
//!   bits (A*: the key's), not a binary heap: the same order up to ties
//!   between equal keys.
//! - The loop through two positional anchors (the second click) is not one
//!   layered search per start of the first anchor but, per start a₀, two
//!   half-searches meeting at the second anchor's candidates y: d(a₀ → y)
//!   forward and d(y → a₀) as the forward search from reverse(a₀), both A*
//!   guided by ONE field, the distances from the second anchor's
//!   candidates (F(reverse(x)) bounds the distance from x to the anchor),
//!   settled only as far as the searches read it. F(reverse(a₀)) + F(a₀)
//!   bounds each start's loop from below; everything is pruned by a level
//!   1 % above the smallest bound, growing by 2 % until a loop below it
//!   exists. The dual curve through both is one A* from the first anchor's
//!   candidates at their distances from ∂, guided by F and by the distance
//!   to ∂. With three or more positional anchors (on distinct consecutive
//!   vertices) one such field per anchor is settled fully (no first
//!   labelled search from all starts, no further bounding searches): the
//!   fields give each start a lower bound (the sum of its two end
//!   segments' field values and the smallest value of every middle
//!   segment), which orders and prunes the per-start layered searches,
//!   all guided by the fields; with a boundary the dual curve, guided too,
//!   runs after the first start, bounded by its loop. The fields of the
//!   last few positional anchors are kept between queries (until the
//!   covered strips change), the two-anchor search's partly settled one
//!   included, so a grab or a drag of one anchor settles one new field.
//!   Exact (tested against one layered search per start and the layered
//!   dual-curve search). The hover query settles the distances
//!   from ∂ to the cheapest dual curve first and runs the closed-loop search
//!   once, bounded by it.
//! - The hover query can also be answered progressively
//!   ([`LoopEngine::hover_begin`], [`LoopEngine::hover_resume`]): the same
//!   search (the distances from ∂ grown until the cheapest dual curve is
//!   proven, the labelled search bounded by it, the exact refinement) run
//!   by slices of a bounded number of settled nodes; until it finishes, the
//!   cheapest dual curve or closed loop found so far (a true walk of g′
//!   through the vertex, with its true cost) is shown in its place. Its
//!   final answer is [`LoopEngine::best_loop`]'s with the distances from ∂
//!   settled fully (tested). Where that search has found nothing yet, the
//!   provisional answer comes from elsewhere: a recent exact answer through
//!   the vertex, or one with a node or two replaced by g-edges through it
//!   ([`LoopEngine::recent_through`]; on a closed mesh, where every loop
//!   through the vertex is found only as the search ends, the idle time
//!   fills the recent answers with loops through spread vertices), else a
//!   walk out of the vertex onto a nearby recent closed loop, along it and
//!   back into the vertex ([`LoopEngine::recent_bridge`], bounded
//!   searches); and on
//!   an open mesh whose distances from ∂ do not reach the vertex yet, a
//!   dual curve through it to where they do, by a greedy A*
//!   ([`LoopEngine::provisional_curve`]).
//! - The fields, the searches through anchors and the distances from ∂ run
//!   one settle loop ([`settle`]); the hover query's two bidirectional
//!   searches (stopping at twice the key) and the tests' references keep
//!   their own.
//! - Alternatives of a single anchor are de-duplicated by direction: a
//!   proposal within 25° (mod 180°) of a cheaper one's at the anchor is the
//!   same "direction class" and dropped; proposals above 6 × the best cost
//!   are not searched for.
//! - When both consecutive anchors are purely positional, |ξ_i| searches are
//!   run (the paper runs min(|ξ_i|, |ξ_{i+1}|) via backward search).
//! - §6.2 uses the strip map's isocurves; before part 2 exists the covered
//!   direction is given per vertex ([`LoopEngine::set_covered`]) or taken
//!   from a loop's tangent within a band ([`LoopEngine::cover_loop`]).

#[cfg(test)]
use std::cmp::Reverse;
#[cfg(test)]
use std::collections::BinaryHeap;

use glam::{DVec3, Vec3};

use super::elastica::{ElasticaGraph, ElasticaParams};
use super::radix_heap::RadixHeap;
use super::surface_graph::SurfaceGraph;
use crate::mesh::TriMesh;
use crate::spatial::SurfaceIndex;

const NONE: u32 = u32::MAX;

/// The hover query refines at most this many directions exactly …
const REFINE_DIRECTIONS: usize = 4;
/// … among those whose labelled loop is within this factor of the best.
const REFINE_RATIO: f32 = 1.25;
/// The first radius (normalised cost) to which the hover query settles the
/// distances from ∂ before looking for dual curves; it doubles as needed.
const BOUNDARY_RADIUS: f32 = 0.25;
/// The factor by which the pruning level of the two-anchor search grows
/// while no loop below it exists.
const LEVEL_GROWTH: f32 = 1.02;
/// The fields of this many recent positional anchors are kept between
/// queries (until the covered strips change).
const FIELD_CACHE: usize = 4;
/// … and by at least this much (normalised cost).
const LEVEL_STEP: f32 = 0.01 * BOUNDARY_RADIUS;
/// The weight of the straight-line distance to the boundary in the A* of
/// a provisional dual curve ([`LoopEngine::provisional_curve`]): above 1
/// the search is greedy (its curve is still a true walk with its true
/// cost, only not the cheapest). 4: 3–4k settled nodes per half on the
/// bunny's proxy, against 9–11k at 2 and more than 6 000 at 0.9.
const PROVISIONAL_GUIDE: f32 = 4.0;
/// The hover query's exact answers kept for provisional loops
/// ([`LoopEngine::recent_through`]).
const RECENT_LOOPS: usize = 128;
/// On a closed mesh the idle time fills the recent answers up to this many
/// (fandisk, 200 hovers after the idle time, native: hovers with no
/// provisional loop 71 without, 28 with 32 loops (0.5 s of idle time), 25
/// with 64 (1.2 s), 28 with 128 (2.7 s)).
const IDLE_LOOPS: usize = 32;
/// The idle-time queries that fill them on a closed mesh run by slices of
/// at most this many settled nodes (about a millisecond), so that a hover
/// waits little for the slice it arrives in.
const IDLE_LOOP_SLICE: u64 = 2_000;
/// A hover with no provisional loop from the recent answers' splices
/// bridges to the nearest this many recent closed loops
/// ([`LoopEngine::recent_bridge`]) …
const BRIDGE_LOOPS: usize = 8;
/// … trying the first this many reached …
const BRIDGE_TRIES: usize = 3;
/// … each of its searches settling at most this many g′ nodes.
const BRIDGE_NODES: u64 = 6_000;

/// A constraint point φ = (p, d) of §5.4: the loop passes near `position`,
/// and, when `direction` is non-zero, with its tangent parallel to it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anchor {
    /// World position (snapped to the nearest vertex).
    pub position: DVec3,
    /// World direction; zero for a purely positional anchor.
    pub direction: DVec3,
}

impl Anchor {
    pub fn positional(position: DVec3) -> Anchor {
        Anchor {
            position,
            direction: DVec3::ZERO,
        }
    }

    pub fn directional(position: DVec3, direction: DVec3) -> Anchor {
        Anchor {
            position,
            direction,
        }
    }
}

/// A dual loop (closed) or dual curve (ending on the boundary at both ends).
#[derive(Debug, Clone, PartialEq)]
pub struct DualLoop {
    /// The g′-node (directed g-edge) sequence; for a closed loop the last
    /// node is followed by the first.
    pub nodes: Vec<u32>,
    /// Polyline on the surface (world units): vertices of g and chord samples
    /// projected onto the faces. A closed loop repeats its first point last.
    pub points: Vec<DVec3>,
    /// The cost c(E) of equation (2), in normalised units (bbox diagonal 1).
    pub cost: f64,
    /// False for a dual curve ending on the boundary (§5.7).
    pub closed: bool,
}

impl DualLoop {
    /// Length of the polyline (world units).
    pub fn length(&self) -> f64 {
        self.points.windows(2).map(|w| w[0].distance(w[1])).sum()
    }
}

/// A place where a loop crosses itself (§8.1: nothing in the optimisation
/// controls self-crossings, "it is easy to automatically detect such a loop
/// and highlight it accordingly, asking for adjustment").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SelfCrossing {
    /// World position.
    pub point: DVec3,
    /// The crossing angle between the two passes, degrees in [0, 90].
    pub angle_degrees: f64,
}

/// Per-node search state of colour A (and the labelled search's label),
/// one 16-byte record: the labelled search, which reads only this colour,
/// touches four nodes per cache line (successors lie side by side).
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(16))]
struct Slot {
    dist: f32,
    parent: u32,
    /// `2·generation` once reached, `2·generation + 1` once settled.
    state: u32,
    /// Source of the path that reached the node (multi-source search).
    label: u32,
}

/// The second colour of the bidirectional loop search, in an array of its
/// own.
#[derive(Debug, Clone, Copy, Default)]
struct SlotB {
    dist: f32,
    parent: u32,
    state: u32,
}

/// What the labelled search of the hover query knows of `reverse(x)`,
/// stored at `x`: a loop closes where a relaxed node `y` meets its reverse,
/// and the successors `y` of a node lie side by side in g′ (the out-edges
/// of one vertex) while their reverses do not. Reading the meeting at `y`
/// instead of at `reverse(y)` turns the one scattered read per relaxed arc
/// into one scattered write per node reached.
#[derive(Debug, Clone, Copy, Default)]
struct Mirror {
    dist: f32,
    label: u32,
    /// The generation's `reached` stamp of `reverse(x)`, or older.
    state: u32,
}

/// Distance and state of node `x` in the bidirectional search's colour A
/// or B.
#[inline]
fn colour(a: &[Slot], b: &[SlotB], x: usize, in_b: bool) -> (f32, u32) {
    if in_b {
        (b[x].dist, b[x].state)
    } else {
        (a[x].dist, a[x].state)
    }
}

#[inline]
fn parent_of(a: &[Slot], b: &[SlotB], x: usize, in_b: bool) -> u32 {
    if in_b { b[x].parent } else { a[x].parent }
}

#[inline]
fn set_colour(
    a: &mut [Slot],
    b: &mut [SlotB],
    x: usize,
    in_b: bool,
    dist: f32,
    parent: u32,
    state: u32,
) {
    if in_b {
        b[x] = SlotB {
            dist,
            parent,
            state,
        };
    } else {
        (a[x].dist, a[x].parent, a[x].state) = (dist, parent, state);
    }
}

#[derive(Debug, Clone, Default)]
struct Workspace {
    slot: Vec<Slot>,
    slot_b: Vec<SlotB>,
    /// The labelled search's state of each node's *reverse*, written when
    /// the reverse is reached ([`LoopEngine::best_direction`]).
    mirror: Vec<Mirror>,
    generation: u32,
    /// The queue of the test-only reference searches (A* keys).
    #[cfg(test)]
    heap: BinaryHeap<Reverse<u64>>,
    /// The queue of the hover searches (monotone keys: distance bits).
    radix: RadixHeap,
    /// Per out-edge of the goal vertex: best closing cost and the closing
    /// predecessor.
    #[cfg(test)]
    cand: Vec<(f32, u32)>,
    path: Vec<u32>,
    /// Scratch for the second half of a bidirectional loop.
    cand_path: Vec<u32>,
    /// Weights of the closing arcs `reverse(s′) → s` between the out-edges
    /// of the hover vertex (row-major by `s′`; infinite where no arc).
    close: Vec<f32>,
    /// Per out-edge of the hover vertex: the cheapest loop the labelled
    /// search closed through it.
    label_best: Vec<f32>,
    /// Nodes settled by all searches so far (a machine-independent effort
    /// measure for benchmarks).
    effort: u64,
}

impl Workspace {
    /// Starts a search: a new stamp marks the entries it writes, so nothing
    /// has to be cleared (all stamps are reset once every 2³² searches).
    fn next_generation(&mut self) -> u32 {
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 || self.generation >= 1 << 30 {
            for s in &mut self.slot {
                s.state = 0;
            }
            for s in &mut self.slot_b {
                s.state = 0;
            }
            for m in &mut self.mirror {
                m.state = 0;
            }
            self.generation = 1;
        }
        self.generation
    }
}

impl ElasticaGraph {
    /// An admissible lower bound of the cost from g′ node `x` to a g-edge
    /// leaving vertex `goal`: 0.9 × the distance from `x`'s midpoint to the
    /// ball around `goal` holding the midpoints of its out-edges.
    fn heuristic_to(&self, goal: usize) -> impl Fn(usize) -> f32 + '_ {
        let goal_p = self.g.mesh.positions[goal].as_vec3();
        let radius = self
            .g
            .out_edges(goal)
            .map(|e| self.midpoint(e).distance(goal_p))
            .fold(0.0f32, f32::max);
        move |x: usize| 0.9 * (self.midpoint(x).distance(goal_p) - radius).max(0.0)
    }
}

/// The distances from ∂ (§5.7) of the g′-nodes, by one Dijkstra from all
/// boundary g-edges that is resumed only as far as the queries need
/// (`LoopEngine::settle_boundary`) or, in idle time, by slices to the end
/// (`LoopEngine::prepare_fields`); dropped when the covered strips change.
#[derive(Debug, Clone, Default)]
struct BoundaryField {
    dist: Vec<f32>,
    parent: Vec<u32>,
    settled: Vec<bool>,
    heap: RadixHeap,
    /// Every node closer than this is settled (∞ once the heap is empty).
    radius: f32,
}

impl BoundaryField {
    /// The cost of leaving to ∂ from each node of `layer`: the distance
    /// from ∂ of its reverse node, ∞ without one.
    fn leave_costs(&self, layer: &[u32], reverse: &[u32]) -> Vec<f32> {
        layer
            .iter()
            .map(|&a| {
                let r = reverse[a as usize];
                if r == NONE {
                    f32::INFINITY
                } else {
                    self.distance(r)
                }
            })
            .collect()
    }

    /// The settled distance from ∂, or ∞ (not closer than the settled
    /// radius).
    fn distance(&self, node: u32) -> f32 {
        let n = node as usize;
        if self.settled[n] {
            self.dist[n]
        } else {
            f32::INFINITY
        }
    }

    /// The settled distance from ∂, or the settled radius (a lower bound).
    fn lower_bound(&self, node: u32) -> f32 {
        let n = node as usize;
        if self.settled[n] {
            self.dist[n]
        } else {
            self.radius
        }
    }
}

/// [`LoopEngine::best_direction`]'s search between two slices of a
/// progressive hover ([`LoopEngine::hover_begin`]).
#[derive(Debug, Clone)]
struct LabelledSearch {
    /// The first out-edge of the hover vertex (the sources' row).
    start: usize,
    /// The workspace generation it runs in: another search since then
    /// has overwritten its state.
    generation: u32,
    /// The cheapest loop closed so far (initially the search's bound).
    best: f32,
    found: Option<(f32, u32)>,
    /// Where `found` closed: (x, y, parent of reverse(y)), relaxing the
    /// arc x → y.
    meet: Option<(u32, u32, u32)>,
    finished: bool,
}

/// The loop engine: g and g′ built once per mesh, then queries.
pub struct LoopEngine {
    pub graph: ElasticaGraph,
    index: Option<SurfaceIndex>,
    disabled: Vec<bool>,
    covered: Vec<(u32, DVec3)>,
    boundary_field: Option<BoundaryField>,
    /// The radius the next hover query starts from: a little above the
    /// last answer's cost (consecutive hovers cost about the same).
    hover_radius: f32,
    has_boundary: bool,
    ws: Workspace,
    /// The state of [`LoopEngine::layered_cycle`]'s search.
    layered: LayeredWorkspace,
    /// The state of [`LoopEngine::two_anchor_loop`]'s searches.
    pair: PairWorkspace,
    /// The progressive hover query between its slices.
    hover_search: Option<HoverSearch>,
    /// Per vertex of g, the straight-line distance (normalised units) to
    /// the nearest boundary vertex: the guide of [`LoopEngine::curve_to_field`]
    /// (empty without a boundary).
    boundary_gap: Vec<f32>,
    /// The last [`RECENT_LOOPS`] exact answers of the hover query (nodes,
    /// closed), the most recent last: provisional loops are made of them
    /// ([`LoopEngine::recent_through`]); dropped when the enabled set
    /// changes.
    recent: Vec<RecentLoop>,
    /// Idle-time queries begun ([`LoopEngine::fill_recent`]).
    idle_queries: u64,
    /// Whether a hover with nothing else to show bridges to a recent loop
    /// ([`LoopEngine::recent_bridge`]; on by default, off for comparisons).
    pub bridge: bool,
}

/// A hover query answered progressively ([`LoopEngine::hover_begin`]):
/// the same answer as [`LoopEngine::best_loop`] with the distances from ∂
/// settled fully, computed by slices of a bounded number of settled g′
/// nodes.
#[derive(Debug, Clone)]
struct HoverSearch {
    v: usize,
    /// The cheapest dual curve through `v` in the distances from ∂ settled
    /// so far (cost, out-edge), in the order of `out_sources` …
    dual: Option<(f32, u32)>,
    /// … and whether no dual curve through `v` is cheaper (every curve
    /// below the settled radius is known).
    dual_proven: bool,
    /// The closed-loop search, once `dual` is proven (bounded by it).
    labelled: Option<LabelledSearch>,
    /// An idle-time query ([`LoopEngine::prepare_fields`] on a closed
    /// mesh), only for its answer among the recent ones: not a hover.
    idle: bool,
}

/// An exact answer of the hover query kept for provisional loops
/// ([`LoopEngine::recent_through`]), with the box of its nodes' ends and
/// its longest node (normalised units).
#[derive(Debug, Clone)]
struct RecentLoop {
    nodes: Vec<u32>,
    closed: bool,
    lo: Vec3,
    hi: Vec3,
    reach: f32,
}

/// The positions of node `x`'s ends (normalised units).
fn g_source(graph: &ElasticaGraph, x: u32) -> Vec3 {
    graph.position[graph.g.source[x as usize] as usize]
}
fn g_target(graph: &ElasticaGraph, x: u32) -> Vec3 {
    graph.position[graph.g.target[x as usize] as usize]
}

/// What one slice of a progressive hover query gives
/// ([`LoopEngine::hover_begin`], [`LoopEngine::hover_resume`]).
#[derive(Debug, Clone, PartialEq)]
pub enum HoverStep {
    /// Not finished: the cheapest loop or dual curve through the vertex
    /// found so far (a true loop of g′ with its true cost, not necessarily
    /// the best), if any.
    Provisional(Option<DualLoop>),
    /// Finished: the exact answer, [`LoopEngine::best_loop`]'s.
    Exact(Option<DualLoop>),
}

/// [`LoopEngine::two_anchor_loop`]: the distances from the second anchor's
/// candidates (kept across the searches of one query) and the second
/// half-search's state.
#[derive(Debug, Clone, Default)]
struct PairWorkspace {
    /// F(x): the distance from any candidate of the second anchor to x, over
    /// the nodes that are enabled or whose reverse is (so that F(reverse(·))
    /// bounds the distances of the forward and of the reversed searches).
    field: GrowingField,
    side: LayeredWorkspace,
    /// Per anchor of a loop through three or more positional anchors, the
    /// same kind of field from its candidates, settled fully
    /// ([`LoopEngine::guided_starts`]).
    fields: Vec<GrowingField>,
    /// Recent anchors' fields by vertex, the most recent last.
    cache: Vec<(u32, GrowingField)>,
}

/// The one settle loop of the engine's best-first searches: pops `heap` in
/// key order and stops at the first key at or above `*bound` (put back when
/// `keep`, so that the search can be resumed); every other entry goes to
/// `visit(node, heap, bound)`, which returns whether it settled the node
/// (false: a stale entry) and may lower `*bound`. Returns the number of
/// Settles node `x` of a growing field: marks it done and lowers the
/// distances of its arcs' heads, except heads that are disabled with
/// their reverse. False when `x` was settled already.
#[inline]
fn settle_node(
    graph: &ElasticaGraph,
    disabled: &[bool],
    dist: &mut [f32],
    done: &mut [bool],
    heap: &mut RadixHeap,
    x: usize,
) -> bool {
    if done[x] {
        return false;
    }
    done[x] = true;
    let g = &graph.g;
    let d = dist[x];
    graph.for_each_arc(x, |y, w| {
        let r = g.reverse[y];
        if disabled[y] && (r == NONE || disabled[r as usize]) {
            return;
        }
        let nd = d + w;
        if nd < dist[y] {
            dist[y] = nd;
            heap.push(nd.to_bits(), y as u32);
        }
    });
    true
}

/// nodes settled.
fn settle(
    heap: &mut RadixHeap,
    bound: &mut f32,
    keep: bool,
    mut visit: impl FnMut(u32, &mut RadixHeap, &mut f32) -> bool,
) -> u64 {
    let mut effort = 0u64;
    while let Some((k, x)) = heap.pop() {
        if f32::from_bits(k) >= *bound || bound.is_nan() {
            if keep {
                // At the last popped key: still a valid entry.
                heap.push(k, x);
            }
            break;
        }
        if visit(x, heap, bound) {
            effort += 1;
        }
    }
    effort
}

/// A multi-source Dijkstra over g′ settled up to a radius that grows on
/// demand (the heap is kept between the steps).
#[derive(Debug, Clone, Default)]
struct GrowingField {
    dist: Vec<f32>,
    done: Vec<bool>,
    heap: RadixHeap,
    /// Every node closer than this is settled (∞ once the heap is empty).
    radius: f32,
}

impl GrowingField {
    /// Starts a new field from `sources` (at distance 0).
    fn reset(&mut self, nodes: usize, sources: &[u32]) {
        self.dist.clear();
        self.dist.resize(nodes, f32::INFINITY);
        self.done.clear();
        self.done.resize(nodes, false);
        self.heap.clear();
        self.radius = 0.0;
        for &z in sources {
            self.dist[z as usize] = 0.0;
            self.heap.push(0f32.to_bits(), z);
        }
    }

    /// Settles every node closer than `radius`, skipping the nodes that are
    /// disabled and whose reverse is disabled too; returns how many it
    /// settled.
    fn grow(&mut self, graph: &ElasticaGraph, disabled: &[bool], radius: f32) -> u64 {
        if radius <= self.radius {
            return 0;
        }
        let (dist, done) = (&mut self.dist, &mut self.done);
        let mut bound = radius;
        let effort = settle(&mut self.heap, &mut bound, true, |x, heap, _| {
            settle_node(graph, disabled, dist, done, heap, x as usize)
        });
        self.radius = if self.heap.is_empty() {
            // Settled everywhere: the heap's buckets are not needed again.
            self.heap = RadixHeap::default();
            f32::INFINITY
        } else {
            radius
        };
        effort
    }

    /// Settles at most `budget` more nodes, nearest first, and sets the
    /// radius to the next distance (∞ once every node is settled): the same
    /// field as [`Self::grow`] to that radius. Returns how many it settled.
    fn grow_by(&mut self, graph: &ElasticaGraph, disabled: &[bool], budget: u64) -> u64 {
        if !self.radius.is_finite() || budget == 0 {
            return 0;
        }
        let (dist, done) = (&mut self.dist, &mut self.done);
        let mut bound = f32::INFINITY;
        let mut left = budget;
        let effort = settle(&mut self.heap, &mut bound, true, |x, heap, bound| {
            if !settle_node(graph, disabled, dist, done, heap, x as usize) {
                return false;
            }
            left -= 1;
            if left == 0 {
                // Stop at the next entry (put back).
                *bound = f32::NEG_INFINITY;
            }
            true
        });
        // Every entry below the next key has been popped: every node
        // closer than it is settled.
        match self.heap.pop() {
            Some((k, x)) => {
                self.heap.push(k, x);
                self.radius = self.radius.max(f32::from_bits(k));
            }
            None => {
                self.heap = RadixHeap::default();
                self.radius = f32::INFINITY;
            }
        }
        effort
    }

    /// The distance of `x`, or the radius when not settled (a lower bound).
    #[inline]
    fn value(&self, x: usize) -> f32 {
        if self.done[x] {
            self.dist[x]
        } else {
            self.radius
        }
    }

    /// [`Self::value`] of `reverse(x)` (0 where x has no reverse).
    #[inline]
    fn value_of_reverse(&self, g: &SurfaceGraph, x: usize) -> f32 {
        let r = g.reverse[x];
        if r == NONE {
            0.0
        } else {
            self.value(r as usize)
        }
    }
}

/// Per (g′ node, layer) state of the layered search
/// ([`LoopEngine::layered_cycle`]), indexed `layer · N + node`, stamped
/// like [`Workspace`] so that nothing has to be cleared between searches.
#[derive(Debug, Clone, Default)]
struct LayeredWorkspace {
    dist: Vec<f32>,
    parent: Vec<u32>,
    /// The source the path to the state started from.
    label: Vec<u32>,
    /// `2·generation` once reached, `2·generation + 1` once settled.
    state: Vec<u32>,
    generation: u32,
    heap: RadixHeap,
}

impl LayeredWorkspace {
    /// Starts a search over `states` states.
    fn start(&mut self, states: usize) -> u32 {
        if self.state.len() < states {
            self.dist.resize(states, f32::INFINITY);
            self.parent.resize(states, NONE);
            self.label.resize(states, NONE);
            self.state.resize(states, 0);
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 || self.generation >= 1 << 30 {
            self.state.iter_mut().for_each(|s| *s = 0);
            self.generation = 1;
        }
        self.heap.clear();
        self.generation
    }
}

/// The distance a single-layer search settled at `x` (∞ if it did not).
fn settled_dist(ws: &LayeredWorkspace, x: u32) -> f32 {
    let x = x as usize;
    if ws.state.get(x) == Some(&(2 * ws.generation + 1)) {
        ws.dist[x]
    } else {
        f32::INFINITY
    }
}

/// The nodes of the path a single-layer search found to `x`, source first.
fn path_to(ws: &LayeredWorkspace, x: u32) -> Vec<u32> {
    let mut path = Vec::new();
    let mut at = x;
    while at != NONE && path.len() <= ws.parent.len() {
        path.push(at);
        at = ws.parent[at as usize];
    }
    path.reverse();
    path
}

/// One A* over g′ (a single layer) from `sources` (node, initial cost),
/// skipping the `blocked` nodes, with the consistent heuristic `h`, pruned
/// at `bound`; `on_settle(x, d, bound)` sees every settled node and may
/// lower the bound. Parents and distances stay in `ws` ([`settled_dist`],
/// [`path_to`]). Returns the number of nodes settled.
fn astar(
    graph: &ElasticaGraph,
    ws: &mut LayeredWorkspace,
    sources: &[(u32, f32)],
    blocked: impl Fn(usize) -> bool,
    h: impl Fn(usize) -> f32,
    bound: f32,
    mut on_settle: impl FnMut(usize, f32, &mut f32),
) -> u64 {
    let now = ws.start(graph.node_count());
    let (reached, settled) = (2 * now, 2 * now + 1);
    if bound.is_nan() || bound <= 0.0 {
        return 0;
    }
    for &(source, c) in sources {
        let src = source as usize;
        if source == NONE || blocked(src) || c.is_nan() || c >= bound {
            continue;
        }
        if ws.state[src] < reached || c < ws.dist[src] {
            ws.state[src] = reached;
            ws.dist[src] = c;
            ws.parent[src] = NONE;
            ws.heap.push((c + h(src)).to_bits(), source);
        }
    }
    let LayeredWorkspace {
        dist,
        parent,
        state,
        heap,
        ..
    } = ws;
    let mut bound = bound;
    settle(heap, &mut bound, false, |x, heap, bound| {
        let x = x as usize;
        if state[x] == settled {
            return false;
        }
        state[x] = settled;
        let d = dist[x];
        on_settle(x, d, bound);
        let cap = *bound;
        graph.for_each_arc(x, |y, w| {
            if blocked(y) {
                return;
            }
            let nd = d + w;
            if state[y] < reached || nd < dist[y] {
                let key = nd + h(y);
                if key.is_nan() || key >= cap {
                    return;
                }
                state[y] = reached;
                dist[y] = nd;
                parent[y] = x as u32;
                heap.push(key.to_bits(), y as u32);
            }
        });
        true
    })
}

/// The path of a layered search ([`LoopEngine::layered_search`]) to state
/// `end` (`nodes` per layer, `n` anchors; for a closed loop without the
/// closing state): its g′ nodes and the position where each layer begins.
fn layered_path_to(
    ws: &LayeredWorkspace,
    end: u32,
    nodes: usize,
    n: usize,
    closed: bool,
) -> (Vec<u32>, Vec<usize>) {
    let mut states = path_to(ws, end);
    if closed {
        states.pop();
    }
    let mut starts = vec![0usize; n];
    for (i, w) in states.windows(2).enumerate() {
        let (la, lb) = (w[0] as usize / nodes, w[1] as usize / nodes);
        if lb != la && lb < n {
            starts[lb] = i + 1;
        }
    }
    let path = states
        .iter()
        .map(|&s| (s as usize % nodes) as u32)
        .collect();
    (path, starts)
}

/// How a layered search ends: back at the node its path started from
/// after the last layer (a closed loop), or at the last anchor, leaving to
/// ∂ at the given cost per candidate of the last layer (a dual curve, §5.7).
enum LayeredEnd<'a> {
    Closed,
    Open(&'a [f32]),
}

impl LoopEngine {
    /// Builds g (k-ring graph) and g′ for `mesh`. Never panics; an empty or
    /// degenerate mesh yields an engine that returns no loops.
    pub fn new(mesh: &TriMesh, params: &ElasticaParams) -> LoopEngine {
        let g = SurfaceGraph::new(mesh, params.rings);
        let index = SurfaceIndex::new(&g.mesh);
        let has_boundary = g.boundary.iter().any(|&b| b);
        let graph = ElasticaGraph::new(g, params);
        let nodes = graph.node_count();
        let mut engine = LoopEngine {
            graph,
            index,
            disabled: vec![false; nodes],
            covered: Vec::new(),
            boundary_field: None,
            hover_radius: BOUNDARY_RADIUS,
            has_boundary,
            ws: Workspace {
                slot: vec![Slot::default(); nodes],
                slot_b: vec![SlotB::default(); nodes],
                mirror: vec![Mirror::default(); nodes],
                ..Workspace::default()
            },
            layered: LayeredWorkspace::default(),
            pair: PairWorkspace::default(),
            hover_search: None,
            boundary_gap: Vec::new(),
            recent: Vec::new(),
            idle_queries: 0,
            bridge: true,
        };
        if engine.has_boundary {
            // What a provisional dual curve needs, made here rather than in
            // the first hover, which meets them.
            engine.boundary_gap = engine.boundary_gaps();
            engine.layered.start(nodes);
        }
        engine
    }

    /// Bytes held by g, g′ and the query buffers (excluding the BVH).
    pub fn memory_bytes(&self) -> usize {
        let n = self.graph.node_count();
        self.graph.memory_bytes()
            + n * (std::mem::size_of::<Slot>()
                + std::mem::size_of::<SlotB>()
                + std::mem::size_of::<Mirror>()
                + 1)
            + self.boundary_field.as_ref().map_or(0, |f| f.dist.len() * 9)
            + self
                .pair
                .cache
                .iter()
                .map(|c| c.1.dist.len() * 5)
                .sum::<usize>()
    }

    /// Number of g′-nodes settled by the hover and loop searches since the
    /// engine was built (an effort measure for benchmarks).
    pub fn settled_nodes(&self) -> u64 {
        self.ws.effort
    }

    /// The vertex of g nearest to a world position (via the closest face).
    pub fn nearest_vertex(&self, world: DVec3) -> Option<usize> {
        let g = &self.graph.g;
        let p = g.to_local(world);
        if let Some(index) = &self.index {
            let c = index.closest(p);
            let t = g.mesh.triangles.get(c.face as usize)?;
            return t.iter().map(|&v| v as usize).min_by(|&a, &b| {
                let da = g.mesh.positions[a].distance_squared(c.point);
                let db = g.mesh.positions[b].distance_squared(c.point);
                da.total_cmp(&db).then(a.cmp(&b))
            });
        }
        (0..g.vertex_count()).min_by(|&a, &b| {
            g.mesh.positions[a]
                .distance_squared(p)
                .total_cmp(&g.mesh.positions[b].distance_squared(p))
        })
    }

    /// The best dual loop (or dual curve) through one positional anchor.
    pub fn best_loop(&mut self, position: DVec3) -> Option<DualLoop> {
        let v = self.nearest_vertex(position)?;
        let (cost, kind) = self.best_through(v, f32::INFINITY)?;
        Some(self.make_loop(kind, cost))
    }

    /// The hover query answered progressively (§4.1's hover, with the
    /// exact answer of [`Self::best_loop`] as it is once the distances from
    /// ∂ are settled fully): settles at most `budget` g′ nodes, then gives
    /// either the exact answer or the cheapest loop or dual curve found so
    /// far, to be shown until [`Self::hover_resume`] finishes. Forgets a
    /// hover query still unfinished.
    ///
    /// The search runs in three steps: the distances from ∂ are grown until
    /// the cheapest dual curve through the vertex is proven (cheaper than
    /// the settled radius, or the field complete), then the labelled
    /// closed-loop search bounded by it, then the exact refinement of the
    /// best few directions (not budgeted: about 2 % of a query). Another
    /// query of the engine between two slices restarts the labelled search
    /// (it shares the workspace); the distances from ∂ are kept.
    pub fn hover_begin(&mut self, position: DVec3, budget: u64) -> HoverStep {
        self.hover_search = None;
        let Some(v) = self.nearest_vertex(position) else {
            return HoverStep::Exact(None);
        };
        self.hover_search = Some(HoverSearch {
            v,
            dual: None,
            dual_proven: !self.has_boundary,
            labelled: None,
            idle: false,
        });
        self.hover_step(budget, true)
    }

    /// Resumes the hover query of [`Self::hover_begin`] for at most
    /// `budget` more settled nodes. `None` when it is still unfinished
    /// (nothing is built for showing) or when there is none (see
    /// [`Self::hover_pending`]).
    pub fn hover_resume(&mut self, budget: u64) -> Option<Option<DualLoop>> {
        self.hover_search.as_ref().filter(|h| !h.idle)?;
        match self.hover_step(budget, false) {
            HoverStep::Exact(l) => Some(l),
            HoverStep::Provisional(_) => None,
        }
    }

    /// Whether a hover query of [`Self::hover_begin`] is unfinished.
    pub fn hover_pending(&self) -> bool {
        self.hover_search.as_ref().is_some_and(|h| !h.idle)
    }

    /// Forgets an unfinished hover query.
    pub fn cancel_hover(&mut self) {
        self.hover_search = None;
    }

    /// One slice of the progressive hover query; builds the provisional
    /// loop only when `show`.
    fn hover_step(&mut self, budget: u64, show: bool) -> HoverStep {
        let Some(mut hs) = self.hover_search.take() else {
            return HoverStep::Exact(None);
        };
        let v = hs.v;
        let mut left = budget;
        while !hs.dual_proven {
            hs.dual = None;
            let mut radius = 0.0;
            if let Some(f) = &self.boundary_field {
                radius = f.radius;
                let mut limit = f32::INFINITY;
                for b in self.out_sources(v) {
                    let r = self.graph.g.reverse[b as usize];
                    if r == NONE {
                        continue;
                    }
                    let c = f.distance(b) + f.distance(r);
                    if c < limit {
                        limit = c;
                        hs.dual = Some((c, b));
                    }
                }
            }
            // Every dual curve cheaper than the radius has both halves
            // settled, so one found below it is the cheapest.
            if radius == f32::INFINITY || hs.dual.is_some_and(|(c, _)| c < radius) {
                hs.dual_proven = true;
                break;
            }
            if left == 0 {
                return self.hover_pause(hs, show, budget);
            }
            let used = self.grow_boundary(f32::INFINITY, left);
            left -= used.min(left);
        }
        let limit = hs.dual.map_or(f32::INFINITY, |(c, _)| c);
        let stale = hs
            .labelled
            .as_ref()
            .is_none_or(|l| l.generation != self.ws.generation);
        if stale {
            hs.labelled = self.labelled_start(v, limit);
        }
        let closed = match hs.labelled.as_mut() {
            None => None,
            Some(search) => {
                self.labelled_run(search, left);
                if !search.finished {
                    return self.hover_pause(hs, show, budget);
                }
                let found = search.found;
                found.and_then(|(approx, _)| self.refine_directions(v, limit, approx))
            }
        };
        let best = closed.or(hs.dual.map(|(c, b)| (c, Kind::Open(b))));
        if let Some((c, _)) = &best {
            self.hover_radius = (1.25 * c).max(BOUNDARY_RADIUS);
        }
        let exact = best.map(|(c, k)| self.make_loop(k, c));
        if let Some(l) = &exact {
            if self.recent.len() >= RECENT_LOOPS {
                self.recent.remove(0);
            }
            let (lo, hi) = l.nodes.iter().fold(
                (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
                |(lo, hi), &x| {
                    let (a, b) = (g_source(&self.graph, x), g_target(&self.graph, x));
                    (lo.min(a).min(b), hi.max(a).max(b))
                },
            );
            let g = &self.graph.g;
            let reach = l
                .nodes
                .iter()
                .map(|&x| g.length[x as usize])
                .fold(0.0, f32::max);
            self.recent.push(RecentLoop {
                nodes: l.nodes.clone(),
                closed: l.closed,
                lo,
                hi,
                reach,
            });
        }
        HoverStep::Exact(exact)
    }

    /// Keeps the unfinished hover query; the cheapest loop or dual curve
    /// found so far when `show`. When the search has found none yet
    /// because the distances from ∂ do not reach `v` (the first hovers of
    /// the mode, before the idle time has settled them), a dual curve
    /// through `v` to where they do reach ([`Self::provisional_curve`],
    /// at most `budget` nodes per half).
    fn hover_pause(&mut self, hs: HoverSearch, show: bool, budget: u64) -> HoverStep {
        let mut shown: Option<(f32, Kind)> = None;
        if show {
            shown = hs.dual.map(|(c, b)| (c, Kind::Open(b)));
            if let Some(l) = hs
                .labelled
                .as_ref()
                .filter(|l| l.generation == self.ws.generation)
            {
                if let (Some((c, _)), Some(meet)) = (l.found, l.meet) {
                    if shown.as_ref().is_none_or(|(d, _)| c < *d) {
                        shown = Some((c, Kind::Closed(self.labelled_loop(meet))));
                    }
                }
            }
        }
        let v = hs.v;
        let dual_proven = hs.dual_proven;
        self.hover_search = Some(hs);
        if !show {
            return HoverStep::Provisional(None);
        }
        // Only when the search itself has nothing to show.
        let mut best = match shown {
            Some((c, k)) => Some(self.make_loop(k, c)),
            None => self.recent_through(v),
        };
        if best.is_none() && self.bridge {
            best = self.recent_bridge(v);
        }
        if best.is_none() && !dual_proven {
            best = self.provisional_curve(v, budget);
        }
        HoverStep::Provisional(best)
    }

    /// A true loop or dual curve through `v` made of a recent exact answer
    /// of the hover query ([`Self::recent`]): the answer itself when it
    /// passes through `v`, else with one or two of its nodes, from `a` to
    /// `c`, replaced by the g-edges `a → v → c` where those exist, are
    /// enabled and turn within the limit (`v` within the k rings of g of
    /// both). The cheapest such walk (its cost summed over its arcs), if
    /// any. The ends of a dual curve, on the boundary, are kept.
    fn recent_through(&self, v: usize) -> Option<DualLoop> {
        let graph = &self.graph;
        let g = &graph.g;
        let edge = |a: usize, b: usize| {
            g.out_edges(a)
                .find(|&e| g.target[e] as usize == b && !self.disabled[e])
        };
        let pv = graph.position[v];
        let mut best: Option<(f64, Vec<u32>, bool)> = None;
        let mut offer = |cost: f64, nodes: Vec<u32>, closed: bool| {
            if best.as_ref().is_none_or(|b| cost < b.0) {
                best = Some((cost, nodes, closed));
            }
        };
        for r in &self.recent {
            let (nodes, closed) = (r.nodes.as_slice(), r.closed);
            let m = nodes.len();
            let outside = (r.lo - pv).max(pv - r.hi).max(Vec3::ZERO).length();
            // Farther than its longest node from every node end: no splice.
            if m < 3 || outside > r.reach {
                continue;
            }
            if nodes.iter().any(|&x| g.source[x as usize] as usize == v) {
                offer(self.walk_weight(nodes, closed), nodes.to_vec(), closed);
                continue;
            }
            // Nodes i … i + span − 1 replaced; a dual curve keeps its ends.
            let (first, last) = if closed { (0, m) } else { (1, m - 1) };
            for span in 1..=2usize {
                for i in first..last {
                    if !closed && i + span > last {
                        break;
                    }
                    let (x, z) = (nodes[i] as usize, nodes[(i + span - 1) % m] as usize);
                    let (a, c) = (g.source[x] as usize, g.target[z] as usize);
                    let reach = g.length[x].max(g.length[z]);
                    if a == v || c == v || a == c || graph.position[a].distance(pv) > reach {
                        continue;
                    }
                    let (Some(e1), Some(e2)) = (edge(a, v), edge(v, c)) else {
                        continue;
                    };
                    let prev = nodes[(i + m - 1) % m] as usize;
                    let next = nodes[(i + span) % m] as usize;
                    if !(graph.is_arc(prev, e1) && graph.is_arc(e1, e2) && graph.is_arc(e2, next)) {
                        continue;
                    }
                    let mut spliced: Vec<u32> = Vec::with_capacity(m + 2);
                    if closed {
                        spliced.extend([e1 as u32, e2 as u32]);
                        spliced.extend((i + span..i + m).map(|k| nodes[k % m]));
                    } else {
                        spliced.extend_from_slice(&nodes[..i]);
                        spliced.extend([e1 as u32, e2 as u32]);
                        spliced.extend_from_slice(&nodes[i + span..]);
                    }
                    offer(self.walk_weight(&spliced, closed), spliced, closed);
                }
            }
        }
        let (cost, mut nodes, closed) = best?;
        if closed {
            // Starting at `v`, as the exact search's loops do (so that an
            // exact answer equal to it is the same node sequence).
            let at = nodes
                .iter()
                .position(|&x| g.source[x as usize] as usize == v);
            nodes.rotate_left(at.unwrap_or(0));
        }
        Some(self.loop_from_nodes(nodes, cost, closed))
    }

    /// A true closed loop through `v` made of a recent closed answer that
    /// passes near it but not through it, where [`Self::recent_through`]'s
    /// splices find none: a walk from an out-edge `b` of `v` onto one of
    /// the nearest [`BRIDGE_LOOPS`] recent loops, in either orientation
    /// (the cheapest node of it first reached, Dijkstra from every
    /// out-edge), along that loop, and back into `v` through `b`: the walk
    /// from `reverse(b)` onto the loop's reverse, reversed (both searches
    /// at most [`BRIDGE_NODES`] settled nodes; for each of the first
    /// [`BRIDGE_TRIES`] loops reached, the cheapest return in the sum of
    /// both walks and the part of the loop between them). A walk of
    /// enabled g′ arcs with its true cost (summed over its arcs), not the
    /// cheapest loop through `v`; `None` when no recent loop is reached.
    fn recent_bridge(&mut self, v: usize) -> Option<DualLoop> {
        let pv = self.graph.position[v];
        let mut near: Vec<(f32, usize)> = self
            .recent
            .iter()
            .enumerate()
            .filter(|(_, r)| r.closed && r.nodes.len() >= 3)
            .map(|(k, r)| {
                let gap = r
                    .nodes
                    .iter()
                    .map(|&x| g_source(&self.graph, x).distance_squared(pv))
                    .fold(f32::INFINITY, f32::min);
                (gap, k)
            })
            .collect();
        near.sort_by(|a, b| a.0.total_cmp(&b.0));
        near.truncate(BRIDGE_LOOPS);
        if near.is_empty() {
            return None;
        }
        let g = &self.graph.g;
        // Each near loop in both orientations: (loop, reversed) → nodes.
        let mut oriented: Vec<Vec<u32>> = Vec::with_capacity(2 * near.len());
        for &(_, k) in &near {
            let nodes = &self.recent[k].nodes;
            if nodes.iter().any(|&x| g.reverse[x as usize] == NONE) {
                oriented.extend([nodes.clone(), Vec::new()]);
            } else {
                oriented.push(nodes.clone());
                oriented.push(nodes.iter().rev().map(|&x| g.reverse[x as usize]).collect());
            }
        }
        // node → (oriented loop, position in it)
        let mut at: std::collections::HashMap<u32, Vec<(u32, u32)>> =
            std::collections::HashMap::new();
        for (o, nodes) in oriented.iter().enumerate() {
            for (i, &x) in nodes.iter().enumerate() {
                at.entry(x).or_default().push((o as u32, i as u32));
            }
        }
        let sources: Vec<(u32, f32)> = self.out_sources(v).into_iter().map(|b| (b, 0.0)).collect();
        // Leaving: the first node of each oriented loop reached, until
        // BRIDGE_TRIES loops are reached in both orientations (a loop
        // reached both ways, from out-edges leaving in opposite directions,
        // passes by on both sides of `v`) or BRIDGE_NODES nodes are settled.
        let mut hits: Vec<(u32, u32, u32, f32)> = Vec::new(); // (oriented loop, position, node, distance)
        let mut both = 0usize;
        let mut left = BRIDGE_NODES;
        let disabled = &self.disabled;
        let graph = &self.graph;
        self.ws.effort += astar(
            graph,
            &mut self.layered,
            &sources,
            |x| disabled[x],
            |_| 0.0,
            f32::INFINITY,
            |x, d, bound| {
                if let Some(list) = at.get(&(x as u32)) {
                    for &(o, i) in list {
                        if hits.iter().all(|h| h.0 != o) {
                            both += usize::from(hits.iter().any(|h| h.0 == o ^ 1));
                            hits.push((o, i, x as u32, d));
                        }
                    }
                }
                left = left.saturating_sub(1);
                if left == 0 || both >= BRIDGE_TRIES {
                    *bound = f32::NEG_INFINITY;
                }
            },
        );
        // Loops reached both ways first (by the sum of both distances),
        // then the others (by their distance).
        let estimate = |h: &(u32, u32, u32, f32)| {
            hits.iter()
                .find(|k| k.0 == h.0 ^ 1)
                .map_or(f32::INFINITY, |k| h.3 + k.3)
        };
        let mut order: Vec<(f32, f32, usize)> = hits
            .iter()
            .enumerate()
            .map(|(n, h)| (estimate(h), h.3, n))
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        order.truncate(BRIDGE_TRIES);
        let hits: Vec<(u32, u32, u32, f32)> = order.iter().map(|o| hits[o.2]).collect();
        let leaves: Vec<Vec<u32>> = hits.iter().map(|h| path_to(&self.layered, h.2)).collect();
        let mut best: Option<(f64, Vec<u32>)> = None;
        for (h, leave) in hits.iter().zip(&leaves) {
            let (o, i) = (h.0 as usize, h.1 as usize);
            let Some((cost, nodes)) = self.bridge_back(&oriented, o, i, leave, &at) else {
                continue;
            };
            if best.as_ref().is_none_or(|(c, _)| cost < *c) {
                best = Some((cost, nodes));
            }
        }
        let (cost, nodes) = best?;
        Some(self.loop_from_nodes(nodes, cost, true))
    }

    /// [`Self::recent_bridge`]'s way back: `leave` runs from an out-edge
    /// `b` of the vertex to `oriented[o][i]`; the walk from `reverse(b)`
    /// onto the loop's reverse (`oriented[o ^ 1]`, the cheapest return in
    /// the sum of both walks and the part of the loop between them, at most
    /// [`BRIDGE_NODES`] settled nodes), and the closed walk b … lo[i] …
    /// lo[j] … back into `b` with its cost, if it is one of enabled arcs.
    fn bridge_back(
        &mut self,
        oriented: &[Vec<u32>],
        o: usize,
        i: usize,
        leave: &[u32],
        at: &std::collections::HashMap<u32, Vec<(u32, u32)>>,
    ) -> Option<(f64, Vec<u32>)> {
        let lo = &oriented[o];
        let m = lo.len();
        let back_o = o ^ 1;
        if oriented[back_o].len() != m || leave.is_empty() {
            return None;
        }
        let b = leave[0];
        let r = self.graph.g.reverse[b as usize];
        if r == NONE || self.disabled[r as usize] {
            return None;
        }
        // The loop's arc weights from position i onwards.
        let mut from_i = vec![0f32; m];
        for s in 1..m {
            let (a, c) = (lo[(i + s - 1) % m], lo[(i + s) % m]);
            from_i[(i + s) % m] =
                from_i[(i + s - 1) % m] + self.graph.arc_weight(a as usize, c as usize);
        }
        // Entering: from reverse(b) onto the loop's reverse, where
        // reverse(z) = lo[j], z at position m − 1 − j of the reverse.
        let leave_cost = self.walk_weight(leave, false) as f32;
        let mut found: Option<(f32, u32, usize)> = None;
        let mut left = BRIDGE_NODES;
        let graph = &self.graph;
        let disabled = &self.disabled;
        self.ws.effort += astar(
            graph,
            &mut self.layered,
            &[(r, 0.0)],
            |x| disabled[x],
            |_| 0.0,
            f32::INFINITY,
            |x, d, bound| {
                if let Some(list) = at.get(&(x as u32)) {
                    for &(_, k) in list.iter().filter(|e| e.0 as usize == back_o) {
                        let j = m - 1 - k as usize;
                        let total = leave_cost + d + from_i[j];
                        if found.is_none() {
                            // Returns much dearer than the first are
                            // not looked for.
                            *bound = bound.min(2.0 * d.max(leave_cost).max(LEVEL_STEP));
                        }
                        if found.is_none_or(|f| total < f.0) {
                            found = Some((total, x as u32, j));
                            *bound = bound.min(total - leave_cost);
                        }
                    }
                }
                left = left.saturating_sub(1);
                if left == 0 {
                    *bound = f32::NEG_INFINITY;
                }
            },
        );
        let (_, z, j) = found?;
        let enter = path_to(&self.layered, z);
        let g = &self.graph.g;
        // b … lo[i], lo[i+1] … lo[j], then reverse(enter) without
        // lo[j] and without b (the loop's first node).
        let mut nodes = leave.to_vec();
        let mut s = i;
        while s != j {
            s = (s + 1) % m;
            nodes.push(lo[s]);
        }
        let back: Vec<u32> = enter.iter().rev().map(|&x| g.reverse[x as usize]).collect();
        if back.len() >= 2 {
            nodes.extend_from_slice(&back[1..back.len() - 1]);
        }
        if !self.is_enabled_cycle(&nodes) {
            return None;
        }
        Some((self.walk_weight(&nodes, true), nodes))
    }

    /// Whether `nodes` is a closed walk of enabled g′ nodes and arcs.
    fn is_enabled_cycle(&self, nodes: &[u32]) -> bool {
        let m = nodes.len();
        m >= 2
            && (0..m).all(|i| {
                let (a, c) = (nodes[i] as usize, nodes[(i + 1) % m] as usize);
                !self.disabled[a] && self.graph.is_arc(a, c)
            })
    }

    /// A true dual curve through `v` (a walk of enabled g′ arcs from ∂ to ∂
    /// with its true cost, not necessarily the cheapest) while the
    /// distances from ∂ do not reach `v`: the cheapest way from an
    /// out-edge `b` of `v` to a node whose reverse the field has reached
    /// (settled or not: its parents are a true path from ∂), then the same
    /// from `reverse(b)`, each by an A* of at most `budget` settled nodes
    /// guided by the straight-line distance to the boundary (weighted by
    /// [`PROVISIONAL_GUIDE`]). `None` when either half finds nothing.
    fn provisional_curve(&mut self, v: usize, budget: u64) -> Option<DualLoop> {
        let g = &self.graph.g;
        let sources: Vec<u32> = self
            .out_sources(v)
            .into_iter()
            .filter(|&b| g.reverse[b as usize] != NONE)
            .collect();
        let (leave, b) = self.curve_to_field(&sources, budget)?;
        let r = self.graph.g.reverse[b as usize];
        let (enter, _) = self.curve_to_field(&[r], budget)?;
        let g = &self.graph.g;
        let back = |walk: &[u32]| -> Vec<u32> {
            walk.iter().rev().map(|&x| g.reverse[x as usize]).collect()
        };
        // ∂ … reverse(y₂), reversed: reverse(y₂) … b, then b … y₁, then
        // y₁ … ∂ (the field's path to reverse(y₁), reversed).
        let mut nodes = self.boundary_path(g.reverse[*enter.last()? as usize]);
        nodes.extend(back(&enter).into_iter().skip(1));
        nodes.extend(leave.iter().skip(1));
        let tail = self.boundary_path(g.reverse[*leave.last()? as usize]);
        nodes.extend(back(&tail).into_iter().skip(1));
        if nodes.contains(&NONE) {
            return None;
        }
        let cost = self.walk_weight(&nodes, false);
        Some(self.loop_from_nodes(nodes, cost, false))
    }

    /// The cost of a walk of g′: the weights of its arcs (for a closed loop
    /// also the arc from the last node back to the first).
    fn walk_weight(&self, nodes: &[u32], closed: bool) -> f64 {
        let m = nodes.len();
        let arcs = if closed { m } else { m.saturating_sub(1) };
        (0..arcs)
            .map(|i| {
                let (a, b) = (nodes[i] as usize, nodes[(i + 1) % m] as usize);
                self.graph.arc_weight(a, b) as f64
            })
            .sum()
    }

    /// [`Self::provisional_curve`]'s half: the cheapest walk (A*, at most
    /// `budget` settled nodes) from `sources` to a node `y` whose reverse
    /// the distances from ∂ have reached, counting the field's distance of
    /// `reverse(y)`. Returns the walk (a source first, `y` last) and the
    /// source it starts from.
    fn curve_to_field(&mut self, sources: &[u32], budget: u64) -> Option<(Vec<u32>, u32)> {
        let field = self.boundary_field.as_ref()?;
        let graph = &self.graph;
        let g = &graph.g;
        let gap = &self.boundary_gap;
        let disabled = &self.disabled;
        let starts: Vec<(u32, f32)> = sources.iter().map(|&s| (s, 0.0)).collect();
        let mut best: Option<(f32, u32)> = None;
        let mut left = budget;
        let effort = astar(
            graph,
            &mut self.layered,
            &starts,
            |x| disabled[x],
            |x| PROVISIONAL_GUIDE * gap[g.target[x] as usize],
            f32::INFINITY,
            |x, d, bound| {
                let r = g.reverse[x];
                if r != NONE {
                    let total = d + field.dist[r as usize];
                    if total < *bound {
                        *bound = total;
                        best = Some((total, x as u32));
                    }
                }
                left = left.saturating_sub(1);
                if left == 0 {
                    *bound = f32::NEG_INFINITY;
                }
            },
        );
        self.ws.effort += effort;
        let (_, y) = best?;
        let walk = path_to(&self.layered, y);
        let first = *walk.first()?;
        Some((walk, first))
    }

    /// [`Self::boundary_gap`]: per vertex, the distance to the nearest
    /// boundary vertex (∞ without a boundary).
    fn boundary_gaps(&self) -> Vec<f32> {
        let g = &self.graph.g;
        let position = &self.graph.position;
        let rim: Vec<Vec3> = (0..g.vertex_count())
            .filter(|&v| g.boundary[v])
            .map(|v| position[v])
            .collect();
        position
            .iter()
            .map(|p| {
                rim.iter()
                    .map(|q| p.distance_squared(*q))
                    .fold(f32::INFINITY, f32::min)
                    .sqrt()
            })
            .collect()
    }

    /// The loop the labelled search closed relaxing x → y, reverse(y)
    /// reached from `p`: s … x, y, reverse(p) … reverse(s′) (the closing
    /// arc reverse(s′) → s implied), as `cycle_through` leaves it.
    fn labelled_loop(&self, (x, y, p): (u32, u32, u32)) -> Vec<u32> {
        let g = &self.graph.g;
        let slot = &self.ws.slot;
        let chain = |last: u32| {
            let mut out = Vec::new();
            let mut z = last;
            while z != NONE && out.len() <= slot.len() {
                out.push(z);
                z = slot[z as usize].parent;
            }
            out.reverse();
            out
        };
        let mut path = chain(x);
        path.push(y);
        if p != NONE {
            path.extend(chain(p).iter().rev().map(|&z| g.reverse[z as usize]));
        }
        path
    }

    /// The best loop and ranked alternatives through one positional anchor,
    /// one per direction class, best first (at most `max` of them).
    pub fn loops_through(&mut self, position: DVec3, max: usize) -> Vec<DualLoop> {
        let Some(v) = self.nearest_vertex(position) else {
            return Vec::new();
        };
        if max == 0 {
            return Vec::new();
        }
        let Some((best, _)) = self.best_through(v, f32::INFINITY) else {
            return Vec::new();
        };
        // Every direction's own best loop (§5.4: the |ξ₀| runs are the
        // alternatives), kept only below a generous multiple of the best.
        let bound = (6.0 * best).max(best + 0.05);
        let mut found: Vec<(f32, f32, Kind)> = Vec::new();
        for b in self.out_sources(v) {
            let angle = self.graph.g.angle_out[b as usize];
            let mut kind_best: Option<(f32, Kind)> = None;
            if let Some((c, k)) = self.open_curve(b, bound) {
                kind_best = Some((c, k));
            }
            let limit = kind_best.as_ref().map_or(bound, |(c, _)| c.min(bound));
            if let Some(c) = self.cycle_through(b, limit) {
                kind_best = Some((c, Kind::Closed(self.ws.path.clone())));
            }
            if let Some((c, k)) = kind_best {
                if c <= bound {
                    found.push((c, angle, k));
                }
            }
        }
        found.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        let class = 25f32.to_radians();
        let mut kept: Vec<(f32, f32, Kind)> = Vec::new();
        for f in found {
            let same = kept.iter().any(|k| {
                let d = (f.1 - k.1).rem_euclid(std::f32::consts::PI);
                d.min(std::f32::consts::PI - d) < class
            });
            if !same {
                kept.push(f);
                if kept.len() >= max {
                    break;
                }
            }
        }
        kept.into_iter()
            .map(|(c, _, k)| self.make_loop(k, c))
            .collect()
    }

    /// The minimum-cost loop (or dual curve) interpolating `anchors` in order
    /// (§5.4, §5.7). `None` when no such loop exists in g′.
    pub fn constrained_loop(&mut self, anchors: &[Anchor]) -> Option<DualLoop> {
        if anchors.is_empty() {
            return None;
        }
        let n = anchors.len();
        let mut verts = Vec::with_capacity(n);
        let mut layers: Vec<Vec<u32>> = Vec::with_capacity(n);
        for a in anchors {
            let v = self.nearest_vertex(a.position)?;
            verts.push(v);
            layers.push(self.candidate_edges(v, a.direction));
            if layers.last().is_none_or(|l| l.is_empty()) {
                return None;
            }
        }
        // A directional anchor's tangent is the bisector of the arriving and
        // leaving g-edges: the arc into it may turn at most half the limit.
        let close: Vec<f32> = anchors
            .iter()
            .map(|a| {
                if a.direction == DVec3::ZERO {
                    f32::INFINITY
                } else {
                    0.5 * self.graph.max_turn
                }
            })
            .collect();
        // One positional anchor: the hover query's loop (§4.1: a click
        // keeps the loop shown while hovering), not |ξ₀| full searches.
        if n == 1 && anchors[0].direction == DVec3::ZERO {
            let (cost, kind) = self.best_through(verts[0], f32::INFINITY)?;
            return Some(self.make_loop(kind, cost));
        }
        let (cost, nodes, closed) = self.layered_cycle(&verts, &layers, &close)?;
        Some(self.loop_from_nodes(nodes, cost as f64, closed))
    }

    /// The minimum-cost loop through the anchors' candidate layers in order
    /// (§5.4's metagraph cycle, and with a boundary the cheapest ∂ → ξ₀ →
    /// … → ξ_{n−1} → ∂ dual curve of §5.7) as ONE A* per start candidate
    /// over a layered copy of g′: state (x, l) is node x having passed the
    /// anchors 1…l. From (x, l) every arc x → y leads to (y, l); when x ends
    /// at the next anchor's vertex and y is one of its candidates (turning
    /// at most its `close` limit), the arc also leads to (y, l + 1). The
    /// closed loop runs from (a₀, 0) to (a₀, n) for each a₀ of the smallest
    /// layer ([`Self::multi_start_cycle`]; for two positional anchors
    /// [`Self::two_anchor_loop`] instead); the dual curve
    /// from every (b, 0) at its distance from ∂ to some (a, n − 1) plus a's
    /// distance to ∂. The same optimum as the metagraph of all pairwise
    /// searches (tested against it), without searching every pair.
    /// Returns the cost, the g′ nodes in order (starting at anchor 0's
    /// candidate for a loop; from ∂ to ∂ for a dual curve) and whether the
    /// loop is closed.
    fn layered_cycle(
        &mut self,
        verts: &[usize],
        layers: &[Vec<u32>],
        close: &[f32],
    ) -> Option<(f32, Vec<u32>, bool)> {
        let n = layers.len();
        if n == 0 || layers.iter().any(|l| l.is_empty()) {
            return None;
        }
        let s = (0..n).min_by_key(|&i| (layers[i].len(), i)).unwrap_or(0);
        let rotated: Vec<usize> = (0..n).map(|k| (s + k) % n).collect();
        // Two positional anchors: the loop or dual curve by half-searches.
        if let Some(found) = self.two_anchor_loop(verts, layers, close, true) {
            return found;
        }
        // Three or more positional anchors on distinct consecutive
        // vertices: every search guided by the anchors' fields; with a
        // boundary the dual curve right after the first start's loop,
        // bounded by it and bounding the other starts' searches.
        let positional =
            close.iter().all(|c| !c.is_finite()) && (0..n).all(|k| verts[k] != verts[(k + 1) % n]);
        let mut best: Option<(f32, Vec<u32>, bool)> = None;
        if positional && n >= 3 {
            self.take_anchor_fields(verts);
            let open = self.has_boundary;
            self.guided_starts(verts, layers, close, s, &rotated, open, &mut best);
            self.return_anchor_fields(verts);
            return best;
        }
        // Any other anchors: the closed loop by layered searches from the
        // starts, then the dual curve bounded by it.
        self.multi_start_cycle(verts, layers, close, s, &rotated, &mut best);
        if self.has_boundary {
            let bound = best.as_ref().map_or(f32::INFINITY, |b| b.0);
            if let Some(found) = self.layered_open(verts, layers, close, bound, false) {
                best = Some(found);
            }
        }
        best
    }

    /// The cheapest dual curve ∂ → ξ₀ → … → ξ_{n−1} → ∂ (§5.7) below
    /// `bound`, by one layered search from ξ₀ at its distances from ∂
    /// (`guided`: also by the anchors' fields in `self.pair.fields`), as
    /// [`Self::layered_cycle`] returns it (from ∂ to ∂).
    fn layered_open(
        &mut self,
        verts: &[usize],
        layers: &[Vec<u32>],
        close: &[f32],
        bound: f32,
        guided: bool,
    ) -> Option<(f32, Vec<u32>, bool)> {
        let n = layers.len();
        // A dual curve cheaper than `bound` has both ends closer to ∂.
        self.settle_boundary(bound);
        let f = self.boundary_field.as_ref()?;
        let enter: Vec<(u32, f32)> = layers[0]
            .iter()
            .map(|&b| (b, f.distance(b)))
            .filter(|e| e.1.is_finite())
            .collect();
        let leave = f.leave_costs(&layers[n - 1], &self.graph.g.reverse);
        let order: Vec<usize> = (0..n).collect();
        let (cost, nodes, _) = self.layered_search(
            verts,
            layers,
            close,
            &order,
            &enter,
            LayeredEnd::Open(&leave),
            bound,
            guided,
        )?;
        let (b0, last) = (nodes[0], nodes[nodes.len() - 1]);
        let mut full = self.boundary_path(b0);
        full.pop();
        full.extend(nodes);
        let mut tail = self.reversed_boundary_path(last);
        if !tail.is_empty() {
            tail.remove(0);
        }
        full.extend(tail);
        Some((cost, full, false))
    }

    /// Fills `self.pair.fields` with one fully settled field per anchor
    /// (the distances from its candidates, [`Self::field_sources`]), taken
    /// from the cache of recent anchors' fields where there (possibly only
    /// partly settled by the two-anchor search), else new.
    fn take_anchor_fields(&mut self, verts: &[usize]) {
        let nodes = self.graph.node_count();
        let mut fields = Vec::with_capacity(verts.len());
        for (k, &v) in verts.iter().enumerate() {
            let cached = self.pair.cache.iter().position(|c| c.0 == v as u32);
            let mut f = match cached {
                Some(i) => self.pair.cache.remove(i).1,
                None => match verts[..k].iter().position(|&w| w == v) {
                    // The same vertex again (not consecutive): its field.
                    Some(j) => std::mem::take(&mut fields[j]),
                    None => {
                        let mut f = GrowingField::default();
                        f.reset(nodes, &self.field_sources(v));
                        f
                    }
                },
            };
            self.ws.effort += f.grow(&self.graph, &self.disabled, f32::INFINITY);
            if let Some(j) = verts[..k].iter().position(|&w| w == v) {
                fields[j] = f.clone();
            }
            fields.push(f);
        }
        self.pair.fields = fields;
    }

    /// Idle time (the design tool between events): settles up to `budget`
    /// g′ nodes of the fields a loop through `anchors` reads (with two or
    /// more anchors, the field of each positional anchor, the last
    /// [`FIELD_CACHE`]), into the cache of recent anchors' fields, so that
    /// the next query (a grab, a drag update, a further click) resumes them
    /// instead of settling them then; then the distances from ∂ (open
    /// meshes), fully, so that no hover query grows them. A field is the
    /// same whichever call settled it so far, so every loop stays the same.
    /// Returns whether a field is still not fully settled.
    pub fn prepare_fields(&mut self, anchors: &[Anchor], budget: u64) -> bool {
        let mut left = budget;
        let mut more = false;
        if anchors.len() >= 2 {
            (left, more) = self.prepare_anchor_fields(anchors, left);
        }
        // Then the distances from ∂ (§5.7), read by every hover query and
        // dual curve: settled fully here, a hover never grows them (the
        // first hovers far from the boundary used to settle most of g′).
        if self.has_boundary && left > 0 {
            self.grow_boundary(f32::INFINITY, left);
            more |= self
                .boundary_field
                .as_ref()
                .is_none_or(|f| f.radius.is_finite());
        }
        // A closed mesh has no dual curve to show while a hover's search
        // runs: its recent answers are the provisional loops
        // ([`Self::recent_through`]), filled here with the loops through
        // vertices spread over the mesh.
        if !self.has_boundary && left > 0 && self.hover_search.as_ref().is_none_or(|h| h.idle) {
            more |= self.fill_recent(left.min(IDLE_LOOP_SLICE));
        }
        more
    }

    /// One slice of [`Self::prepare_fields`]'s loops on a closed mesh: the
    /// hover query at the next vertex of a spread order (the golden ratio's
    /// multiples of the vertex count), resumed for at most `budget` settled
    /// nodes; its answer joins the recent ones. Returns whether there are
    /// fewer than [`IDLE_LOOPS`] of them.
    fn fill_recent(&mut self, budget: u64) -> bool {
        let n = self.graph.g.vertex_count();
        if n == 0 || self.recent.len() >= IDLE_LOOPS {
            return false;
        }
        if self.hover_search.is_none() {
            let v = ((self.idle_queries as f64 * 0.618_033_988_75).fract() * n as f64) as usize;
            self.idle_queries += 1;
            self.hover_search = Some(HoverSearch {
                v: v.min(n - 1),
                dual: None,
                dual_proven: true,
                labelled: None,
                idle: true,
            });
        }
        if let HoverStep::Exact(_) = self.hover_step(budget, false) {
            self.hover_search = None;
        }
        self.recent.len() < IDLE_LOOPS
    }

    /// The anchors' part of [`Self::prepare_fields`]: returns the budget
    /// left and whether a field is still not fully settled.
    fn prepare_anchor_fields(&mut self, anchors: &[Anchor], budget: u64) -> (u64, bool) {
        let mut verts: Vec<usize> = Vec::new();
        for a in anchors.iter().filter(|a| a.direction == DVec3::ZERO) {
            if let Some(v) = self.nearest_vertex(a.position) {
                verts.retain(|&w| w != v);
                verts.push(v);
            }
        }
        let keep = verts.len().saturating_sub(FIELD_CACHE);
        let nodes = self.graph.node_count();
        let mut left = budget;
        let mut more = false;
        for &v in &verts[keep..] {
            let mut f = match self.pair.cache.iter().position(|c| c.0 == v as u32) {
                Some(i) => self.pair.cache.remove(i).1,
                None => {
                    let mut f = GrowingField::default();
                    f.reset(nodes, &self.field_sources(v));
                    f
                }
            };
            let settled = f.grow_by(&self.graph, &self.disabled, left);
            self.ws.effort += settled;
            left = left.saturating_sub(settled.max(1));
            more |= f.radius.is_finite();
            self.cache_field(v, f);
        }
        (left, more)
    }

    /// Puts the fields of [`Self::take_anchor_fields`] back into the cache
    /// (at most [`FIELD_CACHE`] fields, the most recent last).
    fn return_anchor_fields(&mut self, verts: &[usize]) {
        let fields = std::mem::take(&mut self.pair.fields);
        for (f, &v) in fields.into_iter().zip(verts) {
            self.cache_field(v, f);
        }
    }

    /// Keeps `field` (from the candidates of the positional anchor at `v`)
    /// for later queries, dropping the oldest beyond [`FIELD_CACHE`].
    fn cache_field(&mut self, v: usize, field: GrowingField) {
        let cache = &mut self.pair.cache;
        cache.retain(|c| c.0 != v as u32);
        cache.push((v as u32, field));
        if cache.len() > FIELD_CACHE {
            cache.remove(0);
        }
    }

    /// The closed loop through three or more positional anchors (on
    /// distinct consecutive vertices) by one layered search per start a₀
    /// of the smallest layer `s`, guided by the anchors' fields (settled
    /// fully, `self.pair.fields`), cheapest lower bound first, each pruned
    /// by the best loop or curve so far (`best`). The bound of a₀: the
    /// loop a₀ → ξ₁ → … → ξ_{n−1} → a₀ (in `rotated` order) costs at least
    /// F₁(reverse(a₀)) (from a₀ to the next anchor but for the last arc;
    /// g′ weights are reversal-symmetric) plus, per later segment k → k+1,
    /// the smallest F_k over the candidates of anchor k+1, plus F_{n−1}(a₀)
    /// (from the last anchor back to a₀). No search beyond the fields.
    /// `open` (with a boundary): also the dual curve ([`Self::layered_open`],
    /// guided too), searched after the first start, bounded by its loop.
    #[allow(clippy::too_many_arguments)]
    fn guided_starts(
        &mut self,
        verts: &[usize],
        layers: &[Vec<u32>],
        close: &[f32],
        s: usize,
        rotated: &[usize],
        open: bool,
        best: &mut Option<(f32, Vec<u32>, bool)>,
    ) {
        let n = layers.len();
        let fields = &self.pair.fields;
        let g = &self.graph.g;
        let middle: f32 = (1..n - 1)
            .map(|k| {
                layers[rotated[k + 1]]
                    .iter()
                    .map(|&y| fields[rotated[k]].value(y as usize))
                    .fold(f32::INFINITY, f32::min)
            })
            .sum();
        let mut order: Vec<(f32, u32)> = layers[s]
            .iter()
            .map(|&a| {
                let lb = fields[rotated[1]].value_of_reverse(g, a as usize)
                    + middle
                    + fields[rotated[n - 1]].value(a as usize);
                (lb, a)
            })
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for (i, (lb, a0)) in order.into_iter().enumerate() {
            if i == 1 && open {
                // The dual curve, bounded by the first loop.
                let bound = best.as_ref().map_or(f32::INFINITY, |b| b.0);
                if let Some(found) = self.layered_open(verts, layers, close, bound, true) {
                    *best = Some(found);
                }
            }
            let bound = best.as_ref().map_or(f32::INFINITY, |b| b.0);
            // The bounds sum reversed searches: rounding may put them a
            // little above the forward costs.
            if lb * (1.0 - 1e-4) >= bound {
                break;
            }
            if let Some((cost, mut nodes, starts)) = self.layered_search(
                verts,
                layers,
                close,
                rotated,
                &[(a0, 0.0)],
                LayeredEnd::Closed,
                bound,
                true,
            ) {
                // Start the loop at anchor 0's candidate, as the pairwise
                // method does.
                nodes.rotate_left(starts[(n - s) % n]);
                *best = Some((cost, nodes, true));
            }
        }
    }

    /// The loop through two positional anchors on distinct vertices (`None`
    /// for any other anchor set): the cheapest closed loop and, when `open`
    /// and the mesh has a boundary, the cheapest dual curve (§5.7) if that
    /// is cheaper. Returns what [`Self::layered_cycle`] returns.
    ///
    /// The closed loop through a start a₀ of the first anchor is min over
    /// the second anchor's candidates y of d(a₀ → y) + d(y → a₀), and
    /// d(y → a₀) = d(reverse(a₀) → reverse(y)) (g′ weights are
    /// reversal-symmetric): two half-searches per start, from a₀ and from
    /// reverse(a₀), both A* guided by ONE field F, the distances from the
    /// second anchor's candidates (F(reverse(x)) bounds the distance from x
    /// to the anchor, exactly up to its last arc, and is the exact distance
    /// of the reversed half). F(reverse(a₀)) + F(a₀) bounds each start's
    /// loop from below. F is settled only as far as the searches read it
    /// (beyond its radius it reads the radius, still a lower bound): about
    /// the longer half of the loop, not the whole loop.
    ///
    /// Everything is pruned by a level C that starts 1 % above the smallest
    /// of these bounds and grows by 2 %, 4 %, 8 % … until a loop at most C
    /// is found: at each level the starts whose bound is below C run
    /// (cheapest first, pruned by min(best, C)), and the dual curve ∂ → ξ₀
    /// → ξ₁ → ∂ is one A* from ξ₀ at its distances from ∂ to ξ₁ plus their
    /// distances to ∂, guided by F too. Exact: a loop or curve cheaper than
    /// the final level is found in it (tested against one layered search
    /// per start and the layered dual-curve search).
    #[allow(clippy::type_complexity)]
    fn two_anchor_loop(
        &mut self,
        verts: &[usize],
        layers: &[Vec<u32>],
        close: &[f32],
        open: bool,
    ) -> Option<Option<(f32, Vec<u32>, bool)>> {
        if layers.len() != 2 || close.iter().any(|c| c.is_finite()) || verts[0] == verts[1] {
            return None;
        }
        let open = open && self.has_boundary;
        let nodes = self.graph.node_count();
        let v1 = verts[1] as u32;
        // The second anchor's field: resumed from the cache when there (a
        // field is the same whichever query settled it so far).
        match self.pair.cache.iter().position(|c| c.0 == v1) {
            Some(i) => self.pair.field = self.pair.cache.remove(i).1,
            None => {
                let sources = self.field_sources(verts[1]);
                self.pair.field.reset(nodes, &sources);
            }
        }
        let starts: Vec<u32> = layers[0]
            .iter()
            .copied()
            .filter(|&a| !self.disabled[a as usize] && self.graph.g.reverse[a as usize] != NONE)
            .collect();
        // The smallest lower bound of a loop (and of a dual curve: its
        // distance from ∂ to a₀ plus F(reverse(a₀))) over the starts.
        let smallest = |engine: &Self| -> f32 {
            let (g, f) = (&engine.graph.g, &engine.pair.field);
            let bf = engine.boundary_field.as_ref().filter(|_| open);
            starts
                .iter()
                .map(|&a| {
                    let to = f.value_of_reverse(g, a as usize);
                    let closed = to + f.value(a as usize);
                    bf.map_or(closed, |bf| closed.min(bf.lower_bound(a) + to))
                })
                .fold(f32::INFINITY, f32::min)
        };
        // F (and the distances from ∂) first up to about the straight-line
        // distance, then as far as each level's searches read them.
        let p = &self.graph.g.mesh.positions;
        let apart = p[verts[0]].distance(p[verts[1]]) as f32;
        let r = 1.8 * apart + 0.5 * BOUNDARY_RADIUS;
        self.ws.effort += self.pair.field.grow(&self.graph, &self.disabled, r);
        if open {
            self.settle_boundary(r);
        }
        let mut best: (f32, Vec<u32>, bool) = (f32::INFINITY, Vec::new(), true);
        let mut level = 0.0f32;
        loop {
            let lowest = smallest(self);
            if !lowest.is_finite() && !best.0.is_finite() {
                break;
            }
            level = (level * LEVEL_GROWTH)
                .max(lowest * 1.01)
                .max(level + LEVEL_STEP);
            if level > 1e4 {
                level = f32::INFINITY;
            }
            self.two_anchor_closed(verts, layers, &starts, level, &mut best);
            if open {
                self.two_anchor_open(layers, v1, level, &mut best);
            }
            if best.0 <= level || !level.is_finite() {
                break;
            }
        }
        let field = std::mem::take(&mut self.pair.field);
        self.cache_field(verts[1], field);
        Some(best.0.is_finite().then_some(best))
    }

    /// The sources of a field from a positional anchor at `v`: every
    /// out-edge of `v` that is enabled or whose reverse is (so that
    /// F(reverse(x)) is 0 wherever x arrives at `v` in either search
    /// direction, and F bounds both).
    fn field_sources(&self, v: usize) -> Vec<u32> {
        let g = &self.graph.g;
        g.out_edges(v)
            .filter(|&z| {
                let r = g.reverse[z];
                !self.disabled[z] || (r != NONE && !self.disabled[r as usize])
            })
            .map(|z| z as u32)
            .collect()
    }

    /// The closed loops of [`Self::two_anchor_loop`] at one level: every
    /// start whose lower bound is below min(best, `level`), cheapest first,
    /// by its two half-searches; improves `best`.
    fn two_anchor_closed(
        &mut self,
        verts: &[usize],
        layers: &[Vec<u32>],
        starts: &[u32],
        level: f32,
        best: &mut (f32, Vec<u32>, bool),
    ) {
        let v1 = verts[1] as u32;
        let lower = |engine: &Self, a: u32| -> (f32, f32) {
            let f = &engine.pair.field;
            (
                f.value(a as usize),
                f.value_of_reverse(&engine.graph.g, a as usize),
            )
        };
        let mut order: Vec<(f32, u32)> = starts
            .iter()
            .map(|&a| {
                let (back, to) = lower(self, a);
                (back + to, a)
            })
            .filter(|e| e.0.is_finite())
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for &(lb, a0) in &order {
            let cap = best.0.min(level);
            // The bounds sum reversed searches: rounding may put them a
            // little above the forward costs.
            if lb * (1.0 - 1e-4) >= cap {
                break;
            }
            // F exact wherever this start's searches read it below the cap.
            let (back, to) = lower(self, a0);
            let need = cap - back.min(to);
            self.ws.effort += self.pair.field.grow(&self.graph, &self.disabled, need);
            let (back, to) = lower(self, a0);
            if (back + to) * (1.0 - 1e-4) >= cap {
                continue;
            }
            let graph = &self.graph;
            let g = &graph.g;
            let (disabled, field) = (&self.disabled, &self.pair.field);
            // d(a₀ → y): towards the second anchor, F(reverse(x)) bounding
            // the rest (0 on its candidates).
            let h1 = |x: usize| -> f32 {
                if g.source[x] == v1 {
                    0.0
                } else {
                    field.value_of_reverse(g, x)
                }
            };
            self.ws.effort += astar(
                graph,
                &mut self.layered,
                &[(a0, 0.0)],
                |z| disabled[z],
                h1,
                cap - back,
                |_, _, _| {},
            );
            let ws1 = &self.layered;
            let d1: Vec<f32> = layers[1].iter().map(|&y| settled_dist(ws1, y)).collect();
            let min1 = d1.iter().copied().fold(f32::INFINITY, f32::min);
            if min1 + back >= cap {
                continue;
            }
            // d(reverse(a₀) → reverse(y)) over the reversed paths, F(reverse(z))
            // its exact heuristic.
            let blocked2 = |z: usize| -> bool {
                let r = g.reverse[z];
                r == NONE || disabled[r as usize]
            };
            self.ws.effort += astar(
                graph,
                &mut self.pair.side,
                &[(g.reverse[a0 as usize], 0.0)],
                blocked2,
                |z| field.value_of_reverse(g, z),
                cap - min1,
                |_, _, _| {},
            );
            let ws2 = &self.pair.side;
            let mut found: Option<(f32, u32)> = None;
            for (&y, &d) in layers[1].iter().zip(&d1) {
                let r = g.reverse[y as usize];
                if !d.is_finite() || r == NONE {
                    continue;
                }
                let total = d + settled_dist(ws2, r);
                if total < found.map_or(cap, |f| f.0) {
                    found = Some((total, y));
                }
            }
            if let Some((cost, y)) = found {
                // a₀ … y, then y … a₀ from the reversed half, without its
                // ends (y is there already; a₀ closes the loop).
                let mut loop_nodes = path_to(ws1, y);
                let back_path = path_to(ws2, g.reverse[y as usize]);
                let inner = back_path.len().saturating_sub(1);
                loop_nodes.extend(
                    back_path[1..inner]
                        .iter()
                        .rev()
                        .map(|&z| g.reverse[z as usize]),
                );
                *best = (cost, loop_nodes, true);
            }
        }
    }

    /// The dual curve of [`Self::two_anchor_loop`] at one level: ∂ → ξ₀ →
    /// ξ₁ → ∂ cheaper than min(best, `level`), by one A* from ξ₀ (at the
    /// distances from ∂) guided by F, ending on ξ₁ plus the distance to ∂;
    /// improves `best`.
    fn two_anchor_open(
        &mut self,
        layers: &[Vec<u32>],
        v1: u32,
        level: f32,
        best: &mut (f32, Vec<u32>, bool),
    ) {
        let cap = best.0.min(level);
        // A dual curve cheaper than the cap has both ends closer to ∂.
        self.settle_boundary(cap);
        let Some(bf) = self.boundary_field.as_ref() else {
            return;
        };
        let graph = &self.graph;
        let g = &graph.g;
        let enter: Vec<(u32, f32)> = layers[0]
            .iter()
            .map(|&b| (b, bf.distance(b)))
            .filter(|e| e.1 < cap)
            .collect();
        if enter.is_empty() {
            return;
        }
        // The rest of a curve from x: on to ξ₁ (F(reverse(x)), 0 on ξ₁),
        // then to ∂ (at least the cheapest exit of ξ₁); also at least x's
        // own distance to ∂. Both consistent, so is their maximum.
        let exit = |y: u32| -> f32 {
            let r = g.reverse[y as usize];
            if r == NONE {
                f32::INFINITY
            } else {
                bf.distance(r)
            }
        };
        let cheapest_exit = layers[1]
            .iter()
            .map(|&y| exit(y))
            .fold(f32::INFINITY, f32::min);
        if !cheapest_exit.is_finite() {
            return;
        }
        let (disabled, field) = (&self.disabled, &self.pair.field);
        let h = |x: usize| -> f32 {
            let to = if g.source[x] == v1 {
                0.0
            } else {
                field.value_of_reverse(g, x)
            };
            let r = g.reverse[x];
            let out = if r == NONE { 0.0 } else { bf.lower_bound(r) };
            (to + cheapest_exit).max(out)
        };
        let mut end: Option<(f32, u32)> = None;
        self.ws.effort += astar(
            graph,
            &mut self.layered,
            &enter,
            |z| disabled[z],
            h,
            cap,
            |x, d, bound| {
                if g.source[x] != v1 || !layers[1].contains(&(x as u32)) {
                    return;
                }
                let total = d + exit(x as u32);
                if total < *bound {
                    *bound = total;
                    end = Some((total, x as u32));
                }
            },
        );
        let Some((cost, last)) = end else {
            return;
        };
        let nodes = path_to(&self.layered, last);
        let mut full = self.boundary_path(nodes[0]);
        full.pop();
        full.extend(nodes);
        let mut tail = self.reversed_boundary_path(last);
        if !tail.is_empty() {
            tail.remove(0);
        }
        full.extend(tail);
        *best = (cost, full, false);
    }

    /// The closed loop of [`Self::layered_cycle`] by layered searches for
    /// anchor sets without fields (a directional anchor, or consecutive
    /// anchors on one vertex): one from all of the smallest layer `s` at
    /// once (a loop, not necessarily the cheapest: a state keeps only its
    /// cheapest start), then one per start, each pruned by the best loop so
    /// far.
    fn multi_start_cycle(
        &mut self,
        verts: &[usize],
        layers: &[Vec<u32>],
        close: &[f32],
        s: usize,
        rotated: &[usize],
        best: &mut Option<(f32, Vec<u32>, bool)>,
    ) {
        let n = layers.len();
        let all: Vec<(u32, f32)> = layers[s].iter().map(|&a| (a, 0.0)).collect();
        let mut run = |engine: &mut Self, sources: &[(u32, f32)]| {
            let bound = best.as_ref().map_or(f32::INFINITY, |b| b.0);
            if let Some((cost, mut nodes, starts)) = engine.layered_search(
                verts,
                layers,
                close,
                rotated,
                sources,
                LayeredEnd::Closed,
                bound,
                false,
            ) {
                // Start the loop at anchor 0's candidate, as the pairwise
                // method does.
                nodes.rotate_left(starts[(n - s) % n]);
                *best = Some((cost, nodes, true));
            }
        };
        run(self, &all);
        if all.len() > 1 {
            for &source in &all {
                run(self, &[source]);
            }
        }
    }

    /// One A* over the layered g′ of [`Self::layered_cycle`] with the
    /// anchors visited in `order`, from `sources` (node of layer 0's
    /// candidates, initial cost) to `end`, pruned at `bound`. Returns the
    /// cost, the nodes of the path (without the closing state) and the
    /// position in it where each layer begins.
    #[allow(clippy::too_many_arguments)]
    fn layered_search(
        &mut self,
        verts: &[usize],
        layers: &[Vec<u32>],
        close: &[f32],
        order: &[usize],
        sources: &[(u32, f32)],
        end: LayeredEnd<'_>,
        bound: f32,
        guided: bool,
    ) -> Option<(f32, Vec<u32>, Vec<usize>)> {
        let n = order.len();
        let graph = &self.graph;
        let g = &graph.g;
        let nodes = graph.node_count();
        let closed = matches!(end, LayeredEnd::Closed);
        // Layer `last` only ends paths; layers below it expand.
        let last = if closed { n } else { n - 1 };
        // The anchor each layer heads to, its heuristic, and a lower bound
        // of every later segment (admissible and consistent: a candidate of
        // the next anchor is at least that segment's bound from the one
        // after).
        let goals: Vec<usize> = (0..last).map(|l| verts[order[(l + 1) % n]]).collect();
        let hs: Vec<_> = goals.iter().map(|&v| graph.heuristic_to(v)).collect();
        let seg_lb: Vec<f32> = (0..last)
            .map(|l| {
                layers[order[l]]
                    .iter()
                    .map(|&a| hs[l](a as usize))
                    .fold(f32::INFINITY, f32::min)
                    .max(0.0)
            })
            .collect();
        let mut rest = vec![0.0f32; last + 1];
        for l in (0..last).rev() {
            rest[l] = rest[l + 1] + if l + 1 < last { seg_lb[l + 1] } else { 0.0 };
        }
        // Guided: also the fields of the anchors (F(reverse(x)) of the next
        // anchor's field, 0 on its out-edges), with their own bounds of the
        // later segments; the larger of both heuristics.
        let guided = guided && self.pair.fields.len() == n;
        let fields = &self.pair.fields;
        let fh = |l: usize, x: usize| -> f32 {
            if g.source[x] as usize == goals[l] {
                0.0
            } else {
                fields[order[(l + 1) % n]].value_of_reverse(g, x)
            }
        };
        let mut rest_f = vec![0.0f32; last + 1];
        if guided {
            for l in (0..last.saturating_sub(1)).rev() {
                let seg = layers[order[l + 1]]
                    .iter()
                    .map(|&a| fh(l + 1, a as usize))
                    .fold(f32::INFINITY, f32::min)
                    .max(0.0);
                rest_f[l] = rest_f[l + 1] + seg;
            }
        }
        let h = |state: usize| -> f32 {
            let (l, x) = (state / nodes, state % nodes);
            if l >= last {
                0.0
            } else if guided {
                (hs[l](x) + rest[l]).max(fh(l, x) + rest_f[l])
            } else {
                hs[l](x) + rest[l]
            }
        };
        let ws = &mut self.layered;
        let now = ws.start(nodes * (last + 1));
        let (reached, settled) = (2 * now, 2 * now + 1);
        for &(b, c) in sources {
            let st = b as usize;
            if self.disabled[st] || !c.is_finite() {
                continue;
            }
            if ws.state[st] < reached || c < ws.dist[st] {
                ws.state[st] = reached;
                ws.dist[st] = c;
                ws.parent[st] = NONE;
                ws.label[st] = b;
                ws.heap.push((c + h(st)).to_bits(), st as u32);
            }
        }
        let mut best = (bound, NONE);
        let disabled = &self.disabled;
        let LayeredWorkspace {
            dist,
            parent,
            label,
            state,
            heap,
            ..
        } = &mut *ws;
        let mut cap = bound;
        self.ws.effort += settle(heap, &mut cap, false, |st, heap, cap| {
            let st = st as usize;
            if state[st] == settled {
                return false;
            }
            state[st] = settled;
            let (l, x) = (st / nodes, st % nodes);
            let d = dist[st];
            if l == last {
                let total = match end {
                    LayeredEnd::Closed if x == label[st] as usize => d,
                    LayeredEnd::Open(leave) => layers[order[n - 1]]
                        .iter()
                        .position(|&a| a as usize == x)
                        .map_or(f32::INFINITY, |i| d + leave[i]),
                    LayeredEnd::Closed => f32::INFINITY,
                };
                if total < best.0 {
                    best = (total, st as u32);
                    *cap = total;
                }
                return true;
            }
            let next = order[(l + 1) % n];
            let at_goal = g.target[x] as usize == goals[l];
            let source = label[st];
            let only = (closed && l + 1 == last).then_some(source);
            let base = l * nodes;
            graph.for_each_arc(x, |y, w| {
                if disabled[y] {
                    return;
                }
                let nd = d + w;
                let mut relax = |t: usize| {
                    if state[t] < reached || nd < dist[t] {
                        state[t] = reached;
                        dist[t] = nd;
                        parent[t] = st as u32;
                        label[t] = source;
                        heap.push((nd + h(t)).to_bits(), t as u32);
                    }
                };
                relax(base + y);
                if at_goal
                    && only.is_none_or(|o| o as usize == y)
                    && layers[next].contains(&(y as u32))
                    && graph.turn(x, y).abs() <= close[next]
                {
                    relax(base + nodes + y);
                }
            });
            true
        });
        let (cost, end_state) = best;
        if end_state == NONE {
            return None;
        }
        let (path, starts) = layered_path_to(ws, end_state, nodes, n, closed);
        Some((cost, path, starts))
    }

    #[cfg(test)]
    /// The tests' reference for [`Self::layered_cycle`] (the method the
    /// engine used before it):
    /// the minimum-weight cycle of §5.4's metagraph (and, with a boundary,
    /// the cheapest ∂ → ξ₀ → … → ξ_{n−1} → ∂ path, §5.7): cost, chosen index
    /// per layer, closed. `radius`: the first R (tests: ∞, no pruning).
    ///
    /// Exact, and pruned by a radius R: a cycle cheaper than R has each
    /// segment i cheaper than `R − Σ_{l≠i} LB_l` (LB_l a lower bound of
    /// segment l: the A* heuristic, tightened to the cheapest metaedge found
    /// once segment l is searched), so the searches of segment i stop at
    /// that key and metaedges beyond it are left infinite. If the best
    /// cycle found costs at most R it is the optimum; otherwise R grows to
    /// that cost (or doubles) and the round is repeated. Before, every
    /// search ran until it had reached *all* of ξ_{i+1}, including the
    /// directions that need a U-turn there (most of g′ per search).
    fn metagraph_cycle(
        &mut self,
        verts: &[usize],
        layers: &[Vec<u32>],
        close: &[f32],
        radius: Option<f32>,
    ) -> (f32, Vec<usize>, bool) {
        let n = layers.len();
        let lb0: Vec<f32> = (0..n)
            .map(|i| {
                let h = self.graph.heuristic_to(verts[(i + 1) % n]);
                layers[i]
                    .iter()
                    .map(|&a| h(a as usize))
                    .fold(f32::INFINITY, f32::min)
                    .max(0.0)
            })
            .collect();
        let mut radius = radius.unwrap_or(1.5 * lb0.iter().sum::<f32>() + 0.05);
        loop {
            let mut lb = lb0.clone();
            if self.has_boundary {
                // A dual curve replaces the closing segment by ∂ (cost ≥ 0).
                lb[n - 1] = 0.0;
            }
            // Metaedge weights w̄(a, b) for a ∈ ξ_i, b ∈ ξ_{i+1}.
            let mut meta: Vec<Vec<f32>> = Vec::with_capacity(n);
            for i in 0..n {
                let j = (i + 1) % n;
                let others: f32 = (0..n).filter(|&l| l != i).map(|l| lb[l]).sum();
                let threshold = if radius.is_finite() {
                    (radius - others).max(0.0) * (1.0 + 1e-5) + 1e-6
                } else {
                    f32::INFINITY
                };
                let (li, lj) = (&layers[i], &layers[j]);
                let only = if lj.len() == 1 { Some(lj[0]) } else { None };
                let mut w = vec![f32::INFINITY; li.len() * lj.len()];
                if lj.len() == 1 && li.len() > 1 && verts[i] != verts[j] {
                    // §5.4: one backward search from the singleton.
                    self.search_back(lj[0], verts[i], threshold, close[j]);
                    for (ai, &a) in li.iter().enumerate() {
                        w[ai] = self.cand_of(verts[i], a).0;
                    }
                } else {
                    for (ai, &a) in li.iter().enumerate() {
                        self.search(a, verts[j], only, threshold, close[j]);
                        for (bi, &b) in lj.iter().enumerate() {
                            w[ai * lj.len() + bi] = self.cand_of(verts[j], b).0;
                        }
                    }
                }
                let cheapest = w.iter().copied().fold(f32::INFINITY, f32::min);
                if !(self.has_boundary && i == n - 1) {
                    lb[i] = lb[i].max(cheapest.min(threshold / (1.0 + 1e-5) - 1e-6));
                }
                meta.push(w);
            }
            let s = (0..n).min_by_key(|&i| (layers[i].len(), i)).unwrap_or(0);
            let mut best: (f32, Vec<usize>, bool) = (f32::INFINITY, Vec::new(), true);
            for start in 0..layers[s].len() {
                let (cost, choice) = layered_path(layers, &meta, s, n, Some(start), None);
                if cost < best.0 {
                    best = (cost, choice, true);
                }
            }
            if self.has_boundary {
                // Enter and leave ∂ cheaper than the radius: settled that far.
                self.settle_boundary(radius);
                if let Some(f) = self.boundary_field.as_ref() {
                    let enter: Vec<f32> = layers[0].iter().map(|&b| f.distance(b)).collect();
                    let leave = f.leave_costs(&layers[n - 1], &self.graph.g.reverse);
                    let (cost, choice) =
                        layered_path(layers, &meta, 0, n, None, Some((&enter, &leave)));
                    if cost < best.0 {
                        best = (cost, choice, false);
                    }
                }
            }
            if best.0 <= radius || !radius.is_finite() {
                return best;
            }
            radius = if best.0.is_finite() {
                best.0
            } else {
                let r = 2.0 * radius;
                if r > 1e4 { f32::INFINITY } else { r }
            };
        }
    }

    /// §8.1: the self-crossings of a loop's polyline. Two non-neighbouring
    /// segments cross when they come closer than half the median segment
    /// length and, projected into the tangent plane of the nearest vertex,
    /// intersect; crossings closer than two tolerances are one.
    pub fn self_crossings(&self, l: &DualLoop) -> Vec<SelfCrossing> {
        let p = &l.points;
        let m = p.len();
        let mut lengths: Vec<f64> = p.windows(2).map(|w| w[0].distance(w[1])).collect();
        if m < 5 {
            return Vec::new();
        }
        lengths.sort_by(f64::total_cmp);
        let tol = 0.5 * lengths[lengths.len() / 2];
        let segments = m - 1;
        let mut out: Vec<SelfCrossing> = Vec::new();
        for i in 0..segments {
            for j in i + 2..segments {
                // Neighbours along a closed loop (the last and first) touch.
                if l.closed && i == 0 && j == segments - 1 {
                    continue;
                }
                let (a0, a1, b0, b1) = (p[i], p[i + 1], p[j], p[j + 1]);
                let (pa, pb) = closest_points(a0, a1, b0, b1);
                if pa.distance(pb) > tol {
                    continue;
                }
                let mid = 0.5 * (pa + pb);
                let normal = self
                    .nearest_vertex(mid)
                    .map_or(DVec3::Z, |v| self.graph.g.normals[v]);
                let (u, w) = normal.any_orthonormal_pair();
                let flat = |q: DVec3| ((q - mid).dot(u), (q - mid).dot(w));
                if !segments_intersect_2d(flat(a0), flat(a1), flat(b0), flat(b1)) {
                    continue;
                }
                let (da, db) = (a1 - a0, b1 - b0);
                let (da, db) = (da - normal * da.dot(normal), db - normal * db.dot(normal));
                let c = (da.dot(db).abs() / (da.length() * db.length()).max(1e-300)).min(1.0);
                let angle_degrees = c.acos().to_degrees();
                match out.iter_mut().find(|x| x.point.distance(mid) < 2.0 * tol) {
                    Some(x) => x.angle_degrees = x.angle_degrees.min(angle_degrees),
                    None => out.push(SelfCrossing {
                        point: mid,
                        angle_degrees,
                    }),
                }
            }
        }
        out
    }

    /// §6.2: per vertex the covered directions of every committed strip
    /// covering it (world tangents; zero ones ignored). Replaces the
    /// previous state.
    pub fn set_covered(&mut self, covered: &[Vec<DVec3>]) {
        self.covered = covered
            .iter()
            .enumerate()
            .flat_map(|(v, ds)| {
                ds.iter()
                    .filter_map(move |d| Some((v as u32, d.try_normalize()?)))
            })
            .collect();
        self.update_disabled();
    }

    /// Adds a committed loop as a strip of `half_width` (world units) around
    /// it whose isocurves follow the loop's tangent (stand-in for §6.1's map).
    pub fn cover_loop(&mut self, l: &DualLoop, half_width: f64) {
        let g = &self.graph.g;
        let pts: Vec<DVec3> = l.points.iter().map(|&p| g.to_local(p)).collect();
        let hw = half_width / g.diagonal;
        for v in 0..g.vertex_count() {
            let p = g.mesh.positions[v];
            let mut best = (hw, DVec3::ZERO);
            for s in pts.windows(2) {
                let d = s[1] - s[0];
                let len2 = d.length_squared();
                if len2 <= 0.0 {
                    continue;
                }
                let t = ((p - s[0]).dot(d) / len2).clamp(0.0, 1.0);
                let dist = p.distance(s[0] + d * t);
                if dist <= best.0 {
                    best = (dist, d);
                }
            }
            if best.1 != DVec3::ZERO {
                self.covered.push((v as u32, best.1.normalize()));
            }
        }
        self.update_disabled();
    }

    /// Removes every covered strip.
    pub fn clear_covered(&mut self) {
        self.covered.clear();
        self.update_disabled();
    }

    /// Number of g′-nodes currently disabled by covered strips.
    pub fn disabled_count(&self) -> usize {
        self.disabled.iter().filter(|&&d| d).count()
    }

    fn update_disabled(&mut self) {
        self.covered.sort_by_key(|c| c.0);
        let g = &self.graph.g;
        let n = g.vertex_count();
        let mut first = vec![0u32; n + 1];
        for &(v, _) in &self.covered {
            if (v as usize) < n {
                first[v as usize + 1] += 1;
            }
        }
        for v in 0..n {
            first[v + 1] += first[v];
        }
        let cos45 = std::f64::consts::FRAC_1_SQRT_2 - 1e-9;
        let within = |v: usize, t: DVec3| -> bool {
            self.covered[first[v] as usize..first[v + 1] as usize]
                .iter()
                .any(|&(_, d)| {
                    let nv = g.normals[v];
                    let dt = (d - nv * d.dot(nv)).normalize_or_zero();
                    dt.dot(t).abs() >= cos45
                })
        };
        for e in 0..g.edge_count() {
            let (v, w) = (g.source[e] as usize, g.target[e] as usize);
            self.disabled[e] = within(v, g.direction_out(e)) || within(w, g.direction_in(e));
        }
        self.boundary_field = None;
        self.pair.cache.clear();
        // A progressive hover's search ran on the old enabled set, and the
        // recent answers may cross newly disabled nodes.
        self.hover_search = None;
        self.recent.clear();
    }

    /// The enabled out-edges of `v`. (A loop and its reverse leave `v` in
    /// opposite directions, but with discrete directions the reverse of a
    /// loop through one out-edge need not start on another one exactly, so
    /// no half circle is skipped.)
    fn out_sources(&self, v: usize) -> Vec<u32> {
        let g = &self.graph.g;
        g.out_edges(v)
            .filter(|&e| !self.disabled[e])
            .map(|e| e as u32)
            .collect()
    }

    /// ξ: the out-edge closest to `direction`, or all out-edges.
    fn candidate_edges(&self, v: usize, direction: DVec3) -> Vec<u32> {
        let g = &self.graph.g;
        let row = g.out_edges(v).filter(|&e| !self.disabled[e]);
        let nv = g.normals[v];
        let d = (direction - nv * direction.dot(nv)).normalize_or_zero();
        if d == DVec3::ZERO || !d.is_finite() {
            return row.map(|e| e as u32).collect();
        }
        row.max_by(|&a, &b| {
            d.dot(g.direction_out(a))
                .total_cmp(&d.dot(g.direction_out(b)))
                .then(b.cmp(&a))
        })
        .map(|e| vec![e as u32])
        .unwrap_or_default()
    }

    /// Best cost over all directions through `v` (closed loops and, with a
    /// boundary, dual curves), pruned by `bound`.
    ///
    /// With a boundary, the distances from ∂ are settled only as far as the
    /// answer needs: a radius r doubles (from a little above the previous
    /// answer's cost, at least [`BOUNDARY_RADIUS`]) until a dual curve
    /// cheaper than r exists; then one closed-loop search, bounded by that
    /// curve, decides. The closed-loop search (the expensive part: it
    /// settles the ball of half its bound around `v`) runs once per query,
    /// not once per radius; only when r has doubled twice without a dual
    /// curve is it also run at r, so that a cheap closed loop far from the
    /// boundary does not settle the whole field. Exact: a dual curve of cost
    /// c < r has both halves < r, hence settled, and a loop found below r
    /// beats every dual curve not found (all ≥ r).
    fn best_through(&mut self, v: usize, bound: f32) -> Option<(f32, Kind)> {
        if !self.has_boundary {
            return self.best_loop_through(v, bound);
        }
        let start = self.hover_radius.min(bound);
        let mut r = start;
        // The bound of a closed-loop search that found nothing.
        let mut no_closed_below = f32::NEG_INFINITY;
        let best = loop {
            let mut dual: Option<(f32, Kind)> = None;
            let mut limit = r;
            for b in self.out_sources(v) {
                if let Some((c, k)) = self.open_curve(b, limit) {
                    limit = c;
                    dual = Some((c, k));
                }
            }
            if dual.is_some() || r >= bound {
                let limit = dual.as_ref().map_or(bound, |(c, _)| *c);
                let closed = if limit <= no_closed_below {
                    None
                } else {
                    self.best_loop_through(v, limit)
                };
                break closed.or(dual);
            }
            if r >= 4.0 * start {
                if let Some(closed) = self.best_loop_through(v, r) {
                    break Some(closed);
                }
                no_closed_below = r;
            }
            let complete = self
                .boundary_field
                .as_ref()
                .is_some_and(|f| f.heap.is_empty());
            r = if complete {
                bound
            } else {
                (2.0 * r).min(bound)
            };
        };
        if let Some((c, _)) = &best {
            self.hover_radius = (1.25 * c).max(BOUNDARY_RADIUS);
        }
        best
    }

    /// The best closed loop through `v` cheaper than `limit`.
    fn best_loop_through(&mut self, v: usize, limit: f32) -> Option<(f32, Kind)> {
        // One labelled bidirectional search from all out-edges of `v` ranks
        // the closing directions (approximately: each node keeps only its
        // cheapest source), then exact bidirectional searches through the
        // best few (each bounded by the best loop so far) yield the loop.
        let (approx, _) = self.best_direction(v, limit)?;
        self.refine_directions(v, limit, approx)
    }

    /// The exact part of [`Self::best_loop_through`], after the labelled
    /// search (cheapest loop `approx`) left its per-direction costs in
    /// `ws.label_best`: the exact loop through each of the best few
    /// directions, bounded by the best so far.
    fn refine_directions(&mut self, v: usize, limit: f32, approx: f32) -> Option<(f32, Kind)> {
        let mut best: Option<(f32, Kind)> = None;
        let start = self.graph.g.out_edges(v).start;
        let mut ranked: Vec<(f32, u32)> = self
            .ws
            .label_best
            .iter()
            .enumerate()
            .filter(|(_, c)| **c <= REFINE_RATIO * approx)
            .map(|(i, &c)| (c, (start + i) as u32))
            .collect();
        ranked.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut exact = limit;
        for &(c_label, b) in ranked.iter().take(REFINE_DIRECTIONS) {
            let bound = (c_label * (1.0 + 1e-5) + 1e-6).min(exact);
            if let Some(c) = self.cycle_through(b, bound) {
                if c < exact {
                    exact = c;
                    best = Some((c, Kind::Closed(self.ws.path.clone())));
                }
            }
        }
        best
    }

    /// Labelled search from every out-edge of `v` at once (distance 0,
    /// labelled with itself). A loop through `v` is two such paths
    /// `s ⇝ y` and `s′ ⇝ reverse(y)` (g′ weights are reversal-symmetric)
    /// closed by the arc `reverse(s′) → s`; they are met at relaxation time
    /// and the search stops once twice the smallest open distance reaches the
    /// best loop (each half of a cheaper loop would cost less than half of
    /// it). Approximate only in that each node keeps its cheapest source.
    /// Returns the loop cost and the out-edge `s` it leaves `v` through.
    fn best_direction(&mut self, v: usize, bound: f32) -> Option<(f32, u32)> {
        let mut search = self.labelled_start(v, bound)?;
        self.labelled_run(&mut search, u64::MAX);
        search.found
    }

    /// Starts [`Self::best_direction`]'s search (sources queued, closing
    /// arcs tabulated); `None` when `v` has no out-edge.
    fn labelled_start(&mut self, v: usize, bound: f32) -> Option<LabelledSearch> {
        let graph = &self.graph;
        let g = &graph.g;
        let disabled = &self.disabled;
        let ws = &mut self.ws;
        let row = g.out_edges(v);
        if row.is_empty() {
            return None;
        }
        let now = ws.next_generation();
        let reached = 2 * now;
        ws.radix.clear();
        for s in row.clone() {
            if disabled[s] {
                continue;
            }
            ws.slot[s].dist = 0.0;
            ws.slot[s].parent = NONE;
            ws.slot[s].label = s as u32;
            ws.slot[s].state = ws.slot[s].state.max(reached);
            let r = g.reverse[s];
            if r != NONE {
                ws.mirror[r as usize] = Mirror {
                    dist: 0.0,
                    label: s as u32,
                    state: reached,
                };
            }
            ws.radix.push(0.0f32.to_bits(), s as u32);
        }
        let (start, len) = (row.start, row.len());
        ws.close.clear();
        ws.close.resize(len * len, f32::INFINITY);
        ws.label_best.clear();
        ws.label_best.resize(len, f32::INFINITY);
        for (i, s) in row.enumerate() {
            let closing = g.reverse[s];
            if closing != NONE {
                let close_row = &mut ws.close[i * len..(i + 1) * len];
                graph.for_each_arc(closing as usize, |t, w| close_row[t - start] = w);
            }
        }
        Some(LabelledSearch {
            start,
            generation: now,
            best: bound,
            found: None,
            meet: None,
            finished: false,
        })
    }

    /// Runs [`Self::best_direction`]'s search until it is finished or has
    /// settled `budget` nodes (then it can be resumed, as long as no other
    /// search has used the workspace since: `search.generation`). Returns
    /// the nodes settled.
    fn labelled_run(&mut self, search: &mut LabelledSearch, budget: u64) -> u64 {
        let graph = &self.graph;
        let g = &graph.g;
        let disabled = &self.disabled;
        let ws = &mut self.ws;
        let (reached, settled) = (2 * search.generation, 2 * search.generation + 1);
        if ws.generation != search.generation || search.finished {
            return 0;
        }
        let len = ws.label_best.len();
        let mut best = search.best;
        let mut found = search.found;
        let mut meet = search.meet;
        let mut left = budget;
        let (slot, mirror, heap, effort, close, label_best) = (
            &mut ws.slot,
            &mut ws.mirror,
            &mut ws.radix,
            &mut ws.effort,
            &ws.close,
            &mut ws.label_best,
        );
        // The out-edges of the search's vertex start where its sources do.
        let start = search.start;
        let mut finished = true;
        while let Some((k, node)) = heap.pop() {
            if 2.0 * f32::from_bits(k) >= best {
                break;
            }
            let x = node as usize;
            if slot[x].state == settled {
                continue;
            }
            if left == 0 {
                // Out of budget: put the entry back, resume later.
                heap.push(k, node);
                finished = false;
                break;
            }
            left -= 1;
            slot[x].state = settled;
            *effort += 1;
            let d = slot[x].dist;
            let lx = slot[x].label;
            let close_col = &close[lx as usize - start..];
            graph.for_each_arc(x, |y, w| {
                if disabled[y] {
                    return;
                }
                let nd = d + w;
                if nd >= best {
                    return;
                }
                let r = mirror[y];
                if r.state >= reached {
                    // reverse(y) is reached: the closing arc
                    // reverse(label(reverse(y))) → lx.
                    let c = nd + r.dist + close_col[(r.label as usize - start) * len];
                    let lb = &mut label_best[lx as usize - start];
                    *lb = lb.min(c);
                    if c < best {
                        best = c;
                        found = Some((c, lx));
                        // Where the loop closes, for a provisional answer:
                        // x and reverse(y)'s parent are settled, so their
                        // paths stay as they are.
                        let ry = g.reverse[y];
                        meet = Some((x as u32, y as u32, slot[ry as usize].parent));
                    }
                }
                // A node at half the best loop or more is never settled and
                // never needed as the other half of a cheaper loop.
                if 2.0 * nd < best && (slot[y].state < reached || nd < slot[y].dist) {
                    slot[y].state = slot[y].state.max(reached);
                    slot[y].dist = nd;
                    slot[y].parent = x as u32;
                    slot[y].label = lx;
                    let ry = g.reverse[y];
                    if ry != NONE {
                        mirror[ry as usize] = Mirror {
                            dist: nd,
                            label: lx,
                            state: reached,
                        };
                    }
                    heap.push(nd.to_bits(), y as u32);
                }
            });
        }
        search.best = best;
        search.found = found;
        search.meet = meet;
        search.finished = finished;
        budget - left
    }

    /// The exact minimum-cost loop through node `b` (a g-edge leaving vertex
    /// `v`) below `bound`, by bidirectional Dijkstra: colour A searches from
    /// `b`; colour B searches forward from every out-edge `e` of `v` whose
    /// reverse closes into `b` (arc `reverse(e) → b`, starting at that arc's
    /// weight), which by reversal symmetry is the backward search into `b`.
    /// A loop is an A-path to `y` plus a B-path to `reverse(y)`; the search
    /// stops when twice the smallest open key reaches the best meeting.
    /// Leaves the loop (starting with `b`) in `ws.path` and returns its cost.
    fn cycle_through(&mut self, b: u32, bound: f32) -> Option<f32> {
        const B: u32 = 1 << 31;
        let graph = &self.graph;
        let g = &graph.g;
        let disabled = &self.disabled;
        let b = b as usize;
        if b >= g.edge_count() || disabled[b] || g.edge_count() >= B as usize {
            return None;
        }
        let v = g.source[b] as usize;
        let ws = &mut self.ws;
        let now = ws.next_generation();
        let (reached, settled) = (2 * now, 2 * now + 1);
        ws.radix.clear();
        ws.slot[b].dist = 0.0;
        ws.slot[b].parent = NONE;
        ws.slot[b].state = ws.slot[b].state.max(reached);
        ws.radix.push(0.0f32.to_bits(), b as u32);
        for e in g.out_edges(v) {
            let x = g.reverse[e];
            if x == NONE || disabled[e] || !graph.is_arc(x as usize, b) {
                continue;
            }
            let w = graph.arc_weight(x as usize, b);
            ws.slot_b[e] = SlotB {
                dist: w,
                parent: NONE,
                state: reached,
            };
            ws.radix.push(w.to_bits(), e as u32 | B);
        }
        let mut best = bound;
        // (settled node, relaxed node, colour of both is B).
        let mut meet: Option<(u32, u32, bool)> = None;
        let (slot, slot_b, heap, effort) =
            (&mut ws.slot, &mut ws.slot_b, &mut ws.radix, &mut ws.effort);
        while let Some((k, node)) = heap.pop() {
            if 2.0 * f32::from_bits(k) >= best {
                break;
            }
            let raw = node;
            // Colour A grows from b, colour B from the edges closing into b.
            let (x, in_b) = ((raw & !B) as usize, raw & B != 0);
            let (d, state) = colour(slot, slot_b, x, in_b);
            if state == settled {
                continue;
            }
            let parent = parent_of(slot, slot_b, x, in_b);
            set_colour(slot, slot_b, x, in_b, d, parent, settled);
            *effort += 1;
            graph.for_each_arc(x, |y, w| {
                if disabled[y] {
                    return;
                }
                let nd = d + w;
                if nd >= best {
                    return;
                }
                let ry = g.reverse[y];
                if ry != NONE {
                    let (other, other_state) = colour(slot, slot_b, ry as usize, !in_b);
                    if other_state >= reached && nd + other < best {
                        best = nd + other;
                        meet = Some((x as u32, y as u32, in_b));
                    }
                }
                // The optimal loop's halves meet where both are below
                // half its cost: farther nodes need not be kept.
                let (yd, y_state) = colour(slot, slot_b, y, in_b);
                if 2.0 * nd < best && (y_state < reached || nd < yd) {
                    set_colour(slot, slot_b, y, in_b, nd, x as u32, y_state.max(reached));
                    heap.push(nd.to_bits(), y as u32 | if in_b { B } else { 0 });
                }
            });
        }
        let (x, y, in_b) = meet?;
        // A-chain b … a_end and B-chain e … b_end with b_end = reverse(a_end).
        let chain = |b_side: bool, last: u32, out: &mut Vec<u32>| {
            let start = out.len();
            let mut z = last;
            while z != NONE && out.len() - start <= slot.len() {
                out.push(z);
                z = parent_of(slot, slot_b, z as usize, b_side);
            }
            out[start..].reverse();
        };
        let path = &mut ws.path;
        path.clear();
        let mut tail = std::mem::take(&mut ws.cand_path);
        tail.clear();
        if in_b {
            chain(false, g.reverse[y as usize], path);
            chain(true, x, &mut tail);
            tail.push(y);
        } else {
            chain(false, x, path);
            path.push(y);
            chain(true, g.reverse[y as usize], &mut tail);
        }
        // Append reverse(b_{m−1}), …, reverse(b_0): the B-path walked back.
        tail.pop();
        path.extend(tail.iter().rev().map(|&z| g.reverse[z as usize]));
        ws.cand_path = tail;
        Some(best)
    }

    /// The dual curve ∂ → … → b → … → ∂ through node `b` (§5.7), if it
    /// costs less than `bound`.
    fn open_curve(&mut self, b: u32, bound: f32) -> Option<(f32, Kind)> {
        if !self.has_boundary {
            return None;
        }
        let r = self.graph.g.reverse[b as usize];
        if r == NONE {
            return None;
        }
        self.settle_boundary(bound);
        let f = self.boundary_field.as_ref()?;
        let c = f.distance(b) + f.distance(r);
        (c < bound).then_some((c, Kind::Open(b)))
    }

    /// Settles the distances from ∂ of every node closer than `bound`
    /// (resuming the cached Dijkstra; all of them for an infinite bound).
    fn settle_boundary(&mut self, bound: f32) {
        self.grow_boundary(bound, u64::MAX);
    }

    /// [`Self::settle_boundary`] stopped after `budget` settled nodes (the
    /// idle-time slices of [`Self::prepare_fields`]); returns how many it
    /// settled. Whichever slices settled it, the field below its radius is
    /// the same Dijkstra's.
    fn grow_boundary(&mut self, bound: f32, budget: u64) -> u64 {
        if !self.has_boundary || budget == 0 {
            return 0;
        }
        let g = &self.graph.g;
        let nodes = self.graph.node_count();
        let field = self.boundary_field.get_or_insert_with(|| {
            let mut f = BoundaryField {
                dist: vec![f32::INFINITY; nodes],
                parent: vec![NONE; nodes],
                settled: vec![false; nodes],
                heap: RadixHeap::default(),
                radius: 0.0,
            };
            for e in 0..nodes {
                if self.disabled[e] {
                    continue;
                }
                // E∂ in the direction of travel: g-edges that leave a
                // boundary vertex into the interior (a curve's first node).
                // Their reverses, arriving at the boundary from the interior,
                // are the last nodes.
                if g.boundary[g.source[e] as usize] && !g.boundary[g.target[e] as usize] {
                    f.dist[e] = 0.0;
                    f.heap.push(0f32.to_bits(), e as u32);
                }
            }
            f
        });
        let disabled = &self.disabled;
        let graph = &self.graph;
        let BoundaryField {
            dist,
            parent,
            settled,
            heap,
            radius,
        } = field;
        if bound <= *radius {
            return 0;
        }
        let mut cap = bound;
        let mut left = budget;
        let effort = settle(heap, &mut cap, true, |x, heap, cap| {
            let x = x as usize;
            if settled[x] {
                return false;
            }
            settled[x] = true;
            let d = dist[x];
            graph.for_each_arc(x, |y, w| {
                if disabled[y] {
                    return;
                }
                let nd = d + w;
                if nd < dist[y] {
                    dist[y] = nd;
                    parent[y] = x as u32;
                    heap.push(nd.to_bits(), y as u32);
                }
            });
            left -= 1;
            if left == 0 {
                // Out of budget: stop at the next entry (put back).
                *cap = f32::NEG_INFINITY;
            }
            true
        });
        // Every entry below the next key has been popped, so every node
        // closer than it (and, unless the budget ran out, than `bound`) is
        // settled.
        match heap.pop() {
            Some((k, x)) => {
                heap.push(k, x);
                let reached = if left > 0 { bound } else { f32::from_bits(k) };
                *radius = radius.max(reached);
            }
            None => {
                *heap = RadixHeap::default();
                *radius = f32::INFINITY;
            }
        }
        effort
    }

    /// Seed … `node` along the boundary field's parents.
    fn boundary_path(&self, node: u32) -> Vec<u32> {
        let mut out = Vec::new();
        if let Some(BoundaryField { parent, .. }) = &self.boundary_field {
            let mut x = node;
            while x != NONE && out.len() <= parent.len() {
                out.push(x);
                x = parent[x as usize];
            }
        }
        out.reverse();
        out
    }

    /// `node` … ∂: the reversed boundary path of `reverse(node)`.
    fn reversed_boundary_path(&self, node: u32) -> Vec<u32> {
        let r = self.graph.g.reverse[node as usize];
        if r == NONE {
            return vec![node];
        }
        let mut p = self.boundary_path(r);
        p.reverse();
        for x in &mut p {
            *x = self.graph.g.reverse[*x as usize];
        }
        p.retain(|&x| x != NONE);
        p
    }

    #[cfg(test)]
    /// A* in g′ from `source` towards the out-edges of `goal` (all of them,
    /// or only `only`), each reached through an arc. Results in `ws.cand`.
    fn search(&mut self, source: u32, goal: usize, only: Option<u32>, bound: f32, close_turn: f32) {
        let graph = &self.graph;
        let g = &graph.g;
        let ws = &mut self.ws;
        let row = g.out_edges(goal);
        ws.cand.clear();
        ws.cand.resize(row.len(), (f32::INFINITY, NONE));
        if self.disabled.get(source as usize).is_none_or(|&d| d) || row.is_empty() {
            return;
        }
        let now = ws.next_generation();
        let (reached, settled) = (2 * now, 2 * now + 1);
        let h = graph.heuristic_to(goal);
        ws.heap.clear();
        ws.slot[source as usize].dist = 0.0;
        ws.slot[source as usize].parent = NONE;
        ws.slot[source as usize].state = ws.slot[source as usize].state.max(reached);
        ws.heap.push(Reverse(key(h(source as usize), source)));
        let mut remaining = match only {
            Some(o) if row.contains(&(o as usize)) && !self.disabled[o as usize] => 1,
            Some(_) => return,
            None => row.clone().filter(|&e| !self.disabled[e]).count(),
        };
        let mut threshold = bound;
        while let Some(Reverse(k)) = ws.heap.pop() {
            let x = (k & 0xffff_ffff) as usize;
            if ws.slot[x].state == settled {
                continue;
            }
            if f32::from_bits((k >> 32) as u32) >= threshold {
                break;
            }
            ws.slot[x].state = settled;
            let d = ws.slot[x].dist;
            if g.target[x] as usize == goal {
                let mut improved = false;
                graph.for_each_successor(x, |y| {
                    if self.disabled[y]
                        || only.is_some_and(|o| o as usize != y)
                        || graph.turn(x, y).abs() > close_turn
                    {
                        return;
                    }
                    let c = d + graph.arc_weight(x, y);
                    let slot = &mut ws.cand[y - row.start];
                    if c < slot.0 {
                        if slot.1 == NONE {
                            remaining -= 1;
                        }
                        *slot = (c, x as u32);
                        improved = true;
                    }
                });
                if improved && remaining == 0 {
                    let worst = ws
                        .cand
                        .iter()
                        .map(|c| c.0)
                        .filter(|c| c.is_finite())
                        .fold(0.0f32, f32::max);
                    threshold = threshold.min(worst);
                }
            }
            let disabled = &self.disabled;
            let (slot, heap) = (&mut ws.slot, &mut ws.heap);
            graph.for_each_arc(x, |y, w| {
                if disabled[y] {
                    return;
                }
                let nd = d + w;
                if slot[y].state < reached || nd < slot[y].dist {
                    slot[y].state = slot[y].state.max(reached);
                    slot[y].dist = nd;
                    slot[y].parent = x as u32;
                    heap.push(Reverse(key(nd + h(y), y as u32)));
                }
            });
        }
    }

    #[cfg(test)]
    /// The backward search of §5.4 into node `b`: by reversal symmetry of
    /// the g′ weights, the cost of `a ⇝ b` is that of `reverse(b) ⇝
    /// reverse(a)`, so one A* forward from `reverse(b)` (its first arc, the
    /// reverse of the arc into `b`, turning at most `close_turn`) yields the
    /// costs from every out-edge `a` of `goal` into `b` (`ws.cand`, indexed
    /// like `goal`'s out-edges; no predecessors: the path is searched forward
    /// once chosen). Stops at key `bound`.
    fn search_back(&mut self, b: u32, goal: usize, bound: f32, close_turn: f32) {
        let graph = &self.graph;
        let g = &graph.g;
        let ws = &mut self.ws;
        let row = g.out_edges(goal);
        ws.cand.clear();
        ws.cand.resize(row.len(), (f32::INFINITY, NONE));
        let source = g.reverse.get(b as usize).copied().unwrap_or(NONE);
        if source == NONE || self.disabled[b as usize] || self.disabled[source as usize] {
            return;
        }
        let mut remaining = row.clone().filter(|&e| !self.disabled[e]).count();
        let now = ws.next_generation();
        let (reached, settled) = (2 * now, 2 * now + 1);
        let h = graph.heuristic_to(goal);
        ws.heap.clear();
        let s = source as usize;
        ws.slot[s].dist = 0.0;
        ws.slot[s].parent = NONE;
        ws.slot[s].state = ws.slot[s].state.max(reached);
        ws.heap.push(Reverse(key(h(s), source)));
        let threshold = bound;
        while let Some(Reverse(k)) = ws.heap.pop() {
            let x = (k & 0xffff_ffff) as usize;
            if ws.slot[x].state == settled {
                continue;
            }
            if f32::from_bits((k >> 32) as u32) >= threshold {
                break;
            }
            ws.slot[x].state = settled;
            ws.effort += 1;
            let d = ws.slot[x].dist;
            if x != s && g.target[x] as usize == goal {
                let a = g.reverse[x];
                if a != NONE && row.contains(&(a as usize)) && !self.disabled[a as usize] {
                    let c = &mut ws.cand[a as usize - row.start];
                    if c.1 == NONE {
                        *c = (d, x as u32);
                        remaining -= 1;
                        if remaining == 0 {
                            break;
                        }
                    }
                }
            }
            let disabled = &self.disabled;
            let (slot, heap) = (&mut ws.slot, &mut ws.heap);
            graph.for_each_arc(x, |y, w| {
                if disabled[y] || (x == s && graph.turn(x, y).abs() > close_turn) {
                    return;
                }
                let nd = d + w;
                if slot[y].state < reached || nd < slot[y].dist {
                    slot[y].state = slot[y].state.max(reached);
                    slot[y].dist = nd;
                    slot[y].parent = x as u32;
                    heap.push(Reverse(key(nd + h(y), y as u32)));
                }
            });
        }
    }

    #[cfg(test)]
    fn cand_of(&self, goal: usize, b: u32) -> (f32, u32) {
        let row = self.graph.g.out_edges(goal);
        if !row.contains(&(b as usize)) {
            return (f32::INFINITY, NONE);
        }
        self.ws
            .cand
            .get(b as usize - row.start)
            .copied()
            .unwrap_or((f32::INFINITY, NONE))
    }

    fn make_loop(&self, kind: Kind, cost: f32) -> DualLoop {
        match kind {
            Kind::Closed(nodes) => self.loop_from_nodes(nodes, cost as f64, true),
            Kind::Open(b) => {
                let mut nodes = self.boundary_path(b);
                let tail = self.reversed_boundary_path(b);
                nodes.extend(tail.into_iter().skip(1));
                self.loop_from_nodes(nodes, cost as f64, false)
            }
        }
    }

    fn loop_from_nodes(&self, nodes: Vec<u32>, cost: f64, closed: bool) -> DualLoop {
        let g = &self.graph.g;
        let mut points = Vec::with_capacity(nodes.len() * 4 + 1);
        for &e in &nodes {
            let (a, b) = (
                g.mesh.positions[g.source[e as usize] as usize],
                g.mesh.positions[g.target[e as usize] as usize],
            );
            points.push(g.to_world(a));
            for i in 1..4 {
                let p = a.lerp(b, i as f64 / 4.0);
                let p = self.index.as_ref().map_or(p, |ix| ix.closest(p).point);
                points.push(g.to_world(p));
            }
        }
        if let Some(&last) = nodes.last() {
            if closed {
                if let Some(&first) = points.first() {
                    points.push(first);
                }
            } else {
                points.push(g.to_world(g.mesh.positions[g.target[last as usize] as usize]));
            }
        }
        DualLoop {
            nodes,
            points,
            cost,
            closed,
        }
    }

    /// Normalised position of a g-vertex (for tests and tools).
    pub fn vertex_position(&self, v: usize) -> DVec3 {
        self.graph.g.to_world(self.graph.g.mesh.positions[v])
    }

    /// Unit midpoint of a node (normalised units).
    pub fn node_midpoint(&self, e: usize) -> Vec3 {
        self.graph.midpoint(e)
    }
}

#[derive(Debug, Clone)]
enum Kind {
    Closed(Vec<u32>),
    Open(u32),
}

#[cfg(test)]
#[inline]
fn key(cost: f32, node: u32) -> u64 {
    ((cost.max(0.0).to_bits() as u64) << 32) | node as u64
}

#[cfg(test)]
/// Min-cost walk through the metagraph layers. With `start = Some(i)`: a
/// cycle from node i of layer `s` through all layers back to it. With
/// `ends = Some((enter, leave))`: ∂ → layer 0 → … → layer n−1 → ∂.
/// Returns the cost and the chosen index per layer.
fn layered_path(
    layers: &[Vec<u32>],
    meta: &[Vec<f32>],
    s: usize,
    n: usize,
    start: Option<usize>,
    ends: Option<(&[f32], &[f32])>,
) -> (f32, Vec<usize>) {
    let mut back: Vec<Vec<usize>> = vec![Vec::new(); n + 1];
    let mut cost: Vec<f32> = match (start, ends) {
        (Some(i), _) => (0..layers[s].len())
            .map(|j| if j == i { 0.0 } else { f32::INFINITY })
            .collect(),
        (None, Some((enter, _))) => enter.to_vec(),
        _ => return (f32::INFINITY, Vec::new()),
    };
    let steps = if start.is_some() { n } else { n - 1 };
    for step in 0..steps {
        let i = (s + step) % n;
        let j = (i + 1) % n;
        let (li, lj) = (layers[i].len(), layers[j].len());
        let mut next = vec![f32::INFINITY; lj];
        let mut arg = vec![usize::MAX; lj];
        for a in 0..li {
            if !cost[a].is_finite() {
                continue;
            }
            for b in 0..lj {
                let c = cost[a] + meta[i][a * lj + b];
                if c < next[b] {
                    next[b] = c;
                    arg[b] = a;
                }
            }
        }
        back[step + 1] = arg;
        cost = next;
    }
    let (total, mut idx) = match (start, ends) {
        (Some(i), _) => (cost.get(i).copied().unwrap_or(f32::INFINITY), i),
        (None, Some((_, leave))) => cost
            .iter()
            .zip(leave)
            .enumerate()
            .map(|(b, (c, l))| (c + l, b))
            .fold((f32::INFINITY, 0), |m, x| if x.0 < m.0 { x } else { m }),
        _ => return (f32::INFINITY, Vec::new()),
    };
    if !total.is_finite() {
        return (f32::INFINITY, Vec::new());
    }
    let mut choice = vec![0usize; n];
    for step in (1..=steps).rev() {
        let layer = (s + step) % n;
        choice[layer] = idx;
        idx = back[step][idx];
        if idx == usize::MAX {
            return (f32::INFINITY, Vec::new());
        }
    }
    choice[s] = idx;
    (total, choice)
}

/// The closest points of segments `a0a1` and `b0b1`.
fn closest_points(a0: DVec3, a1: DVec3, b0: DVec3, b1: DVec3) -> (DVec3, DVec3) {
    let (d1, d2, r) = (a1 - a0, b1 - b0, a0 - b0);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    let c = d1.dot(r);
    let b = d1.dot(d2);
    let denom = a * e - b * b;
    let mut s = if denom > 1e-300 {
        ((b * f - c * e) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut t = if e > 1e-300 { (b * s + f) / e } else { 0.0 };
    if t < 0.0 {
        t = 0.0;
        s = if a > 1e-300 {
            (-c / a).clamp(0.0, 1.0)
        } else {
            0.0
        };
    } else if t > 1.0 {
        t = 1.0;
        s = if a > 1e-300 {
            ((b - c) / a).clamp(0.0, 1.0)
        } else {
            0.0
        };
    }
    (a0 + d1 * s, b0 + d2 * t)
}

/// Whether the closed 2D segments `pq` and `rs` intersect.
fn segments_intersect_2d(p: (f64, f64), q: (f64, f64), r: (f64, f64), s: (f64, f64)) -> bool {
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    // Orientations within rounding of zero count as zero, so passes that
    // meet exactly at a shared sample point (an endpoint of both) cross.
    let scale = [q, r, s]
        .iter()
        .map(|a| (a.0 - p.0).abs().max((a.1 - p.1).abs()))
        .fold(0.0f64, f64::max);
    let eps = 1e-9 * scale * scale;
    let snap = |d: f64| if d.abs() <= eps { 0.0 } else { d };
    let (d1, d2) = (snap(cross(r, s, p)), snap(cross(r, s, q)));
    let (d3, d4) = (snap(cross(p, q, r)), snap(cross(p, q, s)));
    d1 * d2 <= 0.0 && d3 * d4 <= 0.0 && (d1 != d2 || d3 != d4)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::{cylinder, flat_grid, icosphere, torus};

    /// Plain Dijkstra from `b` over every g′-arc (no pruning, no heuristic):
    /// the minimum loop cost through `b`.
    fn reference_cycle(e: &LoopEngine, b: usize) -> f32 {
        let graph = &e.graph;
        let n = graph.node_count();
        let mut dist = vec![f32::INFINITY; n];
        let mut heap = BinaryHeap::new();
        dist[b] = 0.0;
        heap.push(Reverse(key(0.0, b as u32)));
        while let Some(Reverse(k)) = heap.pop() {
            let x = (k & 0xffff_ffff) as usize;
            let d = f32::from_bits((k >> 32) as u32);
            if d > dist[x] {
                continue;
            }
            graph.for_each_successor(x, |y| {
                if e.disabled[y] {
                    return;
                }
                let nd = d + graph.arc_weight(x, y);
                if nd < dist[y] {
                    dist[y] = nd;
                    heap.push(Reverse(key(nd, y as u32)));
                }
            });
        }
        (0..n)
            .filter(|&x| !e.disabled[x] && dist[x].is_finite() && graph.is_arc(x, b))
            .map(|x| dist[x] + graph.arc_weight(x, b))
            .fold(f32::INFINITY, f32::min)
    }

    /// Sum of the arc weights of a closed node sequence, and whether every
    /// step (including last → first) is an enabled g′-arc.
    fn walk_cost(e: &LoopEngine, nodes: &[u32]) -> (f32, bool) {
        let mut cost = 0.0;
        let mut ok = !nodes.is_empty();
        for i in 0..nodes.len() {
            let (a, c) = (nodes[i] as usize, nodes[(i + 1) % nodes.len()] as usize);
            ok &= e.graph.is_arc(a, c) && !e.disabled[a];
            cost += e.graph.arc_weight(a, c);
        }
        (cost, ok)
    }

    fn check_engine(e: &mut LoopEngine, samples: usize) -> usize {
        let n = e.graph.node_count();
        let mut compared = 0;
        for i in 0..samples {
            let b = (i * 7919 + 13) % n;
            let expected = reference_cycle(e, b);
            let got = e.cycle_through(b as u32, f32::INFINITY);
            match got {
                None => assert!(
                    expected.is_infinite() || e.disabled[b],
                    "node {b}: reference loop {expected}, bidirectional none"
                ),
                Some(c) => {
                    let tol = 1e-4 * expected.max(1.0);
                    assert!(
                        (c - expected).abs() <= tol,
                        "node {b}: bidirectional {c}, reference {expected}"
                    );
                    let path = e.ws.path.clone();
                    assert_eq!(path[0] as usize, b);
                    let (walk, ok) = walk_cost(e, &path);
                    assert!(ok, "node {b}: the loop is not a closed walk in g′");
                    assert!((walk - c).abs() <= tol, "node {b}: walk {walk}, cost {c}");
                    // A bound just below the optimum finds nothing.
                    assert!(e.cycle_through(b as u32, 0.999 * c).is_none());
                    compared += 1;
                }
            }
        }
        compared
    }

    /// The hover query on closed meshes: a real loop through the anchor
    /// (a closed walk in g′ of the reported cost, never below the optimum
    /// over all directions by plain Dijkstra) and, on these smooth surfaces,
    /// equal to that optimum (on fandisk the direction ranking can miss it:
    /// see examples/bench_layout.rs).
    #[test]
    fn hover_loop_is_the_exhaustive_optimum_on_smooth_surfaces() {
        let meshes = [icosphere(1.0, 2), torus(2.0, 0.7, 30, 12)];
        let mut ratios = Vec::new();
        for mesh in &meshes {
            let mut e = LoopEngine::new(mesh, &ElasticaParams::default());
            for v in (0..mesh.vertex_count()).step_by(mesh.vertex_count() / 8) {
                let optimum = e
                    .graph
                    .g
                    .out_edges(v)
                    .map(|b| reference_cycle(&e, b))
                    .fold(f32::INFINITY, f32::min);
                let l = e.best_loop(e.vertex_position(v)).expect("a loop");
                assert!(l.closed);
                assert_eq!(e.graph.g.source[l.nodes[0] as usize] as usize, v);
                let (walk, ok) = walk_cost(&e, &l.nodes);
                assert!(ok, "vertex {v}: not a closed walk in g′");
                let cost = l.cost as f32;
                assert!((walk - cost).abs() <= 1e-4 * cost.max(1.0));
                assert!(
                    cost >= optimum * (1.0 - 1e-4),
                    "vertex {v}: {cost} < {optimum}"
                );
                ratios.push(cost / optimum);
            }
        }
        let worst = ratios.iter().copied().fold(0.0f32, f32::max);
        assert!(
            worst < 1.001,
            "hover loop up to {worst} × the optimum: {ratios:?}"
        );
    }

    /// On open meshes the distances from ∂ are settled lazily; the answers
    /// (hover, alternatives, two-anchor loops) equal those of an engine whose
    /// field was settled completely before the first query.
    #[test]
    fn lazy_boundary_field_gives_the_eager_answers() {
        let meshes = [cylinder(1.0, 3.0, 24, 12), flat_grid(1.0, 12)];
        let mut open_curves = 0;
        for mesh in &meshes {
            let mut lazy = LoopEngine::new(mesh, &ElasticaParams::default());
            let mut eager = LoopEngine::new(mesh, &ElasticaParams::default());
            eager.settle_boundary(f32::INFINITY);
            let n = mesh.vertex_count();
            for v in (0..n).step_by(n / 12) {
                let p = lazy.vertex_position(v);
                let (a, b) = (lazy.best_loop(p), eager.best_loop(p));
                assert_eq!(a.is_some(), b.is_some(), "vertex {v}");
                if let (Some(a), Some(b)) = (a, b) {
                    assert!(
                        (a.cost - b.cost).abs() <= 1e-5 * b.cost.max(1.0),
                        "vertex {v}: {} vs {}",
                        a.cost,
                        b.cost
                    );
                    assert_eq!(a.closed, b.closed, "vertex {v}");
                    open_curves += usize::from(!a.closed);
                }
                let (a, b) = (lazy.loops_through(p, 4), eager.loops_through(p, 4));
                let costs = |l: &[DualLoop]| l.iter().map(|l| l.cost).collect::<Vec<_>>();
                assert_eq!(costs(&a), costs(&b), "vertex {v}: alternatives");
                let q = lazy.vertex_position((v + n / 3) % n);
                let anchors = [Anchor::positional(p), Anchor::positional(q)];
                let (a, b) = (
                    lazy.constrained_loop(&anchors),
                    eager.constrained_loop(&anchors),
                );
                assert_eq!(
                    a.map(|l| l.cost),
                    b.map(|l| l.cost),
                    "vertex {v}: two anchors"
                );
            }
        }
        assert!(open_curves > 0, "no dual curve was the best answer");
    }

    /// The loop through two (and three) positional anchors by the
    /// half-searches of [`LoopEngine::two_anchor_loop`] (and the
    /// field-guided, bound-ordered starts of [`LoopEngine::guided_starts`],
    /// the fields partly from the cache of earlier queries) costs the
    /// same as the method before them, one unpruned layered search per
    /// start of the first anchor, on many random anchor sets of a torus,
    /// a sphere and an open cylinder, with and without a committed strip
    /// (disabled nodes); the loop found walks its cost through the anchors.
    /// On the open cylinder the two- and three-anchor searches with dual
    /// curves (§5.7) equal the cheaper of that and the layered search from ∂.
    #[test]
    fn two_anchor_half_searches_equal_one_layered_search_per_start() {
        use rand_core::{RngCore, SeedableRng};
        let meshes = [
            torus(2.0, 0.7, 30, 12),
            icosphere(1.0, 2),
            cylinder(1.0, 3.0, 24, 12),
        ];
        let mut rng = rand_pcg::Pcg32::seed_from_u64(21);
        let mut compared = 0;
        let mut open_curves = 0;
        for mesh in &meshes {
            let mut e = LoopEngine::new(mesh, &ElasticaParams::default());
            let n = mesh.vertex_count();
            for covered in [false, true] {
                if covered {
                    let l = e
                        .best_loop(e.vertex_position(n / 2))
                        .expect("a loop to commit");
                    e.cover_loop(&l, 0.15 * e.graph.g.diagonal);
                }
                for _ in 0..12 {
                    for count in [2usize, 3] {
                        let verts: Vec<usize> =
                            (0..count).map(|_| rng.next_u32() as usize % n).collect();
                        if (0..count).any(|i| verts[i] == verts[(i + 1) % count]) {
                            continue;
                        }
                        let layers: Vec<Vec<u32>> = verts
                            .iter()
                            .map(|&v| e.candidate_edges(v, DVec3::ZERO))
                            .collect();
                        if layers.iter().any(|l| l.is_empty()) {
                            continue;
                        }
                        let close = vec![f32::INFINITY; count];
                        let order: Vec<usize> = (0..count).collect();
                        // The method before: one search per start, unpruned.
                        let mut reference = f32::INFINITY;
                        for &a in &layers[0] {
                            if let Some((c, _, _)) = e.layered_search(
                                &verts,
                                &layers,
                                &close,
                                &order,
                                &[(a, 0.0)],
                                LayeredEnd::Closed,
                                f32::INFINITY,
                                false,
                            ) {
                                reference = reference.min(c);
                            }
                        }
                        if e.has_boundary {
                            // With the dual curve (§5.7): the layered search
                            // from ∂, fully settled, against the half-search.
                            e.settle_boundary(f32::INFINITY);
                            let f = e.boundary_field.as_ref().expect("a boundary field");
                            let enter: Vec<(u32, f32)> = layers[0]
                                .iter()
                                .map(|&b| (b, f.distance(b)))
                                .filter(|x| x.1.is_finite())
                                .collect();
                            let leave: Vec<f32> = layers[count - 1]
                                .iter()
                                .map(|&a| f.distance(e.graph.g.reverse[a as usize]))
                                .collect();
                            let open = e
                                .layered_search(
                                    &verts,
                                    &layers,
                                    &close,
                                    &order,
                                    &enter,
                                    LayeredEnd::Open(&leave),
                                    f32::INFINITY,
                                    false,
                                )
                                .map_or(f32::INFINITY, |x| x.0);
                            let either = reference.min(open);
                            let got = if count == 2 {
                                e.two_anchor_loop(&verts, &layers, &close, true)
                                    .expect("two positional anchors")
                            } else {
                                e.layered_cycle(&verts, &layers, &close)
                            };
                            let tol = 1e-4 * either.max(1.0);
                            match got {
                                None => assert!(!either.is_finite(), "{verts:?}: no loop or curve"),
                                Some((cost, nodes, closed)) => {
                                    assert!(
                                        (cost - either).abs() <= tol,
                                        "{verts:?} covered {covered}: {cost} vs loop \
                                         {reference} / curve {open}"
                                    );
                                    if !closed {
                                        open_curves += 1;
                                        for w in nodes.windows(2) {
                                            assert!(e.graph.is_arc(w[0] as usize, w[1] as usize));
                                        }
                                    }
                                }
                            }
                        }
                        let mut best = None;
                        let found = if count == 2 {
                            e.two_anchor_loop(&verts, &layers, &close, false)
                                .expect("two positional anchors")
                        } else {
                            e.take_anchor_fields(&verts);
                            e.guided_starts(&verts, &layers, &close, 0, &order, false, &mut best);
                            e.return_anchor_fields(&verts);
                            best
                        };
                        let tol = 1e-4 * reference.max(1.0);
                        match found {
                            None => assert!(!reference.is_finite(), "{verts:?}: no loop found"),
                            Some((cost, nodes, closed)) => {
                                assert!(
                                    (cost - reference).abs() <= tol,
                                    "{verts:?} covered {covered}: {cost} vs {reference}"
                                );
                                assert!(closed);
                                let (walked, ok) = walk_cost(&e, &nodes);
                                assert!(ok, "{verts:?}: not a cycle of arcs");
                                assert!(
                                    (walked - cost).abs() <= tol,
                                    "{verts:?}: walks {walked}, reported {cost}"
                                );
                                assert!(layers[0].contains(&nodes[0]));
                                for &v in &verts {
                                    assert!(
                                        nodes
                                            .iter()
                                            .any(|&x| e.graph.g.source[x as usize] as usize == v),
                                        "{verts:?}: misses anchor vertex {v}"
                                    );
                                }
                                assert!(nodes.iter().all(|&x| !e.disabled[x as usize]));
                                compared += 1;
                            }
                        }
                    }
                }
            }
        }
        assert!(compared >= 100, "only {compared} anchor sets compared");
        assert!(open_curves > 0, "no dual curve was the best answer");
    }

    /// The metagraph cycle pruned by the growing radius equals the unpruned
    /// one (every search run to all targets) for two and three anchors,
    /// positional and directional, on closed and open meshes; so does the
    /// engine's layered search, whose loop walks its cost.
    #[test]
    fn pruned_metagraph_cycle_and_layered_search_equal_the_unpruned_one() {
        let meshes = [torus(2.0, 0.7, 30, 12), cylinder(1.0, 3.0, 24, 12)];
        let mut compared = 0;
        for mesh in &meshes {
            let mut e = LoopEngine::new(mesh, &ElasticaParams::default());
            let n = mesh.vertex_count();
            for k in 0..4 {
                let vs = [k * 37 % n, (k * 37 + n / 3) % n, (k * 37 + 2 * n / 3) % n];
                for count in [2usize, 3] {
                    for directional in [false, true] {
                        let verts = &vs[..count];
                        let layers: Vec<Vec<u32>> = verts
                            .iter()
                            .enumerate()
                            .map(|(i, &v)| {
                                let d = if directional && i == 1 {
                                    e.graph.g.frame_u[v]
                                } else {
                                    DVec3::ZERO
                                };
                                e.candidate_edges(v, d)
                            })
                            .collect();
                        let close: Vec<f32> = (0..count)
                            .map(|i| {
                                if directional && i == 1 {
                                    0.5 * e.graph.max_turn
                                } else {
                                    f32::INFINITY
                                }
                            })
                            .collect();
                        let pruned = e.metagraph_cycle(verts, &layers, &close, None);
                        let full = e.metagraph_cycle(verts, &layers, &close, Some(f32::INFINITY));
                        assert!(full.0.is_finite(), "{verts:?}: no cycle");
                        let tol = 1e-4 * full.0.max(1.0);
                        assert!(
                            (pruned.0 - full.0).abs() <= tol,
                            "{verts:?} directional {directional}: pruned {} vs {}",
                            pruned.0,
                            full.0
                        );
                        // The layered search: the same optimum, and a walk
                        // that really costs it (a closed walk of g′-arcs, or
                        // a curve from ∂ to ∂ through every anchor's vertex).
                        let (cost, nodes, closed) = e
                            .layered_cycle(verts, &layers, &close)
                            .unwrap_or_else(|| panic!("{verts:?}: no layered cycle"));
                        assert!(
                            (cost - full.0).abs() <= tol,
                            "{verts:?} directional {directional}: layered {cost} vs {}",
                            full.0
                        );
                        assert_eq!(closed, full.2, "{verts:?}: closed or open");
                        if closed {
                            let (walked, ok) = walk_cost(&e, &nodes);
                            assert!(ok, "{verts:?}: the layered loop is not a cycle of arcs");
                            assert!(
                                (walked - cost).abs() <= tol,
                                "{verts:?}: the loop walks {walked}, reported {cost}"
                            );
                            assert!(
                                layers[0].contains(&nodes[0]),
                                "{verts:?}: the loop starts at anchor 0"
                            );
                        } else {
                            for w in nodes.windows(2) {
                                assert!(e.graph.is_arc(w[0] as usize, w[1] as usize));
                            }
                        }
                        for &v in verts {
                            assert!(
                                nodes
                                    .iter()
                                    .any(|&x| e.graph.g.source[x as usize] as usize == v),
                                "{verts:?}: the loop misses anchor vertex {v}"
                            );
                        }
                        compared += 1;
                    }
                }
            }
        }
        assert_eq!(compared, 32);
    }

    /// §8.1: a figure eight (lemniscate of Gerono) on a plane crosses
    /// itself once, at the origin, at 90°; a circle never.
    #[test]
    fn a_field_grown_by_slices_is_the_fully_settled_field_below_its_radius() {
        // Independent check: every node below the radius is settled at the
        // distance of a field settled in one go, every other node is at
        // least the radius away; slices end at the field settled fully.
        let mesh = torus(2.0, 0.7, 20, 8);
        let e = LoopEngine::new(&mesh, &ElasticaParams::default());
        let nodes = e.graph.node_count();
        let sources = e.field_sources(3);
        let mut full = GrowingField::default();
        full.reset(nodes, &sources);
        full.grow(&e.graph, &e.disabled, f32::INFINITY);
        let mut sliced = GrowingField::default();
        sliced.reset(nodes, &sources);
        let (mut slices, slice) = (0, nodes as u64 / 25 + 1);
        while sliced.radius.is_finite() {
            let settled = sliced.grow_by(&e.graph, &e.disabled, slice);
            assert!(settled <= slice);
            slices += 1;
            for x in 0..nodes {
                if sliced.done[x] {
                    assert_eq!(
                        sliced.dist[x], full.dist[x],
                        "node {x} after {slices} slices"
                    );
                } else {
                    assert!(
                        full.dist[x] >= sliced.radius,
                        "node {x} below the radius unsettled"
                    );
                }
            }
            assert!(slices < nodes, "slices never end");
        }
        assert!(slices > 10);
        assert!((0..nodes).all(|x| sliced.value(x) == full.value(x)));
    }

    /// §6.2 where strips overlap: a vertex covered by two strips keeps
    /// both directions' constraints, not only the first strip's. Checked on
    /// a plane against the g-edges' chord directions (independent of the
    /// engine's angle tables).
    #[test]
    fn overlapping_strips_keep_every_strips_direction_constraint() {
        let mesh = flat_grid(1.0, 12);
        let n = mesh.vertex_count();
        let dir = |deg: f64| DVec3::new(deg.to_radians().cos(), deg.to_radians().sin(), 0.0);
        let (a, b) = (dir(10.0), dir(70.0));
        let disabled_with = |covered: &[DVec3]| {
            let mut e = LoopEngine::new(&mesh, &ElasticaParams::default());
            e.set_covered(&vec![covered.to_vec(); n]);
            e
        };
        let both = disabled_with(&[a, b]);
        let (only_a, only_b) = (disabled_with(&[a]), disabled_with(&[b]));
        let g = &both.graph.g;
        let cos45 = std::f64::consts::FRAC_1_SQRT_2;
        let (mut checked, mut by_a, mut by_b) = (0, 0, 0);
        for e in 0..g.edge_count() {
            let (v, w) = (g.source[e] as usize, g.target[e] as usize);
            let chord = (g.mesh.positions[w] - g.mesh.positions[v]).normalize();
            let (ca, cb) = (chord.dot(a).abs(), chord.dot(b).abs());
            // Chords within half a degree of 45° from a direction are
            // left out (rounding decides them).
            let tie = |c: f64| (c.acos().to_degrees() - 45.0).abs() < 0.5;
            if tie(ca) || tie(cb) {
                continue;
            }
            checked += 1;
            let expected = ca >= cos45 || cb >= cos45;
            assert_eq!(both.disabled[e], expected, "g-edge {e}: chord {chord}");
            assert_eq!(
                only_a.disabled[e],
                ca >= cos45,
                "g-edge {e}, first strip alone"
            );
            by_a += usize::from(ca >= cos45 && cb < cos45);
            by_b += usize::from(cb >= cos45 && ca < cos45);
        }
        assert!(
            checked > g.edge_count() * 9 / 10,
            "{checked} of {} checked",
            g.edge_count()
        );
        // Each strip disables nodes the other does not.
        assert!(by_a > 100 && by_b > 100, "{by_a} / {by_b}");
        assert!(both.disabled_count() > only_a.disabled_count().max(only_b.disabled_count()));
    }

    #[test]
    fn a_boundary_field_prepared_by_slices_is_the_eager_one_below_its_radius() {
        // Independent check, as for the anchors' fields: after every idle
        // slice (no anchors: only the distances from ∂), each settled node
        // is at the distance of a field settled in one go and every
        // unsettled one at least the radius away; the slices end with the
        // whole field, and the hover answers equal the eager engine's.
        for (mesh, slice) in [
            (cylinder(1.0, 3.0, 24, 12), 1u64),
            (cylinder(1.0, 3.0, 24, 12), 997),
            (flat_grid(1.0, 12), 4_000),
        ] {
            let mut eager = LoopEngine::new(&mesh, &ElasticaParams::default());
            eager.settle_boundary(f32::INFINITY);
            let mut idle = LoopEngine::new(&mesh, &ElasticaParams::default());
            let nodes = idle.graph.node_count();
            let full = eager.boundary_field.as_ref().expect("an eager field");
            let mut slices = 0;
            while idle.prepare_fields(&[], slice) {
                slices += 1;
                let f = idle.boundary_field.as_ref().expect("a field");
                for x in 0..nodes {
                    if f.settled[x] {
                        assert_eq!(f.dist[x], full.dist[x], "node {x}, slice {slices}");
                    } else {
                        assert!(full.dist[x] >= f.radius, "node {x} below the radius");
                    }
                }
                assert!(slices <= nodes, "slices never end");
            }
            assert!(slice > 1 || slices > 100, "{slices} slices of one node");
            let f = idle.boundary_field.as_ref().expect("a field");
            assert_eq!(f.radius, f32::INFINITY);
            assert!((0..nodes).all(|x| f.dist[x] == full.dist[x]));
            let n = mesh.vertex_count();
            for v in (0..n).step_by(n / 10) {
                let p = idle.vertex_position(v);
                let (a, b) = (idle.best_loop(p), eager.best_loop(p));
                assert_eq!(
                    a.map(|l| (l.cost, l.closed)),
                    b.map(|l| (l.cost, l.closed)),
                    "vertex {v}"
                );
            }
        }
    }

    #[test]
    fn fields_prepared_in_idle_time_change_no_loop() {
        // The same anchor sequence as the page (two clicks, a grab, drag
        // updates) on two engines, one of them preparing the fields by
        // slices before each query: the same loops, node for node.
        use rand_core::{RngCore, SeedableRng};
        let meshes = [torus(2.0, 0.7, 30, 12), cylinder(1.0, 3.0, 24, 12)];
        let mut rng = rand_pcg::Pcg32::seed_from_u64(5);
        let mut compared = 0;
        for mesh in &meshes {
            let mut plain = LoopEngine::new(mesh, &ElasticaParams::default());
            let mut prepared = LoopEngine::new(mesh, &ElasticaParams::default());
            let n = mesh.vertex_count();
            let at = |e: &LoopEngine, v: usize| Anchor::positional(e.vertex_position(v));
            for trial in 0..6 {
                let mut anchors = vec![at(&plain, rng.next_u32() as usize % n)];
                let mut steps = Vec::new();
                for _ in 0..2 {
                    anchors.push(at(&plain, rng.next_u32() as usize % n));
                    steps.push(anchors.clone());
                }
                // A grab between the first two, then moved twice.
                for _ in 0..3 {
                    anchors[1] = at(&plain, rng.next_u32() as usize % n);
                    steps.push(anchors.clone());
                }
                for (k, step) in steps.iter().enumerate() {
                    // A different amount of idle time before each query:
                    // none, a slice, most of it, all of it.
                    let budget = [0u64, 500, 20_000, u64::MAX][(trial + k) % 4];
                    let mut left = budget;
                    while left > 0 && prepared.prepare_fields(step, left.min(3000)) {
                        left = left.saturating_sub(3000);
                    }
                    let a = plain.constrained_loop(step);
                    let b = prepared.constrained_loop(step);
                    match (a, b) {
                        (Some(a), Some(b)) => {
                            assert_eq!(a.cost, b.cost, "trial {trial} step {k}");
                            assert_eq!(a.closed, b.closed);
                            assert_eq!(a.nodes, b.nodes, "trial {trial} step {k}");
                            compared += 1;
                        }
                        (None, None) => {}
                        (a, b) => panic!(
                            "trial {trial} step {k}: {:?} / {:?}",
                            a.map(|l| l.cost),
                            b.map(|l| l.cost)
                        ),
                    }
                }
            }
        }
        assert!(compared >= 40, "{compared}");
    }

    /// The progressive hover ([`LoopEngine::hover_begin`] and
    /// [`LoopEngine::hover_resume`], by slices of 1 to 5 000 settled
    /// nodes, from no distances from ∂ settled, sometimes with another
    /// query between two slices) ends with [`LoopEngine::best_loop`]'s loop
    /// of an engine whose distances from ∂ are settled in one go, node for
    /// node; every provisional loop shown meanwhile is a walk of enabled g′
    /// arcs through the hovered vertex whose summed weights are its cost,
    /// and costs no less than the exact loop. On a torus, an open cylinder
    /// and a plane.
    /// A loop or dual curve shown for vertex `v`: it passes through `v`,
    /// walks enabled g′ arcs (a dual curve from the boundary to the
    /// boundary), and its weights sum to its cost.
    fn check_true_walk(e: &LoopEngine, l: &DualLoop, v: usize) {
        let g = &e.graph.g;
        assert!(
            l.nodes.iter().any(|&x| g.source[x as usize] as usize == v),
            "vertex {v}: the provisional loop misses the vertex"
        );
        let nodes = &l.nodes;
        let arcs = if l.closed {
            nodes.len()
        } else {
            nodes.len() - 1
        };
        let mut cost = 0.0f64;
        for i in 0..arcs {
            let (a, c) = (nodes[i] as usize, nodes[(i + 1) % nodes.len()] as usize);
            assert!(
                e.graph.is_arc(a, c) && !e.disabled[a],
                "vertex {v}: arc {i}"
            );
            cost += e.graph.arc_weight(a, c) as f64;
        }
        if !l.closed {
            // A dual curve's weights from ∂ and back: its two ends
            // leave and reach the boundary.
            assert!(g.boundary[g.source[nodes[0] as usize] as usize]);
            assert!(g.boundary[g.target[*nodes.last().unwrap() as usize] as usize]);
        }
        assert!(
            (cost - l.cost).abs() <= 1e-4 * l.cost.max(1.0),
            "vertex {v}: walked {cost}, reported {}",
            l.cost
        );
    }

    #[test]
    fn a_closed_mesh_shows_true_provisional_loops_from_its_idle_time_loops() {
        // On a closed mesh the hover's search finds a loop only as it ends;
        // after the idle time's loops through spread vertices, a hover
        // stopped after one node shows a true loop through its vertex at
        // every vertex (32 loops on 640 vertices; none without them): a
        // recent loop spliced through it, else bridged to from it
        // ([`LoopEngine::recent_bridge`]).
        let mesh = torus(2.0, 0.7, 40, 16);
        let n = mesh.vertex_count();
        let mut idle = LoopEngine::new(&mesh, &ElasticaParams::default());
        let mut plain = LoopEngine::new(&mesh, &ElasticaParams::default());
        let mut slices = 0;
        while idle.prepare_fields(&[], 5_000) {
            slices += 1;
            assert!(slices < 100_000, "the idle loops never end");
        }
        assert_eq!(idle.recent.len(), IDLE_LOOPS);
        let (mut shown, mut queried, mut cheaper, mut bridged) = (0, 0, 0, 0);
        for v in (0..n).step_by(7) {
            let p = idle.vertex_position(v);
            queried += 1;
            if let HoverStep::Provisional(l) = plain.hover_begin(p, 1) {
                assert!(l.is_none(), "vertex {v}: a loop without any search");
            }
            plain.cancel_hover();
            let exact = plain.best_loop(p).expect("a loop on the torus");
            let spliced = idle.recent_through(v).is_some();
            match idle.hover_begin(p, 1) {
                HoverStep::Provisional(Some(l)) => {
                    check_true_walk(&idle, &l, v);
                    assert!(l.closed, "vertex {v}: a closed mesh's loop");
                    bridged += usize::from(!spliced);
                    // Not necessarily dearer than the hover's answer: that
                    // one refines only the labelled search's best few
                    // directions.
                    cheaper += usize::from(l.cost < exact.cost * (1.0 - 1e-6));
                    shown += 1;
                }
                HoverStep::Provisional(None) => {}
                HoverStep::Exact(_) => panic!("vertex {v}: exact after one node"),
            }
            idle.cancel_hover();
        }
        eprintln!(
            "closed mesh: {shown} of {queried} hovers shown a provisional loop ({bridged} bridged to a recent loop, {cheaper} cheaper than the hover's answer)"
        );
        // Every hover shows a loop; most through the vertex are bridged
        // (the splices alone: a quarter).
        assert_eq!(shown, queried);
        assert!(2 * bridged >= queried, "{bridged} of {queried} bridged");
    }

    #[test]
    fn an_open_mesh_shows_a_dual_curve_before_the_distances_from_the_boundary_reach_the_vertex() {
        // The middle of a long open cylinder, no distances from ∂ settled:
        // the first slice settles too few of them to prove a dual curve
        // through the vertex, and shows one to where they reach instead.
        let mesh = cylinder(1.0, 6.0, 24, 36);
        let mut e = LoopEngine::new(&mesh, &ElasticaParams::default());
        let p = DVec3::new(1.0, 0.0, 0.0);
        let v = e.nearest_vertex(p).expect("a vertex");
        let l = match e.hover_begin(p, 400) {
            HoverStep::Provisional(Some(l)) => l,
            other => panic!("no provisional curve: {other:?}"),
        };
        // The field does not reach the vertex: the curve is not its own.
        let f = e.boundary_field.as_ref().expect("a field");
        assert!(
            e.graph
                .g
                .out_edges(v)
                .all(|b| f.distance(b as u32).is_infinite())
        );
        assert!(!l.closed);
        check_true_walk(&e, &l, v);
        let exact = loop {
            if let Some(x) = e.hover_resume(10_000) {
                break x.expect("an exact answer");
            }
        };
        assert!(l.cost >= exact.cost - 1e-6 * exact.cost);
        eprintln!(
            "open mesh: provisional {:.3}, exact {:.3}",
            l.cost, exact.cost
        );
    }

    #[test]
    fn a_progressive_hover_ends_with_the_exact_loop_and_shows_true_loops_meanwhile() {
        let meshes = [
            torus(2.0, 0.7, 30, 12),
            cylinder(1.0, 3.0, 24, 12),
            flat_grid(1.0, 12),
        ];
        let (mut shown, mut worse, mut exact_at_once, mut interrupted) = (0, 0, 0, 0);
        for mesh in &meshes {
            let mut eager = LoopEngine::new(mesh, &ElasticaParams::default());
            eager.settle_boundary(f32::INFINITY);
            let mut progressive = LoopEngine::new(mesh, &ElasticaParams::default());
            let n = mesh.vertex_count();
            for (k, v) in (0..n).step_by(n / 16).enumerate() {
                let p = eager.vertex_position(v);
                let reference = eager.best_loop(p);
                let budget = [1u64, 40, 700, 5_000][k % 4];
                let check_shown = |e: &LoopEngine, l: &DualLoop| check_true_walk(e, l, v);
                let mut provisional: Vec<DualLoop> = Vec::new();
                let exact = match progressive.hover_begin(p, budget) {
                    HoverStep::Exact(l) => {
                        exact_at_once += 1;
                        l
                    }
                    HoverStep::Provisional(l) => {
                        provisional.extend(l);
                        let mut slices = 0;
                        loop {
                            slices += 1;
                            if k % 3 == 1 && slices == 2 {
                                // Another query between two slices.
                                let q = eager.vertex_position((v + n / 2) % n);
                                progressive.loops_through(q, 2);
                                interrupted += 1;
                            }
                            if let Some(l) = progressive.hover_resume(budget) {
                                break l;
                            }
                        }
                    }
                };
                assert!(!progressive.hover_pending());
                for l in &provisional {
                    check_shown(&progressive, l);
                    shown += 1;
                    let best = exact
                        .as_ref()
                        .expect("an exact loop after a provisional one");
                    assert!(
                        l.cost >= best.cost - 1e-6 * best.cost.max(1.0),
                        "vertex {v}"
                    );
                    worse += usize::from(l.cost > best.cost * (1.0 + 1e-6));
                }
                match (&exact, &reference) {
                    (Some(a), Some(b)) => {
                        assert_eq!(a.cost, b.cost, "vertex {v}");
                        assert_eq!(a.closed, b.closed, "vertex {v}");
                        assert_eq!(a.nodes, b.nodes, "vertex {v}");
                    }
                    (None, None) => {}
                    _ => panic!("vertex {v}: {exact:?} / {reference:?}"),
                }
            }
        }
        // Every path was taken: exact at once, provisional loops (some worse
        // than the exact one), searches restarted after another query.
        assert!(exact_at_once > 0 && shown > 0 && worse > 0 && interrupted > 0);
        eprintln!(
            "progressive hover: {exact_at_once} exact at once, {shown} provisional ({worse} worse)"
        );
    }

    #[test]
    fn self_crossings_of_a_figure_eight_and_a_circle() {
        let e = LoopEngine::new(&flat_grid(1.0, 12), &ElasticaParams::default());
        let curve = |f: &dyn Fn(f64) -> DVec3| {
            let points: Vec<DVec3> = (0..=200)
                .map(|k| f(std::f64::consts::TAU * k as f64 / 200.0))
                .collect();
            DualLoop {
                nodes: Vec::new(),
                points,
                cost: 0.0,
                closed: true,
            }
        };
        let eight = curve(&|t| DVec3::new(0.6 * t.sin(), 0.6 * t.sin() * t.cos(), 0.0));
        let x = e.self_crossings(&eight);
        assert_eq!(x.len(), 1, "{x:?}");
        assert!(x[0].point.length() < 0.02, "{x:?}");
        assert!((x[0].angle_degrees - 90.0).abs() < 2.0, "{x:?}");
        let circle = curve(&|t| DVec3::new(0.6 * t.cos(), 0.6 * t.sin(), 0.0));
        assert!(e.self_crossings(&circle).is_empty());
        // A flatter eight crosses at a smaller angle: 2·atan(0.5) ≈ 53.1°.
        let flat = curve(&|t| DVec3::new(0.6 * t.sin(), 0.3 * t.sin() * t.cos(), 0.0));
        let x = e.self_crossings(&flat);
        assert_eq!(x.len(), 1, "{x:?}");
        let expected = 2.0 * 0.5f64.atan().to_degrees();
        assert!((x[0].angle_degrees - expected).abs() < 2.0, "{x:?}");
    }

    #[test]
    fn bidirectional_loop_search_matches_plain_dijkstra() {
        let meshes = [
            icosphere(1.0, 2),
            torus(2.0, 0.7, 30, 12),
            cylinder(1.0, 3.0, 24, 12),
            flat_grid(1.0, 12),
        ];
        let mut compared = 0;
        for mesh in &meshes {
            let mut e = LoopEngine::new(mesh, &ElasticaParams::default());
            compared += check_engine(&mut e, 25);
            // With a committed strip disabling part of g′ (§6.2).
            let p = e.vertex_position(0);
            if let Some(l) = e.best_loop(p) {
                e.cover_loop(&l, 0.3 * e.graph.g.diagonal);
                assert!(e.disabled_count() > 0);
                compared += check_engine(&mut e, 25);
            }
        }
        assert!(compared > 100, "only {compared} loops compared");
    }
}
