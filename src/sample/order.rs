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

use crate::trace::Hit;

/// Consecutive hits at most this many f32 ulps apart (at max(t, 1)) may be in either order: the
/// watertight test's `t` is good to a few ulps, so this leaves a wide margin.
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
}

/// Whether some consecutive hits are too close for their f32 order to be trusted.
pub(crate) fn has_close_hits(hits: &[Hit]) -> bool {
    hits.windows(2).any(|w| close(w[0].t, w[1].t))
}

fn close(a: f32, b: f32) -> bool {
    b - a <= WINDOW_ULPS * f32::EPSILON * a.abs().max(1.0)
}

/// Reorders every window of close hits (`crossings[k]` is `hits[k]`) as the module documentation says;
/// returns how many crossings met a coincident surface facing the same way (an overlap).
pub(crate) fn reorder(crossings: &mut [Crossing], hits: &[Hit]) -> u64 {
    let mut overlaps = 0;
    let mut start = 0;
    while start < hits.len() {
        let mut end = start + 1;
        while end < hits.len() && close(hits[end - 1].t, hits[end].t) {
            end += 1;
        }
        if end - start > 1 {
            overlaps += order_window_between(crossings, start, end);
        }
        start = end;
    }
    overlaps
}

/// Orders the window `start..end` given its neighbours. The space the line is in before the window is
/// in front of the previous crossing's patch if it left that front side. At the start of the line it is
/// unknown (outside an object is in front of it, outside an enclosure behind its walls): it is then
/// chosen so that the line ends the window in the space the next crossing closes (in front if that one
/// arrives at a front side), and in front when there is no next crossing either.
fn order_window_between(crossings: &mut [Crossing], start: usize, end: usize) -> u64 {
    if start > 0 {
        let in_front = crossings[start - 1].cos >= 0.0;
        return order_window(&mut crossings[start..end], in_front).0;
    }
    let mut trial = crossings[start..end].to_vec();
    let (overlaps, ends_in_front) = order_window(&mut trial, true);
    let wanted = crossings.get(end).map(|next| next.cos < 0.0);
    if wanted.is_some_and(|w| w != ends_in_front) {
        return order_window(&mut crossings[start..end], false).0;
    }
    crossings[start..end].copy_from_slice(&trial);
    overlaps
}

/// Orders one window: by plane distance, and coincident crossings so that the line alternates between
/// front and back space, starting `in_front` or not. Returns the overlaps met and whether the line ends
/// in front.
fn order_window(window: &mut [Crossing], mut in_front: bool) -> (u64, bool) {
    let mut rest: Vec<Crossing> = window.to_vec();
    rest.sort_by(|a, b| a.t.total_cmp(&b.t));
    let mut overlaps = 0;
    for slot in 0..window.len() {
        let t0 = rest[0].t;
        let same_place = rest
            .iter()
            .take_while(|c| c.t - t0 <= COINCIDENT * t0.abs().max(1.0))
            .count();
        let pick = choose(&rest[..same_place], in_front);
        let c = rest.remove(pick);
        if slot > 0 {
            let last = window[slot - 1];
            let coincident = (c.t - last.t).abs() <= COINCIDENT * c.t.abs().max(1.0);
            if coincident && c.patch != last.patch && c.cos * last.cos > 0.0 {
                overlaps += 1;
            }
        }
        if c.cos != 0.0 {
            in_front = c.cos > 0.0;
        }
        window[slot] = c;
    }
    (overlaps, in_front)
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

    fn c(patch: u32, cos: f64, t: f64) -> Crossing {
        Crossing {
            patch,
            triangle: patch,
            cos,
            t,
        }
    }

    fn hit(t: f32) -> Hit {
        Hit { t, triangle: 0 }
    }

    /// Swapped by f32, put back by the plane distances.
    #[test]
    fn close_hits_follow_the_plane_distances() {
        let hits = [hit(1.0), hit(2.0), hit(2.0 + 1e-7)];
        let mut x = [c(0, 0.5, 1.0), c(2, -0.5, 2.000001), c(1, 0.5, 2.0000005)];
        assert!(has_close_hits(&hits));
        assert_eq!(reorder(&mut x, &hits), 0);
        assert_eq!(x.map(|c| c.patch), [0, 1, 2]);
    }

    /// A two-sided panel from front space: arrive at A, leave from B. A base on the floor from inside the
    /// solid: leave the base, arrive at the floor.
    #[test]
    fn coincident_crossings_alternate_between_front_and_back_space() {
        let hits = [hit(1.0), hit(2.0), hit(2.0)];
        let mut panel = [c(0, 0.5, 1.0), c(7, 0.5, 2.0), c(6, -0.5, 2.0)];
        reorder(&mut panel, &hits);
        assert_eq!(panel.map(|c| c.patch), [0, 6, 7]);
        let mut base = [c(0, -0.5, 1.0), c(3, -0.5, 2.0), c(9, 0.5, 2.0)];
        reorder(&mut base, &hits);
        assert_eq!(base.map(|c| c.patch), [0, 9, 3]);
        // From outside an enclosure up into a solid standing on its floor: the floor's back, the base
        // (d = 0), then the solid's top from behind.
        let hits = [hit(1.0), hit(1.0), hit(2.0)];
        let mut up = [c(9, -0.5, 1.0), c(3, 0.5, 1.0), c(8, 0.5, 2.0)];
        reorder(&mut up, &hits);
        assert_eq!(up.map(|c| c.patch), [3, 9, 8]);
    }

    /// Overlapping surfaces facing the same way: the first in the scene is next to the front space,
    /// whichever way the line goes, and the crossing is counted.
    #[test]
    fn overlaps_are_won_by_the_first_surface_and_counted() {
        let hits = [hit(1.0), hit(1.0), hit(3.0)];
        let mut down = [c(6, -0.5, 1.0), c(4, -0.5, 1.0), c(5, 0.5, 3.0)];
        assert_eq!(reorder(&mut down, &hits), 1);
        assert_eq!(down.map(|c| c.patch), [4, 6, 5]);
        let mut up = [c(4, 0.5, 1.0), c(6, 0.5, 1.0), c(5, -0.5, 3.0)];
        assert_eq!(reorder(&mut up, &hits), 1);
        assert_eq!(up.map(|c| c.patch), [6, 4, 5]);
    }
}
