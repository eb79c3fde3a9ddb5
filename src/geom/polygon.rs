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

/// Triangles covering a simple polygon, convex or not: a fan when it is convex, else ear clipping about
/// its Newell normal (a fan of a concave polygon would cover area outside it and overlap itself).
pub fn triangulate(points: &[Point]) -> Vec<[usize; 3]> {
    let (normal, area) = newell(points);
    if points.len() <= 3 || area <= 0.0 || is_convex(points, normal) {
        return fan(points.len());
    }
    ear_clip(points, normal)
}

/// Ear clipping: repeatedly cuts off a convex corner whose triangle holds no other corner. A polygon
/// with no ear left (self-intersecting) has its rest fanned.
fn ear_clip(points: &[Point], normal: Normal) -> Vec<[usize; 3]> {
    let mut left: Vec<usize> = (0..points.len()).collect();
    let mut out = Vec::with_capacity(points.len() - 2);
    while left.len() > 3 {
        let n = left.len();
        let ear = (0..n).find(|&k| {
            let (a, b, c) = (left[(k + n - 1) % n], left[k], left[(k + 1) % n]);
            turn(points[a], points[b], points[c], normal) > 0.0
                && !left.iter().any(|&o| {
                    o != a
                        && o != b
                        && o != c
                        && inside(points[o], [points[a], points[b], points[c]], normal)
                })
        });
        let Some(k) = ear else {
            out.extend(fan(n).into_iter().map(|t| t.map(|i| left[i])));
            return out;
        };
        out.push([left[(k + n - 1) % n], left[k], left[(k + 1) % n]]);
        left.remove(k);
    }
    out.push([left[0], left[1], left[2]]);
    out
}

/// Whether `p` lies in the triangle (boundary included), seen along `normal`.
fn inside(p: Point, t: [Point; 3], normal: Normal) -> bool {
    (0..3).all(|k| turn(t[k], t[(k + 1) % 3], p, normal) >= 0.0)
}

/// Planar pieces of a non-planar polygon: a quad becomes two triangles along its shorter diagonal (the
/// better-shaped pair, and the fold that moves the surface least for the slightly bent quads of real
/// files); a larger polygon becomes the triangles of [`triangulate`].
pub fn planar_pieces(points: &[Point]) -> Vec<[usize; 3]> {
    if points.len() == 4 {
        let d02 = (points[2] - points[0]).length();
        let d13 = (points[3] - points[1]).length();
        return if d02 <= d13 {
            vec![[0, 1, 2], [0, 2, 3]]
        } else {
            vec![[1, 2, 3], [1, 3, 0]]
        };
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
        let tris = triangulate(&l);
        assert_eq!(tris.len(), 4);
        assert!((area_of(&l, &tris) - 3.0).abs() < 1e-12);
        for t in &tris {
            let c = centroid(&t.map(|i| l[i]));
            assert!(c.x < 1.0 || c.y < 1.0, "a triangle outside the L: {t:?}");
        }
        // Convex polygons keep the fan from the first corner.
        let square =
            [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].map(|(x, y)| DVec3::new(x, y, 0.0));
        assert_eq!(triangulate(&square), fan(4));
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
        assert_eq!(planar_pieces(&kite), vec![[1, 2, 3], [1, 3, 0]]);
        assert_eq!(planar_pieces(&q).len(), 2);
    }
}
