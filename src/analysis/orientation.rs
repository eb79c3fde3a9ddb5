//! Which way the surfaces face: the diagnosis of a scene whose lines meet back sides where a closed,
//! consistently oriented scene shows only front sides, or where no segment joins two patches at all.
//!
//! The evidence is gathered per object while pairing ([`ObjectSides`]): segments from a front side to a
//! back side (lost pairs), and back sides met from open space at a line's ends. An object whose back
//! sides are seen from outside it while its front sides are seen only from inside it (pairs among its
//! own patches) looks inside out; one whose back sides are seen from outside while its front sides are
//! seen from outside too is a one-sided surface seen from behind (a leaf, a sign, a single-polygon wall).
//! A room seen from outside is neither: its back sides meet only open space, never a front side.

use super::warnings::{RunWarning, RunWarningKind};
use crate::sample::tally::{ObjectSides, Tally};
use crate::scene::Scene;

/// An object is diagnosed when at least this share of the segments reaching it arrive at a back side
/// from a front side: far above the few a consistently oriented scene can show (lines grazing an edge,
/// interpenetrating parts), far below a surface seen from behind half the time.
const BACK_SHARE: f64 = 0.01;
/// ... and at least this many of them, so that a handful of grazing lines never makes a warning.
const MIN_BACK_SEGMENTS: u64 = 10;
/// How many objects a warning names.
const NAMED: usize = 5;

/// The orientation warnings of a run: no pairs at all (`enclosed`: the environment patch gave the
/// escapes partners), or objects that look inside out or one-sided.
pub(crate) fn warnings(scene: &Scene, total: &Tally, enclosed: bool) -> Vec<RunWarning> {
    let c = &total.counters;
    let sides = &total.orientation;
    if c.lines == 0 || c.hits == 0 || sides.len() != scene.objects.len() {
        return Vec::new();
    }
    if c.pairs == 0 && !enclosed {
        return vec![no_pairs(scene, total)];
    }
    // The usual case, a consistently oriented scene, costs no pass over the pair counts.
    if sides.iter().all(|s| s.back_seen < MIN_BACK_SEGMENTS) {
        return Vec::new();
    }
    let front = front_seen(scene, total);
    let (mut inside_out, mut one_sided, mut lights, mut solids) = (vec![], vec![], vec![], vec![]);
    for (k, s) in sides.iter().enumerate() {
        let reached = s.back_seen + front.all[k];
        if s.back_seen < MIN_BACK_SEGMENTS || (s.back_seen as f64) < BACK_SHARE * reached as f64 {
            continue;
        }
        if front.from_outside[k] as f64 * 100.0 < s.back_seen as f64 {
            inside_out.push(k);
        } else if emits(scene, k) {
            lights.push(k);
        } else if is_closed(scene, k) {
            solids.push(k);
        } else {
            one_sided.push(k);
        }
    }
    let mut out = Vec::new();
    if !inside_out.is_empty() {
        out.push(
            RunWarning::new(
                RunWarningKind::InsideOut,
                format!(
                    "{}: normals face inwards: {} look(s) inside out: segments from front sides outside \
                     them arrive at their back sides and are absorbed there, while their front sides are \
                     seen only from inside them; try --flip-normals{}",
                    scene.name,
                    named(scene, sides, &inside_out),
                    names_argument(scene, &inside_out)
                ),
            )
            .about(names(scene, &inside_out)),
        );
    }
    if !one_sided.is_empty() {
        out.push(
            RunWarning::new(
                RunWarningKind::OneSided,
                format!(
                    "{}: one-sided surface(s) seen from behind: {}: segments from front sides arrive at \
                     their back sides and are absorbed there (they count in their rows, as escapes do: the \
                     form factors between the other surfaces stay right). If they are thin surfaces meant \
                     to be seen from both sides (a leaf, a sign, a single-polygon wall), try --two-sided{}; \
                     if they are open solids standing on or cutting through another surface (a box without \
                     a bottom on a floor that runs under it), the hidden part of that surface is what sees \
                     their inside, and --two-sided would only add surfaces inside the solid",
                    scene.name,
                    named(scene, sides, &one_sided),
                    names_argument(scene, &one_sided)
                ),
            )
            .about(names(scene, &one_sided)),
        );
    }
    if !lights.is_empty() {
        out.push(
            RunWarning::new(
                RunWarningKind::LightSeenFromBehind,
                format!(
                    "{}: light(s) seen from behind: {}: segments from front sides arrive at their dark \
                     back sides and are absorbed there, as at a lamp's housing (the form factors between \
                     the other surfaces stay right); a light emits from its front side only, so do not make \
                     it two-sided",
                    scene.name,
                    named(scene, sides, &lights)
                ),
            )
            .about(names(scene, &lights)),
        );
    }
    if !solids.is_empty() {
        out.push(
            RunWarning::new(
                RunWarningKind::SeenInsideSolid,
                format!(
                    "{}: closed solid(s) seen from inside: {}: front sides inside them (objects inside or \
                     cutting through them) see their back sides, and those segments are absorbed there; \
                     --two-sided would add surfaces inside the solid: move or cut what lies inside it",
                    scene.name,
                    named(scene, sides, &solids)
                ),
            )
            .about(names(scene, &solids)),
        );
    }
    out
}

/// Whether any patch of object `k` emits (a light: seen from behind, its back is a housing, not a
/// surface to make two-sided).
fn emits(scene: &Scene, k: usize) -> bool {
    scene
        .patches
        .iter()
        .any(|p| p.object as usize == k && scene.materials[p.material as usize].emission > 0.0)
}

/// Whether object `k` is a closed surface: every edge of its triangles, its corners matched by
/// position (so that meshes whose faces do not share vertex indices count too), is shared by exactly
/// two of them.
fn is_closed(scene: &Scene, k: usize) -> bool {
    let mut edges: std::collections::HashMap<([u32; 3], [u32; 3]), u32> = Default::default();
    let key = |v: u32| scene.positions[v as usize].map(f32::to_bits);
    for p in scene.patches.iter().filter(|p| p.object as usize == k) {
        let first = p.first_triangle as usize;
        for t in &scene.triangles[first..first + p.triangle_count as usize] {
            for e in 0..3 {
                let (a, b) = (key(t[e]), key(t[(e + 1) % 3]));
                *edges
                    .entry(if a < b { (a, b) } else { (b, a) })
                    .or_default() += 1;
            }
        }
    }
    !edges.is_empty() && edges.values().all(|&n| n == 2)
}

/// Pair ends on each object's front sides, in all and from other objects or open space.
struct FrontSeen {
    all: Vec<u64>,
    from_outside: Vec<u64>,
}

/// Front sides seen, per object: escapes from the counters, pairs from the pair counts when counted
/// (without them every pair end counts as seen from outside, which never calls an object inside out).
fn front_seen(scene: &Scene, total: &Tally) -> FrontSeen {
    let n = scene.objects.len();
    let mut all: Vec<u64> = total.orientation.iter().map(|s| s.front_open).collect();
    let mut from_outside = all.clone();
    let object_of = |p: u32| scene.patches[p as usize].object as usize;
    match &total.counts {
        Some(counts) => counts.for_each(|i, j, k| {
            let (a, b) = (object_of(i), object_of(j));
            all[a] += k;
            all[b] += k;
            if a != b {
                from_outside[a] += k;
                from_outside[b] += k;
            }
        }),
        None => {
            // Spread the pairs evenly: only the shares matter, and the inside-out test is skipped.
            let share = 2 * total.counters.pairs / n.max(1) as u64;
            all.iter_mut().for_each(|a| *a += share);
            from_outside.iter_mut().for_each(|f| *f = u64::MAX / 2);
        }
    }
    FrontSeen { all, from_outside }
}

/// The warning of a run in which no segment joined two patches, with what the lines met instead.
fn no_pairs(scene: &Scene, total: &Tally) -> RunWarning {
    let c = &total.counters;
    let sides = &total.orientation;
    let backs: Vec<usize> = (0..sides.len())
        .filter(|&k| sides[k].back_seen + sides[k].back_from_open + sides[k].back_to_open > 0)
        .collect();
    let fronts: Vec<usize> = (0..sides.len())
        .filter(|&k| sides[k].front_open > 0)
        .collect();
    let diagnosis = if is_flat(scene) {
        "every patch lies in one plane, and a flat surface sees nothing of itself from either side \
         (--two-sided and --flip-normals cannot change that); there is no complexity to measure"
            .to_string()
    } else if backs.is_empty() {
        format!(
            "every line that meets the scene meets front sides from open space only, so the objects are \
             closed solids (or surfaces) seen from outside and no surface sees another. If {} is a room \
             or a box meant to be seen from inside, its normals face outwards: try --flip-normals{}; \
             for objects in open space, --enclose measures them against their surroundings",
            named(scene, sides, &fronts),
            names_argument(scene, &fronts)
        )
    } else {
        format!(
            "lines meet back sides of {}: one-sided surfaces seen from behind, or normals facing the \
             wrong way: try --two-sided{} or --flip-normals{}",
            named(scene, sides, &backs),
            names_argument(scene, &backs),
            names_argument(scene, &backs)
        )
    };
    let about = if backs.is_empty() { &fronts } else { &backs };
    RunWarning::new(
        RunWarningKind::NoPairs,
        format!(
            "{}: no line segment joined two patches ({} escapes, {} unpaired), so the visibility \
             measures are undefined: {diagnosis}",
            scene.name, c.escapes, c.unpaired
        ),
    )
    .about(names(scene, about))
    .with_numbers(&[
        ("escapes", c.escapes as f64),
        ("unpaired", c.unpaired as f64),
    ])
}

/// Whether every patch lies in one plane (tracing space: the unit bounding sphere, so the tolerance is
/// relative to the scene's size).
fn is_flat(scene: &Scene) -> bool {
    const TOLERANCE: f64 = 1e-9;
    let Some(first) = scene.patches.first() else {
        return false;
    };
    let (n, d) = (first.normal, first.offset);
    scene.patches.iter().all(|p| {
        let cos = p.normal.dot(n);
        (cos.abs() - 1.0).abs() < TOLERANCE && (p.offset * cos.signum() - d).abs() < TOLERANCE
    })
}

/// The objects for a message, the most affected first: `name` (back sides met N times), ...
fn named(scene: &Scene, sides: &[ObjectSides], objects: &[usize]) -> String {
    let mut sorted = objects.to_vec();
    sorted.sort_by_key(|&k| std::cmp::Reverse(backs_met(&sides[k])));
    let mut parts: Vec<String> = sorted
        .iter()
        .take(NAMED)
        .map(|&k| {
            let s = &sides[k];
            let open = s.back_from_open + s.back_to_open;
            let detail = match (s.back_seen, open) {
                (0, 0) => String::new(),
                (seen, 0) => format!(" ({seen} segments at its back sides)"),
                (0, open) => format!(" ({open} line ends at its back sides)"),
                (seen, open) => format!(
                    " ({seen} segments at its back sides from a front, {open} line ends at them)"
                ),
            };
            format!("`{}`{detail}", scene.objects[k])
        })
        .collect();
    if sorted.len() > NAMED {
        parts.push(format!("and {} more", sorted.len() - NAMED));
    }
    parts.join(", ")
}

/// The names of some objects, in the scene's order.
fn names(scene: &Scene, objects: &[usize]) -> Vec<String> {
    objects.iter().map(|&k| scene.objects[k].clone()).collect()
}

fn backs_met(s: &ObjectSides) -> u64 {
    s.back_seen + s.back_from_open + s.back_to_open
}

/// The objects as the argument of `--flip-normals` or `--two-sided`: nothing when they are all the
/// scene's objects (the flags' default), else a space and their names separated by commas.
fn names_argument(scene: &Scene, objects: &[usize]) -> String {
    if objects.len() == scene.objects.len() {
        return String::new();
    }
    let names: Vec<&str> = objects.iter().map(|&k| scene.objects[k].as_str()).collect();
    format!(" {}", names.join(","))
}
