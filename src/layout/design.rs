//! The design session of dual strip weaving (Campen & Kobbelt 2014, *Dual
//! Strip Weaving*, §4.1 "Tools and Metaphors", with the strip compatibility
//! of §6.2 and the reflectional symmetry of §5.8): hovering proposes the best
//! loop through a point, the wheel browses ranked alternatives, clicks and
//! drags place positional and directional anchors the loop interpolates,
//! grabbing the loop inserts an anchor, a commit turns the loop into a
//! strip; every action is undoable.
//!
//! The state that undo/redo restores is small (committed loops with their
//! anchors, the anchors being edited, layout-vertex moves), so each action
//! pushes a full [`Snapshot`]. The engine's covered set (§6.2) is derived
//! from the committed loops: [`LoopEngine::cover_loop`] per loop at once,
//! replaced by the strip analysis' covered directions when they arrive
//! ([`LayoutDesign::apply_covered`], checked against [`LayoutDesign::revision`]).
//!
//! Deviations from the paper:
//! - §5.8 designs on one half M₀ with curves reflected on ∂M₀. Here the
//!   design runs on the whole surface and a committed loop's mirror image is
//!   added as a second strip: the loop through the mirrored anchors (or, for a
//!   hover proposal, through three mirrored directional samples of the loop),
//!   unless the loop is its own mirror image ([`is_self_symmetric`] within
//!   2 % of the bounding-box diagonal), in which case no copy is added.
//! - Wheel alternatives are those of [`LoopEngine::loops_through`] (one per
//!   direction class); with anchors placed the wheel does nothing (the loop
//!   is determined by the anchors).
//! - A click after browsing to an alternative places a *directional* anchor
//!   along that alternative's tangent, so the click keeps the loop that was
//!   shown (the paper: "the one which was already shown when the user
//!   hovered over this point").

use glam::DVec3;

use super::loops::{Anchor, DualLoop, HoverStep, LoopEngine};
use super::symmetry::{MirrorPlane, is_self_symmetric};

/// At most this many wheel alternatives are computed per hover point.
pub const MAX_ALTERNATIVES: usize = 8;
/// Stand-in strip half width for [`LoopEngine::cover_loop`], as a fraction
/// of the bounding-box diagonal (before the strip analysis replaces it).
pub const COVER_HALF_WIDTH: f64 = 0.04;
/// A loop within this mean distance (fraction of the diagonal) of its mirror
/// image is self-symmetric.
const SELF_SYMMETRIC: f64 = 0.02;

/// The mirror image of an anchor (position and direction).
fn reflect_anchor(m: &MirrorPlane, a: &Anchor) -> Anchor {
    let d = a.direction;
    Anchor {
        position: m.reflect(a.position),
        direction: d - 2.0 * d.dot(m.normal) * m.normal,
    }
}

/// A committed dual loop: the spine of one strip.
#[derive(Debug, Clone, PartialEq)]
pub struct CommittedLoop {
    /// The strip's identity: unique in the session, kept through delete,
    /// undo and redo (what per-strip settings such as grid counts key on;
    /// the strip's index shifts when an earlier strip is deleted).
    pub id: u64,
    pub dual: DualLoop,
    /// The anchors that made it (the hover point for a plain proposal).
    pub anchors: Vec<Anchor>,
    /// True for the mirror image added by the symmetry option.
    pub mirrored: bool,
}

/// The state undo and redo restore.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Snapshot {
    pub committed: Vec<CommittedLoop>,
    pub anchors: Vec<Anchor>,
    /// Layout-vertex moves (vertex id of the layout, new position), latest last.
    pub moves: Vec<(u32, DVec3)>,
}

/// The hover proposals at one point, best first; `all` once the wheel asked
/// for the alternatives.
#[derive(Debug, Clone)]
struct Hover {
    position: DVec3,
    /// The g vertex the proposals go through, while they are current
    /// (`None` once the covered strips changed under them).
    vertex: Option<usize>,
    proposals: Vec<DualLoop>,
    all: bool,
    index: usize,
    /// Whether `proposals` holds the exact best loop; else the one shown
    /// is provisional and the engine's search is unfinished
    /// ([`LayoutDesign::hover_begin`]).
    exact: bool,
    /// Exact, and not yet given out by [`LayoutDesign::hover_resume`].
    unreported: bool,
    /// Whether the exact loop that replaced a provisional one is that same
    /// loop (node for node): then it was on screen from the first answer.
    unchanged: bool,
}

/// Why an action did nothing.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DesignError {
    NoLoop,
    NoSuchStrip(usize),
    NothingToUndo,
    NothingToRedo,
}

impl std::fmt::Display for DesignError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DesignError::NoLoop => write!(f, "no loop through these anchors"),
            DesignError::NoSuchStrip(i) => write!(f, "there is no strip {i}"),
            DesignError::NothingToUndo => write!(f, "nothing to undo"),
            DesignError::NothingToRedo => write!(f, "nothing to redo"),
        }
    }
}

impl std::error::Error for DesignError {}

/// One design session on one mesh.
pub struct LayoutDesign {
    pub engine: LoopEngine,
    state: Snapshot,
    /// The loop through the anchors (None without anchors or when none exists).
    constrained: Option<DualLoop>,
    hover: Option<Hover>,
    mirror: Option<MirrorPlane>,
    undo: Vec<Snapshot>,
    redo: Vec<Snapshot>,
    /// Bumped whenever the committed loops change.
    revision: u64,
    /// The id the next committed loop gets ([`CommittedLoop::id`]).
    next_id: u64,
}

impl LayoutDesign {
    pub fn new(engine: LoopEngine) -> LayoutDesign {
        LayoutDesign {
            engine,
            state: Snapshot::default(),
            constrained: None,
            hover: None,
            mirror: None,
            undo: Vec::new(),
            redo: Vec::new(),
            revision: 0,
            next_id: 0,
        }
    }

    pub fn committed(&self) -> &[CommittedLoop] {
        &self.state.committed
    }

    pub fn anchors(&self) -> &[Anchor] {
        &self.state.anchors
    }

    pub fn moves(&self) -> &[(u32, DVec3)] {
        &self.state.moves
    }

    pub fn snapshot(&self) -> &Snapshot {
        &self.state
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    /// Changes whenever the committed loops change (commit, delete, undo,
    /// redo); an analysis computed for an older revision is stale.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    pub fn mirror(&self) -> Option<MirrorPlane> {
        self.mirror
    }

    /// Sets or clears the mirror plane used by later commits (a setting, not
    /// an undoable action).
    pub fn set_mirror(&mut self, mirror: Option<MirrorPlane>) {
        self.mirror = mirror;
    }

    /// The loop that Enter would commit: the loop through the anchors when
    /// there are any, else the browsed hover proposal.
    pub fn proposal(&self) -> Option<&DualLoop> {
        if !self.state.anchors.is_empty() {
            return self.constrained.as_ref();
        }
        let h = self.hover.as_ref()?;
        h.proposals.get(h.index)
    }

    /// Index of the browsed alternative (0: the best) and how many are known.
    pub fn browse_position(&self) -> (usize, usize) {
        self.hover
            .as_ref()
            .map_or((0, 0), |h| (h.index, h.proposals.len()))
    }

    /// Hovering at `position`: the best loop through it (§4.1). With anchors
    /// placed, the proposal is the loop through them and hovering changes
    /// nothing.
    pub fn hover(&mut self, position: DVec3) -> Option<&DualLoop> {
        self.hover_begin(position, u64::MAX).0
    }

    /// Hovering answered progressively: at most `budget` settled g′ nodes
    /// of search now ([`LoopEngine::hover_begin`]); returns the proposal and
    /// whether it is the exact best loop. A provisional proposal is
    /// replaced by the exact one through [`Self::hover_resume`] (or, before
    /// Enter, the wheel or new covered strips, by finishing the search:
    /// what is committed or browsed is always the exact loop's).
    pub fn hover_begin(&mut self, position: DVec3, budget: u64) -> (Option<&DualLoop>, bool) {
        let mut exact = true;
        if self.state.anchors.is_empty() {
            // The pointer still over the same vertex: the same loops, nothing
            // searched again (a move shows the best one again, as a new
            // search would).
            let vertex = self.engine.nearest_vertex(position);
            if let Some(h) = self
                .hover
                .as_mut()
                .filter(|h| vertex.is_some() && h.vertex == vertex)
            {
                h.position = position;
                h.index = 0;
                exact = h.exact;
                return (self.proposal(), exact);
            }
            let (proposals, done) = match self.engine.hover_begin(position, budget) {
                HoverStep::Exact(l) => (l.into_iter().collect(), true),
                HoverStep::Provisional(l) => (l.into_iter().collect(), false),
            };
            exact = done;
            self.hover = Some(Hover {
                position,
                vertex,
                proposals,
                all: false,
                index: 0,
                exact,
                unreported: false,
                unchanged: false,
            });
        }
        (self.proposal(), exact)
    }

    /// Resumes an unfinished hover for at most `budget` settled g′ nodes.
    /// Returns the exact proposal once, when it has become exact (here or
    /// by an action that finished it since); `None` otherwise.
    pub fn hover_resume(&mut self, budget: u64) -> Option<Option<&DualLoop>> {
        let h = self.hover.as_mut()?;
        if !h.exact {
            // The engine forgot it (another query since): begin again.
            let step = if self.engine.hover_pending() {
                self.engine.hover_resume(budget)
            } else {
                match self.engine.hover_begin(h.position, budget) {
                    HoverStep::Exact(l) => Some(l),
                    HoverStep::Provisional(_) => None,
                }
            };
            let l = step?;
            let key = |l: Option<&DualLoop>| l.map(|l| (l.nodes.clone(), l.closed));
            h.unchanged = key(h.proposals.first()) == key(l.as_ref());
            h.proposals = l.into_iter().collect();
            h.exact = true;
            h.unreported = true;
        }
        if !std::mem::take(&mut h.unreported) {
            return None;
        }
        Some(h.proposals.get(h.index))
    }

    /// Whether the exact loop [`Self::hover_resume`] gave out last is the
    /// provisional one shown before it, node for node.
    pub fn hover_unchanged(&self) -> bool {
        self.hover.as_ref().is_some_and(|h| h.unchanged)
    }

    /// Whether [`Self::hover_resume`] has something to do.
    pub fn hover_pending(&self) -> bool {
        self.hover
            .as_ref()
            .is_some_and(|h| !h.exact || h.unreported)
    }

    /// Finishes an unfinished hover search now; `report`: the exact
    /// proposal is still to be given out by [`Self::hover_resume`] (it is
    /// not when the action's own answer shows it).
    fn finish_hover(&mut self, report: bool) {
        if self.hover.as_ref().is_some_and(|h| !h.exact) {
            while self.hover_resume(u64::MAX).is_none() {}
            if let Some(h) = self.hover.as_mut() {
                h.unreported = report;
            }
        }
    }

    /// Forgets the hover proposals and an unfinished search.
    fn drop_hover(&mut self) {
        self.hover = None;
        self.engine.cancel_hover();
    }

    /// Forgets the hover proposals (e.g. after a warm-up query).
    pub fn clear_hover(&mut self) {
        self.drop_hover();
    }

    /// The wheel: moves `delta` steps through the ranked alternatives at the
    /// hover point (computed on the first turn), wrapping around.
    pub fn browse(&mut self, delta: i32) -> Option<&DualLoop> {
        if !self.state.anchors.is_empty() {
            return self.proposal();
        }
        // The alternatives are ranked after the exact best loop.
        self.finish_hover(false);
        let engine = &mut self.engine;
        let h = self.hover.as_mut()?;
        if !h.all {
            // The shown loop stays first (ties may rank another equal-cost
            // route of its direction class first).
            let alternatives = engine.loops_through(h.position, MAX_ALTERNATIVES);
            if h.proposals.is_empty() {
                h.proposals = alternatives;
            } else {
                h.proposals.extend(alternatives.into_iter().skip(1));
            }
            h.all = true;
        }
        let n = h.proposals.len() as i64;
        if n > 0 {
            h.index = (h.index as i64 + delta as i64).rem_euclid(n) as usize;
        }
        self.proposal()
    }

    /// Places an anchor after the others (a click: positional; a drag:
    /// directional). Undoable.
    pub fn add_anchor(&mut self, position: DVec3, direction: Option<DVec3>) -> Option<&DualLoop> {
        let mut anchor = match direction.and_then(DVec3::try_normalize) {
            Some(d) => Anchor::directional(position, d),
            None => Anchor::positional(position),
        };
        // The first click keeps a browsed alternative: its tangent there.
        if self.state.anchors.is_empty() && anchor.direction == DVec3::ZERO {
            if let Some(h) = self.hover.as_ref().filter(|h| h.index > 0) {
                if let Some(t) = h
                    .proposals
                    .get(h.index)
                    .and_then(|l| tangent_at(l, position))
                {
                    anchor.direction = t;
                }
            }
        }
        if self.hover.as_ref().is_some_and(|h| !h.exact) {
            self.drop_hover();
        }
        self.push_undo();
        self.state.anchors.push(anchor);
        self.update_constrained();
        self.proposal()
    }

    /// While dragging: the last anchor becomes directional along `direction`
    /// (zero: positional again). Part of the drag's action, not a new one.
    pub fn set_last_anchor_direction(&mut self, direction: DVec3) -> Option<&DualLoop> {
        let last = self.state.anchors.last_mut()?;
        last.direction = direction.try_normalize().unwrap_or(DVec3::ZERO);
        self.update_constrained();
        self.proposal()
    }

    /// Grab-and-drag (§4.1): a new anchor at `position`, inserted between
    /// the two anchors whose stretch of the current loop passes nearest to
    /// `grabbed` (the point where the loop was grabbed). Without a current
    /// loop it is appended. Returns the new anchor's index. Undoable.
    pub fn insert_anchor_on_loop(&mut self, grabbed: DVec3, position: DVec3) -> usize {
        let index = self.insertion_index(grabbed);
        if self.hover.as_ref().is_some_and(|h| !h.exact) {
            self.drop_hover();
        }
        self.push_undo();
        self.state
            .anchors
            .insert(index, Anchor::positional(position));
        self.update_constrained();
        index
    }

    /// Moves anchor `i` to `position` (the drag after a grab). Part of the
    /// grab's action, not a new one.
    pub fn move_anchor(&mut self, i: usize, position: DVec3) -> Option<&DualLoop> {
        self.state.anchors.get_mut(i)?.position = position;
        self.update_constrained();
        self.proposal()
    }

    /// Idle time: settles up to `budget` g′ nodes of the distance fields
    /// the next query through the current anchors reads, then of the
    /// distances from ∂ that hovering reads ([`LoopEngine::prepare_fields`];
    /// nothing it answers changes, only how soon). Returns whether more
    /// remains.
    pub fn prepare_fields(&mut self, budget: u64) -> bool {
        self.engine.prepare_fields(&self.state.anchors, budget)
    }

    /// Escape: drops the anchors. Undoable (when there were any).
    pub fn clear_anchors(&mut self) {
        if self.state.anchors.is_empty() {
            return;
        }
        self.push_undo();
        self.state.anchors.clear();
        self.constrained = None;
    }

    /// Enter: the proposal becomes a strip; with a mirror plane also its
    /// mirror image unless the loop is self-symmetric. Returns how many loops
    /// were added. Undoable.
    pub fn commit(&mut self) -> Result<usize, DesignError> {
        // Enter commits the exact best loop, never a provisional one.
        self.finish_hover(false);
        let dual = self.proposal().cloned().ok_or(DesignError::NoLoop)?;
        let anchors = if self.state.anchors.is_empty() {
            let h = self.hover.as_ref().ok_or(DesignError::NoLoop)?;
            let direction = if h.index > 0 {
                tangent_at(&dual, h.position).unwrap_or(DVec3::ZERO)
            } else {
                DVec3::ZERO
            };
            vec![Anchor::directional(h.position, direction)]
        } else {
            self.state.anchors.clone()
        };
        // The mirror image is searched before either strip covers the surface.
        let copy = self
            .mirror
            .and_then(|m| self.mirror_loop(&m, &dual, &anchors));
        self.push_undo();
        let mut added = vec![CommittedLoop {
            id: 0,
            dual,
            anchors,
            mirrored: false,
        }];
        added.extend(copy);
        let count = added.len();
        for c in &mut added {
            c.id = self.next_id;
            self.next_id += 1;
            self.engine.cover_loop(&c.dual, self.cover_half_width());
        }
        self.state.committed.extend(added);
        self.state.anchors.clear();
        self.constrained = None;
        self.drop_hover();
        self.revision += 1;
        Ok(count)
    }

    /// Deletes strip `i` (with its mirror partner). Undoable.
    pub fn delete_strip(&mut self, i: usize) -> Result<(), DesignError> {
        let committed = &self.state.committed;
        if i >= committed.len() {
            return Err(DesignError::NoSuchStrip(i));
        }
        let start = if committed[i].mirrored && i > 0 && !committed[i - 1].mirrored {
            i - 1
        } else {
            i
        };
        let end = if committed.get(start + 1).is_some_and(|c| c.mirrored) {
            start + 2
        } else {
            start + 1
        };
        self.push_undo();
        self.state.committed.drain(start..end);
        self.committed_changed();
        Ok(())
    }

    /// Records a layout-vertex move (dragging a vertex of the primal
    /// layout). Undoable.
    pub fn move_layout_vertex(&mut self, vertex: u32, position: DVec3) {
        self.push_undo();
        self.state.moves.retain(|m| m.0 != vertex);
        self.state.moves.push((vertex, position));
    }

    pub fn undo(&mut self) -> Result<(), DesignError> {
        let previous = self.undo.pop().ok_or(DesignError::NothingToUndo)?;
        let now = std::mem::replace(&mut self.state, previous);
        self.restored(&now);
        self.redo.push(now);
        Ok(())
    }

    pub fn redo(&mut self) -> Result<(), DesignError> {
        let next = self.redo.pop().ok_or(DesignError::NothingToRedo)?;
        let now = std::mem::replace(&mut self.state, next);
        self.restored(&now);
        self.undo.push(now);
        Ok(())
    }

    /// §6.2 from the strip analysis: per-vertex covered directions of the
    /// strips of revision `revision` (ignored when stale). Returns whether
    /// they were applied. The hover proposal on screen is kept (the
    /// analysis arrives from its own worker, possibly after the user
    /// hovered; Enter commits the loop that is shown); the next hover
    /// searches with the new covered set.
    pub fn apply_covered(&mut self, revision: u64, covered: &[Vec<DVec3>]) -> bool {
        if revision != self.revision {
            return false;
        }
        // The hover shown becomes exact for the covered set it was hovered
        // in (and is given out as such).
        self.finish_hover(true);
        self.engine.set_covered(covered);
        // The proposal stays on screen; the next hover searches again.
        if let Some(h) = self.hover.as_mut() {
            h.vertex = None;
        }
        true
    }

    fn cover_half_width(&self) -> f64 {
        COVER_HALF_WIDTH * self.engine.graph.g.diagonal
    }

    fn push_undo(&mut self) {
        self.undo.push(self.state.clone());
        self.redo.clear();
    }

    /// After undo/redo replaced `before` by the current state.
    fn restored(&mut self, before: &Snapshot) {
        if before.committed != self.state.committed {
            self.committed_changed();
        }
        self.update_constrained();
        self.drop_hover();
    }

    /// Recomputes the stand-in covered set from the committed loops.
    fn committed_changed(&mut self) {
        self.engine.clear_covered();
        let hw = self.cover_half_width();
        for c in &self.state.committed {
            self.engine.cover_loop(&c.dual, hw);
        }
        self.drop_hover();
        self.revision += 1;
    }

    fn update_constrained(&mut self) {
        self.constrained = if self.state.anchors.is_empty() {
            None
        } else {
            self.engine.constrained_loop(&self.state.anchors)
        };
    }

    /// Where a grabbed point goes in the anchor order: after the anchor
    /// whose position along the loop precedes the grabbed point's.
    fn insertion_index(&self, grabbed: DVec3) -> usize {
        let n = self.state.anchors.len();
        let Some(l) = self.constrained.as_ref().filter(|_| n >= 2) else {
            return n;
        };
        let s = |p: DVec3| arc_parameter(&l.points, p);
        let sp = s(grabbed);
        let sa: Vec<f64> = self.state.anchors.iter().map(|a| s(a.position)).collect();
        let total = l.length().max(f64::MIN_POSITIVE);
        if l.closed {
            // Anchor i's stretch runs from sa[i] forward to sa[i + 1]
            // (cyclically); the loop may run either way through the anchors,
            // so measure forward in the direction the anchors are ordered.
            let forward = |a: f64, b: f64| (b - a).rem_euclid(total);
            let ahead: f64 = (0..n).map(|i| forward(sa[i], sa[(i + 1) % n])).sum();
            let reversed = ahead > 1.5 * total;
            for i in 0..n {
                let (a, b) = (sa[i], sa[(i + 1) % n]);
                let inside = if reversed {
                    forward(sp, a) <= forward(b, a)
                } else {
                    forward(a, sp) <= forward(a, b)
                };
                if inside {
                    return i + 1;
                }
            }
            n
        } else {
            // Open curve: anchors ordered along it (increasing or decreasing).
            let increasing = sa[n - 1] >= sa[0];
            sa.iter()
                .filter(|&&a| if increasing { a <= sp } else { a >= sp })
                .count()
        }
    }

    /// The mirror image of a loop being committed, or None when the loop is
    /// its own mirror image or no mirrored loop exists.
    fn mirror_loop(
        &mut self,
        m: &MirrorPlane,
        dual: &DualLoop,
        anchors: &[Anchor],
    ) -> Option<CommittedLoop> {
        let mirrored: Vec<DVec3> = dual.points.iter().map(|&p| m.reflect(p)).collect();
        let tol = SELF_SYMMETRIC * self.engine.graph.g.diagonal;
        if is_self_symmetric(&dual.points, &mirrored, tol) {
            return None;
        }
        let mut mirrored_anchors: Vec<Anchor> =
            anchors.iter().map(|a| reflect_anchor(m, a)).collect();
        if mirrored_anchors.len() < 2 {
            mirrored_anchors = samples_with_tangents(&mirrored, 3)
                .into_iter()
                .map(|(p, t)| Anchor::directional(p, t))
                .collect();
        }
        let l = self.engine.constrained_loop(&mirrored_anchors)?;
        Some(CommittedLoop {
            id: 0, // set by the commit
            dual: l,
            anchors: mirrored_anchors,
            mirrored: true,
        })
    }
}

/// Arc-length parameter of the point of `points` nearest to `p`.
fn arc_parameter(points: &[DVec3], p: DVec3) -> f64 {
    let mut best = (f64::INFINITY, 0.0);
    let mut s = 0.0;
    for w in points.windows(2) {
        let d = w[1] - w[0];
        let len2 = d.length_squared();
        let t = if len2 > 0.0 {
            ((p - w[0]).dot(d) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let dist = p.distance_squared(w[0] + d * t);
        if dist < best.0 {
            best = (dist, s + t * len2.sqrt());
        }
        s += len2.sqrt();
    }
    best.1
}

/// The loop's unit tangent at its point nearest to `p`.
fn tangent_at(l: &DualLoop, p: DVec3) -> Option<DVec3> {
    l.points
        .windows(2)
        .filter(|w| w[0] != w[1])
        .min_by(|a, b| {
            let da = p.distance_squared((a[0] + a[1]) * 0.5);
            let db = p.distance_squared((b[0] + b[1]) * 0.5);
            da.total_cmp(&db)
        })
        .and_then(|w| (w[1] - w[0]).try_normalize())
}

/// `count` points evenly spaced by arc length along a polyline, with unit
/// tangents.
fn samples_with_tangents(points: &[DVec3], count: usize) -> Vec<(DVec3, DVec3)> {
    let total: f64 = points.windows(2).map(|w| w[0].distance(w[1])).sum();
    if total <= 0.0 {
        return Vec::new();
    }
    let mut out = Vec::with_capacity(count);
    let mut s = 0.0;
    let mut k = 0;
    for w in points.windows(2) {
        let len = w[0].distance(w[1]);
        while k < count && (k as f64 + 0.5) * total / count as f64 <= s + len {
            let target = (k as f64 + 0.5) * total / count as f64;
            let t = if len > 0.0 { (target - s) / len } else { 0.0 };
            if let Some(d) = (w[1] - w[0]).try_normalize() {
                out.push((w[0].lerp(w[1], t), d));
            }
            k += 1;
        }
        s += len;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::ElasticaParams;
    use crate::mesh::generate::torus;

    /// Mean over `a` of the distance to the nearest point of `b`'s vertices.
    fn mean_distance(a: &[DVec3], b: &[DVec3]) -> f64 {
        if a.is_empty() || b.is_empty() {
            return f64::INFINITY;
        }
        let sum: f64 = a
            .iter()
            .map(|p| {
                b.iter()
                    .map(|q| p.distance_squared(*q))
                    .fold(f64::INFINITY, f64::min)
                    .sqrt()
            })
            .sum();
        sum / a.len() as f64
    }

    fn torus_design() -> LayoutDesign {
        let mesh = torus(2.0, 0.7, 40, 16);
        LayoutDesign::new(LoopEngine::new(&mesh, &ElasticaParams::default()))
    }

    /// A point on the torus surface at angles (u, v) (see `generate::torus`).
    fn on_torus(u: f64, v: f64) -> DVec3 {
        let ring = 2.0 + 0.7 * v.cos();
        DVec3::new(ring * u.cos(), ring * u.sin(), 0.7 * v.sin())
    }

    /// A second hover over the same vertex shows the same best loop without
    /// a search (and the best again after the wheel); a hover at another
    /// vertex, or after the covered strips changed, searches.
    #[test]
    fn hover_over_the_same_vertex_reuses_its_loops() {
        let mut d = torus_design();
        let p = on_torus(0.3, 0.0);
        let first = d.hover(p).cloned().expect("a loop");
        d.browse(1);
        let settled = d.engine.settled_nodes();
        // A point a little off the vertex: the same nearest vertex.
        let v = d.engine.nearest_vertex(p).unwrap();
        let nearby = on_torus(0.3 + 1e-3, 1e-3);
        assert_eq!(d.engine.nearest_vertex(nearby), Some(v));
        assert_eq!(d.hover(nearby), Some(&first), "the best loop again");
        assert_eq!(d.engine.settled_nodes(), settled, "nothing searched");
        // Another vertex: a search.
        let other = on_torus(1.3, 0.5);
        assert_ne!(d.engine.nearest_vertex(other), Some(v));
        d.hover(other).expect("a loop");
        assert!(d.engine.settled_nodes() > settled);
        // Back, after new covered directions: searched again.
        d.hover(p);
        let rev = d.revision();
        assert!(d.apply_covered(rev, &[]));
        let settled = d.engine.settled_nodes();
        assert_eq!(d.hover(p), Some(&first));
        assert!(
            d.engine.settled_nodes() > settled,
            "searched after the covered strips changed"
        );
    }

    /// A hover answered progressively (one settled node before the first
    /// answer: provisional) gives the exact loop once through
    /// `hover_resume`; Enter before that commits the exact loop, not the
    /// provisional one; the wheel ranks after the exact loop; new covered
    /// strips arriving meanwhile finish it for the strips it was hovered
    /// with and give it out. The exact loop is `hover`'s on a fresh design.
    #[test]
    fn a_provisional_hover_is_replaced_by_the_exact_loop_and_never_committed() {
        let points = [on_torus(0.3, 0.0), on_torus(1.1, 2.0), on_torus(2.4, 0.9)];
        let mut provisional_worse = 0;
        for (i, &p) in points.iter().enumerate() {
            let exact = torus_design().hover(p).cloned().expect("a loop");
            // Resumed to the end, from first answers after 1 to 1 000 nodes.
            for budget in [1, 100, 300, 1_000] {
                let mut d = torus_design();
                let (shown, done) = d.hover_begin(p, budget);
                let shown = shown.cloned();
                if done {
                    assert_eq!(shown.as_ref(), Some(&exact), "point {i}: at once");
                    continue;
                }
                assert!(d.hover_pending());
                if let Some(l) = &shown {
                    assert!(l.cost >= exact.cost, "point {i}");
                    provisional_worse += usize::from(l.nodes != exact.nodes);
                }
                let got = loop {
                    if let Some(l) = d.hover_resume(50) {
                        break l.cloned();
                    }
                };
                assert_eq!(got.as_ref(), Some(&exact), "point {i}: resumed");
                assert_eq!(d.hover_unchanged(), shown.as_ref() == Some(&exact));
                assert!(d.hover_resume(50).is_none(), "given out once");
                assert!(!d.hover_pending());
                assert_eq!(d.proposal(), Some(&exact));
            }
            // Enter while provisional.
            let mut d = torus_design();
            assert!(!d.hover_begin(p, 1).1);
            assert_eq!(d.commit(), Ok(1));
            assert_eq!(d.committed()[0].dual, exact, "point {i}: committed");
            assert!(!d.hover_pending());
            // The wheel while provisional: the exact loop first.
            let mut d = torus_design();
            d.hover_begin(p, 1);
            d.browse(1);
            d.browse(-1);
            assert_eq!(d.proposal(), Some(&exact), "point {i}: browsed back");
            // New covered strips while provisional.
            let mut d = torus_design();
            d.hover_begin(p, 1);
            let n = d.engine.graph.g.vertex_count();
            let covered = vec![vec![DVec3::X, DVec3::Y, DVec3::Z]; n];
            assert!(d.apply_covered(d.revision(), &covered));
            assert_eq!(
                d.hover_resume(50).map(|l| l.cloned()),
                Some(Some(exact.clone()))
            );
        }
        assert!(
            provisional_worse > 0,
            "every provisional loop was already the exact one"
        );
    }

    #[test]
    fn hover_then_commit_adds_a_strip_and_undo_redo_round_trip() {
        let mut d = torus_design();
        let p = on_torus(0.3, 0.0);
        let best = d
            .hover(p)
            .cloned()
            .expect("a loop through the outer equator");
        assert!(best.closed);
        assert_eq!(d.commit(), Ok(1));
        assert_eq!(d.committed().len(), 1);
        assert_eq!(d.committed()[0].dual, best);
        let after_one = d.snapshot().clone();
        let rev = d.revision();

        d.add_anchor(on_torus(2.0, 1.5), None);
        d.add_anchor(on_torus(2.5, 1.5), None);
        let with_anchors = d.snapshot().clone();
        assert_eq!(with_anchors.anchors.len(), 2);

        d.undo().unwrap();
        assert_eq!(d.anchors().len(), 1);
        d.undo().unwrap();
        assert_eq!(d.snapshot(), &after_one, "undo restores exactly");
        assert_eq!(d.revision(), rev, "committed loops did not change");
        d.redo().unwrap();
        d.redo().unwrap();
        assert_eq!(d.snapshot(), &with_anchors, "redo restores exactly");
        assert!(d.proposal().is_some(), "the constrained loop is recomputed");
        assert_eq!(d.redo(), Err(DesignError::NothingToRedo));

        // Undo all the way back to the empty design.
        while d.can_undo() {
            d.undo().unwrap();
        }
        assert!(d.committed().is_empty() && d.anchors().is_empty());
        assert_eq!(d.engine.disabled_count(), 0, "nothing covered");
    }

    #[test]
    fn a_new_action_clears_redo() {
        let mut d = torus_design();
        d.add_anchor(on_torus(0.0, 0.0), None);
        d.add_anchor(on_torus(0.0, 2.0), None);
        d.undo().unwrap();
        assert!(d.can_redo());
        d.add_anchor(on_torus(1.0, 1.0), None);
        assert!(!d.can_redo());
        assert_eq!(d.redo(), Err(DesignError::NothingToRedo));
        assert_eq!(d.anchors().len(), 2);
        assert_eq!(d.anchors()[1].position, on_torus(1.0, 1.0));
    }

    #[test]
    fn delete_then_undo_restores_the_strip_and_its_covering() {
        let mut d = torus_design();
        d.hover(on_torus(0.0, 0.0));
        d.commit().unwrap();
        d.hover(on_torus(1.0, 1.6));
        d.commit().unwrap();
        assert_eq!(d.committed().len(), 2);
        let before = d.snapshot().clone();
        let disabled = d.engine.disabled_count();
        assert!(disabled > 0, "committed strips disable g′-nodes (§6.2)");
        d.delete_strip(0).unwrap();
        assert_eq!(d.committed().len(), 1);
        assert_eq!(d.committed()[0], before.committed[1]);
        assert!(d.engine.disabled_count() < disabled);
        d.undo().unwrap();
        assert_eq!(d.snapshot(), &before);
        assert_eq!(d.engine.disabled_count(), disabled, "covering recomputed");
        assert_eq!(d.delete_strip(7), Err(DesignError::NoSuchStrip(7)));
    }

    /// A strip keeps its id through the deletion of an earlier strip, undo
    /// and redo; a strip committed after an undo gets an id never used.
    #[test]
    fn strips_keep_their_ids_through_delete_undo_and_redo() {
        let mut d = torus_design();
        for p in [on_torus(0.0, 0.0), on_torus(1.0, 1.6), on_torus(2.5, 0.8)] {
            d.hover(p);
            d.commit().unwrap();
        }
        let ids = |d: &LayoutDesign| d.committed().iter().map(|c| c.id).collect::<Vec<_>>();
        let three = ids(&d);
        assert_eq!(three.len(), 3);
        assert!(three[0] != three[1] && three[1] != three[2] && three[0] != three[2]);
        d.delete_strip(0).unwrap();
        assert_eq!(ids(&d), three[1..], "the later strips keep their ids");
        d.undo().unwrap();
        assert_eq!(ids(&d), three);
        d.redo().unwrap();
        assert_eq!(ids(&d), three[1..]);
        d.undo().unwrap();
        d.undo().unwrap();
        assert_eq!(ids(&d), three[..2]);
        d.hover(on_torus(3.5, 0.4));
        d.commit().unwrap();
        let fresh = ids(&d)[2];
        assert!(!three.contains(&fresh), "a new strip, a new id: {fresh}");
    }

    #[test]
    fn the_wheel_browses_distinct_alternatives_and_wraps() {
        let mut d = torus_design();
        let p = on_torus(0.5, 0.0);
        let best = d.hover(p).cloned().unwrap();
        let first = d.browse(0).cloned().unwrap();
        assert_eq!(first.points, best.points, "alternative 0 is the best loop");
        let (_, n) = d.browse_position();
        assert!(n >= 2, "a torus point has several loop directions: {n}");
        let second = d.browse(1).cloned().unwrap();
        assert_ne!(second.points, best.points);
        assert!(second.cost >= best.cost);
        d.browse(n as i32 - 1);
        assert_eq!(d.browse_position().0, 0, "wraps around");
        // Clicking on an alternative keeps it: a directional anchor along it.
        d.browse(1);
        d.add_anchor(p, None);
        assert_ne!(d.anchors()[0].direction, DVec3::ZERO);
    }

    #[test]
    fn grabbing_inserts_the_anchor_between_its_neighbours_along_the_loop() {
        let mut d = torus_design();
        // Three anchors along the outer equator (v = 0) at u = 0, 2, 4.
        for u in [0.0, 2.0, 4.0] {
            d.add_anchor(on_torus(u, 0.0), None);
        }
        let l = d.proposal().cloned().expect("a loop through three anchors");
        assert!(l.closed);
        // Grabbed between the second and third anchors (u = 3).
        let i = d.insert_anchor_on_loop(on_torus(3.0, 0.0), on_torus(3.0, 0.3));
        assert_eq!(i, 2);
        assert_eq!(d.anchors().len(), 4);
        d.undo().unwrap();
        // Grabbed between the third and the first (u = 5.5): after the third.
        let i = d.insert_anchor_on_loop(on_torus(5.5, 0.0), on_torus(5.5, 0.3));
        assert_eq!(i, 3);
    }

    #[test]
    fn a_mirror_plane_adds_the_mirror_image_unless_self_symmetric() {
        let mut d = torus_design();
        // Plane x = 0: a meridian loop at u = 0.4 has its image at u = π − 0.4.
        d.set_mirror(MirrorPlane::new(DVec3::ZERO, DVec3::X));
        d.add_anchor(on_torus(0.4, 0.0), Some(DVec3::Z));
        assert_eq!(d.commit(), Ok(2));
        let image = &d.committed()[1];
        assert!(image.mirrored);
        let m = MirrorPlane::new(DVec3::ZERO, DVec3::X).unwrap();
        let reflected: Vec<DVec3> = d.committed()[0]
            .dual
            .points
            .iter()
            .map(|&p| m.reflect(p))
            .collect();
        assert!(
            mean_distance(&image.dual.points, &reflected) < 0.05,
            "the copy is the mirror image"
        );
        // The outer equator is its own mirror image: no copy.
        d.add_anchor(
            on_torus(1.0, 0.0),
            Some(DVec3::new(-1.0f64.sin(), 1.0f64.cos(), 0.0)),
        );
        assert_eq!(d.commit(), Ok(1));
        // Deleting the copy deletes its original too.
        d.delete_strip(1).unwrap();
        assert_eq!(d.committed().len(), 1);
        assert!(!d.committed()[0].mirrored);
    }

    #[test]
    fn stale_analysis_is_ignored() {
        let mut d = torus_design();
        d.hover(on_torus(0.0, 0.0));
        d.commit().unwrap();
        let rev = d.revision();
        let n = d.engine.graph.g.vertex_count();
        d.undo().unwrap();
        assert!(!d.apply_covered(rev, &vec![Vec::new(); n]));
        assert!(d.apply_covered(d.revision(), &vec![Vec::new(); n]));
        assert_eq!(d.engine.disabled_count(), 0);
    }

    #[test]
    fn commit_without_a_proposal_is_an_error() {
        let mut d = torus_design();
        assert_eq!(d.commit(), Err(DesignError::NoLoop));
        assert!(!d.can_undo());
        assert_eq!(d.undo(), Err(DesignError::NothingToUndo));
    }
}
