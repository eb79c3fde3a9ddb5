//! The true order of crossings that f32 cannot tell apart: nearly touching and coincident surfaces.
//!
//! Canonical hits are sorted by their f32 distance `t`, which is only good to a few ulps. Two surfaces
//! closer than that along a line (two spheres 1e-6 apart, a cube floating 1e-6 above the floor) can come
//! out swapped, and pairing then sees a line that arrives at a back side and leaves from a front side: a
//! false escape and a lost pair. Within such a window of close hits, the crossings are put in the order
//! of their f64 plane distances (the same planes the pair distances come from, exact to ~1e-16 / cos).
//!
//! Crossings at the *same* place (coincident planes: a cube standing on the floor, the two faces of a
//! two-sided panel, a decal on a wall) have no order at all. They are ordered so that the line alternates
//! between the space in front of the surfaces and the space behind them, which is what a vanishing gap
//! or thickness gives in the limit: a two-sided panel is crossed front-in, back, front-out (two pairs and
//! an empty segment, never the two sides paired at d = 0), and a solid standing on the floor is left
//! through its base straight onto the floor (a pair at d = 0, counted apart as degenerate). Coincident
//! surfaces facing the *same* way (a decal, a duplicated face) overlap: only one of them can be seen
//! there, and it is always the one first in the scene (lowest triangle index), from either side; each
//! such crossing is counted so that the report can warn.

use crate::geom::Normal;
use crate::trace::Hit;

/// Consecutive hits at most this many f32 ulps apart (at max(t, 1)) may be in either order: the
/// watertight test's `t` is good to a few ulps (a grazing crossing's is recomputed in f64 when it might
/// not be, `crate::trace::rust::watertight`), so this leaves a wide margin.
const WINDOW_ULPS: f32 = 16.0;

/// Crossings whose f64 plane distances differ by less than this (times max(t, 1)) are at the same place:
/// far below any real gap scx can trace (f32 vertices are ~1e-7 apart), far above f64 rounding of
/// coincident planes (~1e-16 / cos).
const COINCIDENT: f64 = 1e-10;

/// One crossing of a line with a patch, in f64.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Crossing {
    /// The patch crossed.
    pub patch: u32,
    /// The triangle reported (ties between coincident surfaces go by it).
    pub triangle: u32,
    /// Patch normal . line direction: < 0 arriving at the front side, > 0 leaving from it.
    pub cos: f64,
    /// Distance along the line to the patch's plane (the f32 `t` when the line lies in the plane).
    pub t: f64,
    /// The patch's unit normal.
    pub normal: Normal,
}

/// Whether some consecutive hits are too close for their f32 order to be trusted.
pub(crate) fn has_close_hits(hits: &[Hit]) -> bool {
    hits.windows(2).any(|w| close(w[0].t, w[1].t))
}

fn close(a: f32, b: f32) -> bool {
    b - a <= WINDOW_ULPS * f32::EPSILON * a.abs().max(1.0)
}

/// Reorders every window of close hits (`crossings[k]` is `hits[k]`) as the module documentation says,
/// and removes the crossings of every edge the line only touches ([`is_touch`]) unless `on_face` says
/// that each of them lies on its triangle: then the line really passes through the wedge at the edge
/// (a chord across the corner of a room, or through the tip of a solid's ridge) and is ordered like
/// any other window; returns how many crossings met a coincident surface facing the same way (an
/// overlap).
pub(crate) fn reorder(
    crossings: &mut Vec<Crossing>,
    hits: &[Hit],
    on_face: impl Fn(&Crossing) -> bool,
) -> u64 {
    let mut overlaps = 0;
    let mut touched = vec![false; crossings.len()];
    let mut start = 0;
    while start < hits.len() {
        let mut end = start + 1;
        while end < hits.len() && close(hits[end - 1].t, hits[end].t) {
            end += 1;
        }
        if end - start > 1 {
            let window = &crossings[start..end];
            if is_touch(window) && !window.iter().all(&on_face) {
                touched[start..end].fill(true);
            } else {
                // A window right after this one adapts to whichever space this one ends in, so its
                // first crossing (in f32 order, not yet in its true order) says nothing about it.
                let next_is_window = end + 1 < hits.len() && close(hits[end].t, hits[end + 1].t);
                overlaps += order_window_between(crossings, start, end, next_is_window);
            }
        }
        start = end;
    }
    if touched.contains(&true) {
        let mut k = 0;
        crossings.retain(|_| {
            k += 1;
            !touched[k - 1]
        });
    }
    overlaps
}

/// Whether a window of close crossings is a line touching an edge (or vertex) where surfaces meet at an
/// angle: planes not all parallel, as many arrivals at front sides as departures, none in its plane. Two
/// planes at an angle crossed within a few f32 ulps of each other are crossed at their common edge, and a
/// line that arrives at one front and leaves another there grazes the ridge or valley and goes on in the
/// space it came from (in exact arithmetic it may miss both patches; a line entering or leaving a solid
/// through an edge meets its faces all facing one way, and coincident parallel surfaces, a two-sided
/// panel or a decal, are ordered by [`order_window`] instead). Ordered by plane distance, a touch would
/// pair the two surfaces across ~1e-9 (a huge term of eq. 27) or read as two escapes from a closed scene
/// (seen on `@labyrinth`, lines touching the hall's outer edges); it is measure zero, so it is dropped.
///
/// The same signature is also left by a line that *does* cross both faces within a few ulps: across
/// the corner of an enclosure (the room's walls near their common edge, leaving one front and arriving
/// at the other), or through the tip of a ridge. Those crossings lie on their triangles, the touch's
/// do not (they are on the planes beyond the edge), which [`reorder`]'s caller tells from the f64 line
/// and triangles. Dropping the chords lost the largest terms of eq. 27 (`-2 log2 d` for `d` below a few
/// f32 ulps): I_s^c of the octahedron read 4e-5 low (4 standard errors of 20 Sobol' runs of 10^8 lines).
fn is_touch(window: &[Crossing]) -> bool {
    let arrivals = window.iter().filter(|c| c.cos < 0.0).count();
    let departures = window.iter().filter(|c| c.cos > 0.0).count();
    if arrivals == 0 || arrivals != departures || arrivals + departures != window.len() {
        return false;
    }
    let at_an_angle = |a: &Crossing, b: &Crossing| a.normal.dot(b.normal).abs() < 1.0 - 1e-9;
    if window.len() > SMALL_WINDOW {
        // Planes all parallel to the first are parallel to each other (to the tolerance's order):
        // O(n) for the stacks of a hostile file.
        return window[1..].iter().any(|b| at_an_angle(&window[0], b));
    }
    window
        .iter()
        .any(|a| window.iter().any(|b| at_an_angle(a, b)))
}

/// Orders the window `start..end` given its neighbours. The space the line is in before the window is
/// in front of the previous crossing's patch if it left that front side. At the start of the line it is
/// unknown (outside an object is in front of it, outside an enclosure behind its walls): it is then
/// chosen so that the line ends the window in the space the next crossing closes (in front if that one
/// arrives at a front side), and in front when there is no next crossing either, or when the next
/// crossing starts a window of its own (two-sided walls one after the other: that window is ordered
/// after this one, from the space this one ends in, so its first crossing in f32 order says nothing).
///
/// The plane distances give the true order of surfaces that nearly touch. They do not when the line
/// grazes an edge where two surfaces meet at an angle: it crosses both planes within rounding of the
/// edge, and which plane comes first says nothing (in exact arithmetic the line may miss both patches).
/// Such an order shows itself by leaving the line in a space the next crossing does not close (on
/// `@labyrinth`, a line grazing the floor's edge under a wall read as an escape from a closed scene); the
/// window is then ordered as crossings at one place, which lets the line graze the edge and go on in the
/// space it came from.
fn order_window_between(
    crossings: &mut [Crossing],
    start: usize,
    end: usize,
    next_is_window: bool,
) -> u64 {
    let before = (start > 0).then(|| crossings[start - 1].cos >= 0.0);
    let wanted = crossings
        .get(end)
        .filter(|_| !next_is_window)
        .map(|next| next.cos < 0.0);
    let starts: &[bool] = match before {
        Some(true) => &[true],
        Some(false) => &[false],
        None => &[true, false],
    };
    for same_place in [COINCIDENT, f64::INFINITY] {
        for &in_front in starts {
            let mut trial = crossings[start..end].to_vec();
            let (overlaps, ends_in_front) = order_window(&mut trial, in_front, same_place);
            if wanted.is_none_or(|w| w == ends_in_front) {
                crossings[start..end].copy_from_slice(&trial);
                return overlaps;
            }
        }
    }
    // No order is consistent with the neighbours (broken geometry): the plane distances' order.
    order_window(&mut crossings[start..end], starts[0], COINCIDENT).0
}

/// Whether two crossings are at one place along the line (coincident planes, within rounding).
pub(super) fn at_one_place(a: &Crossing, b: &Crossing) -> bool {
    (a.t - b.t).abs() <= COINCIDENT * a.t.abs().max(b.t.abs()).max(1.0)
}

/// Orders one window: by plane distance, and crossings whose plane distances differ by at most
/// `same_place` (times max(t, 1)) so that the line alternates between front and back space, starting
/// `in_front` or not. Returns the overlaps met and whether the line ends in front.
fn order_window(window: &mut [Crossing], in_front: bool, same_place: f64) -> (u64, bool) {
    if window.len() > SMALL_WINDOW {
        order_large_window(window, in_front, same_place)
    } else {
        order_small_window(window, in_front, same_place)
    }
}

/// Windows up to this many crossings are ordered by scanning the crossings at the current place for
/// each slot; larger ones (thousands of coplanar triangles stacked in a hostile file) by
/// [`order_large_window`], the same order at O(n log n).
const SMALL_WINDOW: usize = 32;

/// [`order_window`] by rescanning the crossings still to place: O(n^2), cheapest for the few crossings
/// of a window in a real scene.
fn order_small_window(window: &mut [Crossing], mut in_front: bool, same_place: f64) -> (u64, bool) {
    let mut rest: Vec<Crossing> = window.to_vec();
    rest.sort_by(|a, b| a.t.total_cmp(&b.t));
    let mut overlaps = 0;
    for slot in 0..window.len() {
        let t0 = rest[0].t;
        let here = rest
            .iter()
            .take_while(|c| c.t - t0 <= same_place * t0.abs().max(1.0))
            .count();
        let pick = choose(&rest[..here], in_front);
        let c = rest.remove(pick);
        overlaps += place(window, slot, c, &mut in_front);
    }
    (overlaps, in_front)
}

/// [`order_window`] in O(n log n): the crossings sorted by plane distance enter the candidates at the
/// current place (arrivals and departures apart, each ordered by triangle and then by sorted position,
/// which is how [`choose`] breaks ties) as the place moves on, and each slot takes [`choose`]'s pick
/// from them.
fn order_large_window(window: &mut [Crossing], mut in_front: bool, same_place: f64) -> (u64, bool) {
    use std::collections::BTreeSet;
    let mut sorted: Vec<Crossing> = window.to_vec();
    sorted.sort_by(|a, b| a.t.total_cmp(&b.t));
    let n = sorted.len();
    let mut placed = vec![false; n];
    // The first crossing not placed yet (the current place), and the first not yet a candidate.
    let (mut first, mut entered) = (0, 0);
    let mut arrivals: BTreeSet<(u32, usize)> = BTreeSet::new();
    let mut departures: BTreeSet<(u32, usize)> = BTreeSet::new();
    let mut overlaps = 0;
    for slot in 0..n {
        while placed[first] {
            first += 1;
        }
        let t0 = sorted[first].t;
        entered = entered.max(first);
        while entered < n && sorted[entered].t - t0 <= same_place * t0.abs().max(1.0) {
            let c = &sorted[entered];
            if c.cos < 0.0 {
                arrivals.insert((c.triangle, entered));
            } else if c.cos > 0.0 {
                departures.insert((c.triangle, entered));
            }
            entered += 1;
        }
        let first_arrival = arrivals.first().copied();
        let first_departure = departures.last().copied();
        let (preferred, other) = if in_front {
            (first_arrival, first_departure)
        } else {
            (first_departure, first_arrival)
        };
        let pick = match preferred.or(other) {
            Some(key) => {
                arrivals.remove(&key);
                departures.remove(&key);
                key.1
            }
            // Only crossings in their planes at this place: the nearest.
            None => first,
        };
        placed[pick] = true;
        overlaps += place(window, slot, sorted[pick], &mut in_front);
    }
    (overlaps, in_front)
}

/// Puts crossing `c` in `window[slot]` and moves the line into the space it leads to; returns 1 when
/// it overlaps the crossing before it (coincident, another patch, facing the same way), else 0.
fn place(window: &mut [Crossing], slot: usize, c: Crossing, in_front: &mut bool) -> u64 {
    let mut overlap = 0;
    if slot > 0 {
        let last = window[slot - 1];
        let coincident = (c.t - last.t).abs() <= COINCIDENT * c.t.abs().max(1.0);
        if coincident && c.patch != last.patch && c.cos * last.cos > 0.0 {
            overlap = 1;
        }
    }
    if c.cos != 0.0 {
        *in_front = c.cos > 0.0;
    }
    window[slot] = c;
    overlap
}

/// Which of the crossings at one place comes next: one that closes the current space (arriving at a
/// front side when in front, leaving one when behind), else one of the other facing, else one in the
/// plane. Among arrivals the lowest triangle goes first and among departures the highest, so that of
/// overlapping surfaces facing the same way the first in the scene is always the one next to the space
/// in front.
fn choose(candidates: &[Crossing], in_front: bool) -> usize {
    let arrivals = || candidates.iter().enumerate().filter(|(_, c)| c.cos < 0.0);
    let departures = || candidates.iter().enumerate().filter(|(_, c)| c.cos > 0.0);
    let first_arrival = arrivals().min_by_key(|(_, c)| c.triangle).map(|(k, _)| k);
    let first_departure = departures().max_by_key(|(_, c)| c.triangle).map(|(k, _)| k);
    let (preferred, other) = if in_front {
        (first_arrival, first_departure)
    } else {
        (first_departure, first_arrival)
    };
    preferred.or(other).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A crossing of a plane facing +z (all parallel).
    fn c(patch: u32, cos: f64, t: f64) -> Crossing {
        Crossing {
            patch,
            triangle: patch,
            cos,
            t,
            normal: Normal::Z,
        }
    }

    /// A crossing of a plane with the given normal.
    fn cn(patch: u32, cos: f64, t: f64, normal: [f64; 3]) -> Crossing {
        Crossing {
            normal: Normal::from_array(normal),
            ..c(patch, cos, t)
        }
    }

    fn patches(x: &[Crossing]) -> Vec<u32> {
        x.iter().map(|c| c.patch).collect()
    }

    fn hit(t: f32) -> Hit {
        Hit { t, triangle: 0 }
    }

    /// Swapped by f32, put back by the plane distances.
    #[test]
    fn close_hits_follow_the_plane_distances() {
        let hits = [hit(1.0), hit(2.0), hit(2.0 + 1e-7)];
        let mut x = vec![c(0, 0.5, 1.0), c(2, -0.5, 2.000001), c(1, 0.5, 2.0000005)];
        assert!(has_close_hits(&hits));
        assert_eq!(reorder(&mut x, &hits, |_| false), 0);
        assert_eq!(patches(&x), [0, 1, 2]);
    }

    /// A two-sided panel from front space: arrive at A, leave from B. A base on the floor from inside the
    /// solid: leave the base, arrive at the floor.
    #[test]
    fn coincident_crossings_alternate_between_front_and_back_space() {
        let hits = [hit(1.0), hit(2.0), hit(2.0)];
        let mut panel = vec![c(0, 0.5, 1.0), c(7, 0.5, 2.0), c(6, -0.5, 2.0)];
        reorder(&mut panel, &hits, |_| false);
        assert_eq!(patches(&panel), [0, 6, 7]);
        let mut base = vec![c(0, -0.5, 1.0), c(3, -0.5, 2.0), c(9, 0.5, 2.0)];
        reorder(&mut base, &hits, |_| false);
        assert_eq!(patches(&base), [0, 9, 3]);
        // From outside an enclosure up into a solid standing on its floor: the floor's back, the base
        // (d = 0), then the solid's top from behind.
        let hits = [hit(1.0), hit(1.0), hit(2.0)];
        let mut up = vec![c(9, -0.5, 1.0), c(3, 0.5, 1.0), c(8, 0.5, 2.0)];
        reorder(&mut up, &hits, |_| false);
        assert_eq!(patches(&up), [3, 9, 8]);
    }

    /// A line touching an edge where two surfaces meet at an angle crosses both planes within rounding,
    /// in either order: the touch is dropped and the line goes on in the space it came from.
    #[test]
    fn an_edge_touched_within_rounding_is_dropped() {
        let (floor, wall) = ([0.0, 1.0, 0.0], [0.0, 0.0, -1.0]);
        // From outside a closed hall, over the edge where its floor meets a wall, on to a wall seen from
        // behind: in plane order the wall comes first, which read as its front seeing out of the scene.
        let hits = [hit(1.0), hit(1.0), hit(2.0)];
        let mut start = vec![
            cn(115, 0.36, 1.0 + 1e-9, floor),
            cn(118, -0.26, 1.0, wall),
            cn(208, 0.9, 2.0, [1.0, 0.0, 0.0]),
        ];
        assert_eq!(reorder(&mut start, &hits, |_| false), 0);
        assert_eq!(patches(&start), [208]);
        // The line's only contact: the outer edge of the hall (two escapes before).
        let hits = [hit(1.0), hit(1.0)];
        let mut only = vec![
            cn(1615, 0.78, 1.0 + 1e-9, wall),
            cn(1523, -0.59, 1.0, floor),
        ];
        reorder(&mut only, &hits, |_| false);
        assert!(only.is_empty());
        // Exactly through the edge: the same plane distance, still a touch.
        let mut exact = vec![cn(1615, 0.78, 1.0, wall), cn(1523, -0.59, 1.0, floor)];
        reorder(&mut exact, &hits, |_| false);
        assert!(exact.is_empty());
        // Inside a room, grazing the edge of a block: the room's two walls see each other.
        let hits = [hit(1.0), hit(2.0), hit(2.0), hit(3.0)];
        let mut inside = vec![
            c(0, 0.5, 1.0),
            cn(1, -0.5, 2.0 + 1e-9, floor),
            cn(2, 0.5, 2.0, wall),
            c(3, -0.5, 3.0),
        ];
        reorder(&mut inside, &hits, |_| false);
        assert_eq!(patches(&inside), [0, 3]);
    }

    /// The touch's signature left by a line that crosses both faces (each crossing on its triangle):
    /// across the corner of a room, leaving one wall's front and arriving at the other's 1e-9 further
    /// on, the two are kept in their plane order (a pair across the corner, the largest term of eq. 27);
    /// through the tip of a block's ridge, arriving at one face and leaving the other, kept too (the
    /// line is inside the block between them).
    #[test]
    fn crossings_on_their_faces_are_no_touch() {
        let (floor, wall) = ([0.0, 0.0, 1.0], [0.6, 0.0, 0.8]);
        let hits = [hit(1.0), hit(1.0)];
        let mut corner = vec![cn(7, -0.59, 1.0 + 1e-9, floor), cn(8, 0.78, 1.0, wall)];
        reorder(&mut corner, &hits, |_| true);
        assert_eq!(patches(&corner), [8, 7]);
        let mut tip = vec![cn(8, 0.78, 1.0 + 1e-9, wall), cn(7, -0.59, 1.0, floor)];
        reorder(&mut tip, &hits, |_| true);
        assert_eq!(patches(&tip), [7, 8]);
        // One crossing off its triangle: a touch, dropped.
        let mut touch = vec![cn(7, -0.59, 1.0 + 1e-9, floor), cn(8, 0.78, 1.0, wall)];
        reorder(&mut touch, &hits, |c| c.patch == 7);
        assert!(touch.is_empty());
    }

    /// Parallel surfaces that only nearly touch keep their plane order; when that order would leave the
    /// line in a space its next crossing does not close, they are ordered as one place.
    #[test]
    fn parallel_surfaces_keep_a_consistent_order() {
        let hits = [hit(1.0), hit(2.0), hit(2.0), hit(3.0)];
        let mut near = vec![
            c(0, 0.5, 1.0),
            c(2, 0.5, 2.0 + 1e-9),
            c(1, -0.5, 2.0),
            c(3, -0.5, 3.0),
        ];
        reorder(&mut near, &hits, |_| false);
        assert_eq!(patches(&near), [0, 1, 2, 3]);
        let mut swapped = vec![
            c(0, 0.5, 1.0),
            c(1, -0.5, 2.0 + 1e-9),
            c(2, 0.5, 2.0),
            c(3, -0.5, 3.0),
        ];
        reorder(&mut swapped, &hits, |_| false);
        assert_eq!(patches(&swapped), [0, 1, 2, 3]);
    }

    /// Overlapping surfaces facing the same way: the first in the scene is next to the front space,
    /// whichever way the line goes, and the crossing is counted.
    #[test]
    fn overlaps_are_won_by_the_first_surface_and_counted() {
        let hits = [hit(1.0), hit(1.0), hit(3.0)];
        let mut down = vec![c(6, -0.5, 1.0), c(4, -0.5, 1.0), c(5, 0.5, 3.0)];
        assert_eq!(reorder(&mut down, &hits, |_| false), 1);
        assert_eq!(patches(&down), [4, 6, 5]);
        let mut up = vec![c(4, 0.5, 1.0), c(6, 0.5, 1.0), c(5, -0.5, 3.0)];
        assert_eq!(reorder(&mut up, &hits, |_| false), 1);
        assert_eq!(patches(&up), [6, 4, 5]);
    }

    /// The large-window order is the small-window order: random windows with many crossings at one
    /// place, both facings and crossings in their planes, repeated triangles, both place tolerances and
    /// both starting spaces.
    #[test]
    fn large_windows_are_ordered_as_small_ones() {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % n
        };
        for size in 1..120usize {
            for _ in 0..8 {
                let places = 1 + next(4);
                let window: Vec<Crossing> = (0..size)
                    .map(|_| {
                        let place = next(places) as f64;
                        let t = 1.0 + place * 1e-11 + next(3) as f64 * 1e-13;
                        let cos = [-0.5, 0.5, 0.0, -0.25, 0.25][next(5) as usize];
                        c(next(40) as u32, cos, t)
                    })
                    .collect();
                for same_place in [COINCIDENT, f64::INFINITY] {
                    for in_front in [true, false] {
                        let (mut small, mut large) = (window.clone(), window.clone());
                        let a = order_small_window(&mut small, in_front, same_place);
                        let b = order_large_window(&mut large, in_front, same_place);
                        assert_eq!((a, &small), (b, &large), "{window:?}");
                    }
                }
            }
        }
    }
}
