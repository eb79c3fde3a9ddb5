//! Polygons as files give them: how far from planar, whether convex, and how to cut them into triangles.
//!
//! Points are a polygon's corners in order; results are triangles of corner positions (indices into the
//! polygon's own corner list), counter-clockwise about the polygon's Newell normal like the polygon.

use super::{centroid, newell, Normal, Point};

/// How far a polygon's corners leave its best-fit (Newell) plane, as a fraction of its size (the largest
/// distance of a corner from the centroid). 0 for triangles and degenerate polygons.
pub fn planarity_deviation(points: &[Point]) -> f64 {
    let (normal, area) = newell(points);
    if points.len() <= 3 || area <= 0.0 {
        return 0.0;
    }
    let c = centroid(points);
    let size = points.iter().map(|&p| (p - c).length()).fold(0.0, f64::max);
    let off = points
        .iter()
        .map(|&p| normal.dot(p - c).abs())
        .fold(0.0, f64::max);
    if size > 0.0 {
        off / size
    } else {
        0.0
    }
}

/// Whether every corner of the polygon turns the same way about `normal` (no reflex corner). Collinear
/// corners count as convex.
pub fn is_convex(points: &[Point], normal: Normal) -> bool {
    let n = points.len();
    (0..n).all(|k| {
        turn(
            points[(k + n - 1) % n],
            points[k],
            points[(k + 1) % n],
            normal,
        ) >= 0.0
    })
}

/// The turn at `b` from `a` to `c` about `normal`: > 0 counter-clockwise (convex corner).
fn turn(a: Point, b: Point, c: Point, normal: Normal) -> f64 {
    (b - a).cross(c - b).dot(normal)
}

/// The fan of triangles from the first corner: right for convex polygons, and the order scx has always
/// used for them.
pub fn fan(count: usize) -> Vec<[usize; 3]> {
    (1..count.saturating_sub(1))
        .map(|k| [0, k, k + 1])
        .collect()
}

/// Polygons with more corners than this are large: a convex one is cut by [`halving`] instead of a fan,
/// and one convex but for corners within rounding of a straight line counts as convex.
pub const LARGE_POLYGON: usize = 4096;

/// How far a corner of a large polygon may turn the wrong way and still count as straight: its distance
/// from the line through its neighbours, as a fraction of the polygon's size (the fraction scx takes
/// for planarity by default: far above the rounding of coordinates written with 6 digits).
const NEARLY_STRAIGHT: f64 = 1e-4;

/// The most containment tests ear clipping may make for one polygon: far more than any polygon up to
/// [`LARGE_POLYGON`] corners needs (about n^2 / 2), and a bound on the time a polygon can take.
const EAR_CLIP_BUDGET: u64 = 1 << 28;

/// A polygon that ear clipping could not cut within its budget of steps (2^28).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TooIntricate {
    /// Its corners.
    pub corners: usize,
}

impl std::fmt::Display for TooIntricate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "a concave polygon of {} corners: too intricate to cut into triangles within scx's bound \
             of {EAR_CLIP_BUDGET} steps; cut it into smaller faces (or triangulate it) first",
            self.corners
        )
    }
}

/// Triangles covering a simple polygon, convex or not: a fan when it is convex, else ear clipping about
/// its Newell normal (a fan of a concave polygon would cover area outside it and overlap itself). A
/// large convex polygon (or one convex within rounding) is cut by [`halving`]. Ear clipping that takes
/// more than its bound of steps is an error.
pub fn triangulate(points: &[Point]) -> Result<Vec<[usize; 3]>, TooIntricate> {
    let n = points.len();
    let (normal, area) = newell(points);
    if n <= 3 || area <= 0.0 {
        return Ok(fan(n));
    }
    let large = n > LARGE_POLYGON;
    if is_convex(points, normal) {
        return Ok(if large { halving(n) } else { fan(n) });
    }
    if large && is_nearly_convex(points, normal) {
        return Ok(halving(n));
    }
    ear_clip(points, normal)
}

/// Whether every corner turns the convex way or lies within [`NEARLY_STRAIGHT`] of the line through its
/// neighbours: a convex polygon whose coordinates were rounded.
fn is_nearly_convex(points: &[Point], normal: Normal) -> bool {
    let n = points.len();
    let c = centroid(points);
    let size = points.iter().map(|&p| (p - c).length()).fold(0.0, f64::max);
    let allowed = NEARLY_STRAIGHT * size;
    (0..n).all(|k| {
        let (a, b, c) = (points[(k + n - 1) % n], points[k], points[(k + 1) % n]);
        let t = turn(a, b, c, normal);
        // |(b - a) x (c - b)| is the distance of b from the line a-c times |c - a|.
        t >= 0.0 || -t <= allowed * (c - a).length()
    })
}

/// Triangles of a convex polygon of `count` corners in rounds: each round cuts off every other corner
/// (triangles of three neighbours), and the next works on the corners left, until three are left. The
/// triangles of a round are about as large as its corners' spacing, where a fan's are all slivers meeting
/// at one corner, which bounding volume hierarchies handle badly.
pub fn halving(count: usize) -> Vec<[usize; 3]> {
    let mut ring: Vec<usize> = (0..count).collect();
    let mut out = Vec::with_capacity(count.saturating_sub(2));
    while ring.len() > 3 {
        let mut next = Vec::with_capacity(ring.len() / 2 + 2);
        let mut k = 0;
        while k + 2 < ring.len() {
            out.push([ring[k], ring[k + 1], ring[k + 2]]);
            next.push(ring[k]);
            k += 2;
        }
        next.extend_from_slice(&ring[k..]);
        ring = next;
    }
    if ring.len() == 3 {
        out.push([ring[0], ring[1], ring[2]]);
    }
    out
}

/// Ear clipping: repeatedly cuts off the first convex corner whose triangle holds no other corner. A
/// polygon with no ear left (self-intersecting) has its rest fanned. More than [`EAR_CLIP_BUDGET`]
/// containment tests is an error.
fn ear_clip(points: &[Point], normal: Normal) -> Result<Vec<[usize; 3]>, TooIntricate> {
    let mut left: Vec<usize> = (0..points.len()).collect();
    let mut out = Vec::with_capacity(points.len() - 2);
    let mut work = 0u64;
    while left.len() > 3 {
        let n = left.len();
        let mut ear = None;
        for k in 0..n {
            let (a, b, c) = (left[(k + n - 1) % n], left[k], left[(k + 1) % n]);
            if turn(points[a], points[b], points[c], normal) <= 0.0 {
                continue;
            }
            work += n as u64;
            if work > EAR_CLIP_BUDGET {
                return Err(TooIntricate {
                    corners: points.len(),
                });
            }
            let blocked = left.iter().any(|&o| {
                o != a
                    && o != b
                    && o != c
                    && inside(points[o], [points[a], points[b], points[c]], normal)
            });
            if !blocked {
                ear = Some(k);
                break;
            }
        }
        let Some(k) = ear else {
            out.extend(fan(n).into_iter().map(|t| t.map(|i| left[i])));
            return Ok(out);
        };
        out.push([left[(k + n - 1) % n], left[k], left[(k + 1) % n]]);
        left.remove(k);
    }
    out.push([left[0], left[1], left[2]]);
    Ok(out)
}

/// Whether `p` lies in the triangle (boundary included), seen along `normal`.
fn inside(p: Point, t: [Point; 3], normal: Normal) -> bool {
    (0..3).all(|k| turn(t[k], t[(k + 1) % 3], p, normal) >= 0.0)
}

/// Planar pieces of a non-planar polygon: a quad becomes two triangles along its shorter diagonal (the
/// better-shaped pair, and the fold that moves the surface least for the slightly bent quads of real
/// files); a larger polygon becomes the triangles of [`triangulate`].
pub fn planar_pieces(points: &[Point]) -> Result<Vec<[usize; 3]>, TooIntricate> {
    if points.len() == 4 {
        let d02 = (points[2] - points[0]).length();
        let d13 = (points[3] - points[1]).length();
        return Ok(if d02 <= d13 {
            vec![[0, 1, 2], [0, 2, 3]]
        } else {
            vec![[1, 2, 3], [1, 3, 0]]
        });
    }
    triangulate(points)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{triangle_area, DVec3};

    fn area_of(points: &[Point], tris: &[[usize; 3]]) -> f64 {
        tris.iter()
            .map(|t| triangle_area(points[t[0]], points[t[1]], points[t[2]]))
            .sum()
    }

    /// An L-shaped hexagon (area 3 of unit squares): its fan from corner 0 would leave the polygon.
    #[test]
    fn concave_polygons_are_cut_into_triangles_inside_them() {
        let l = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ]
        .map(|(x, y)| DVec3::new(x, y, 0.0));
        let (normal, area) = newell(&l);
        assert!(!is_convex(&l, normal));
        assert!((area - 3.0).abs() < 1e-12);
        let tris = triangulate(&l).unwrap();
        assert_eq!(tris.len(), 4);
        assert!((area_of(&l, &tris) - 3.0).abs() < 1e-12);
        for t in &tris {
            let c = centroid(&t.map(|i| l[i]));
            assert!(c.x < 1.0 || c.y < 1.0, "a triangle outside the L: {t:?}");
        }
        // Convex polygons keep the fan from the first corner.
        let square =
            [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(x, y)| DVec3::new(x, y, 0.0));
        assert_eq!(triangulate(&square).unwrap(), fan(4));
    }

    /// A unit square with one corner lifted by h: its deviation is h / (2 * size) to first order
    /// (the best plane passes halfway), and the pieces take the shorter diagonal.
    #[test]
    fn bent_quads_are_measured_and_split_along_the_shorter_diagonal() {
        let h = 1e-3;
        let q = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, h),
            DVec3::new(0.0, 1.0, 0.0),
        ];
        let size = (0.5f64 * 0.5 * 2.0).sqrt();
        let d = planarity_deviation(&q);
        assert!((d - h / 4.0 / size).abs() < 1e-6 * h, "{d}");
        assert_eq!(planarity_deviation(&q[..3]), 0.0);
        // Stretch along x so that the diagonal 1-3 is the shorter.
        let kite = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(3.0, -0.5, 0.0),
            DVec3::new(4.0, 0.0, h),
            DVec3::new(3.0, 0.5, 0.0),
        ];
        assert_eq!(planar_pieces(&kite).unwrap(), vec![[1, 2, 3], [1, 3, 0]]);
        assert_eq!(planar_pieces(&q).unwrap().len(), 2);
    }

    /// A large convex polygon is cut in rounds (every triangle inside it, the area kept); one whose
    /// coordinates were rounded (so a few corners turn the wrong way by a hair) counts as convex.
    #[test]
    fn large_convex_polygons_are_cut_in_rounds() {
        for n in [4, 5, 6, 7, 100, 1001] {
            let tris = halving(n);
            assert_eq!(tris.len(), n - 2, "{n}");
            let mut seen = vec![0; n];
            for t in &tris {
                assert!(
                    t[0] < t[1] && t[1] < t[2],
                    "{t:?}: counter-clockwise like the polygon"
                );
                for &v in t {
                    seen[v] += 1;
                }
            }
            assert!(seen.iter().all(|&s| s > 0), "{n}: every corner used");
        }
        let n = LARGE_POLYGON + 1000;
        let round = |x: f64| (x * 1e6).round() / 1e6;
        let circle: Vec<Point> = (0..n)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                DVec3::new(round(a.cos()), round(a.sin()), 0.0)
            })
            .collect();
        let (normal, area) = newell(&circle);
        assert!(
            !is_convex(&circle, normal),
            "rounding makes some corners reflex"
        );
        let tris = triangulate(&circle).unwrap();
        assert_eq!(tris, halving(n));
        assert!(
            (area_of(&circle, &tris) - area).abs() < 1e-9,
            "{}",
            area_of(&circle, &tris)
        );
    }

    /// A concave polygon too large for ear clipping's bound is an error, not minutes of work.
    #[test]
    fn ear_clipping_is_bounded() {
        // A comb of deep teeth: far from convex.
        let teeth = 60_000;
        let mut comb = Vec::new();
        for k in 0..teeth {
            let x = k as f64;
            comb.push(DVec3::new(x, 0.0, 0.0));
            comb.push(DVec3::new(x + 0.5, 1000.0, 0.0));
        }
        comb.push(DVec3::new(teeth as f64, -1.0, 0.0));
        comb.push(DVec3::new(0.0, -1.0, 0.0));
        let e = triangulate(&comb).unwrap_err();
        assert_eq!(e.corners, comb.len());
        assert!(e.to_string().contains("too intricate"), "{e}");
    }
}
