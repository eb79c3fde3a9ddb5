//! Shapes as points: axis-aligned rectangles cut into grids of quads, and boxes made of six of them.

use super::{DVec3, Point};

/// Which way a closed shape's faces look.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Facing {
    /// Outwards (a solid, seen from outside).
    Out,
    /// Inwards (an enclosure, seen from inside).
    In,
}

/// An axis-aligned rectangle: `x[axis] = level`, spanning `lo..hi` on the next two axes in cyclic order
/// (`(axis + 1) % 3`, `(axis + 2) % 3`), its front towards `+axis` when `positive`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// The axis the rectangle is perpendicular to (0, 1, 2 for x, y, z).
    pub axis: usize,
    /// Its coordinate on that axis.
    pub level: f64,
    /// The lower corner on the two other axes, in cyclic order.
    pub lo: [f64; 2],
    /// The upper corner on the two other axes.
    pub hi: [f64; 2],
    /// Whether its front side faces `+axis`.
    pub positive: bool,
}

/// One cell of a rectangle's grid: its indices along the two axes and its corners, counter-clockwise
/// seen from the front.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridCell {
    /// Index along the first axis after `axis`.
    pub i: usize,
    /// Index along the second.
    pub j: usize,
    /// The four corners.
    pub corners: [Point; 4],
}

impl Rect {
    /// The rectangle cut into `cells.0 x cells.1` equal cells, row by row (`i` outer, `j` inner).
    pub fn grid(&self, cells: (usize, usize)) -> Vec<GridCell> {
        let (u, v) = ((self.axis + 1) % 3, (self.axis + 2) % 3);
        let point = |i: usize, j: usize| {
            let mut p = DVec3::ZERO;
            p[self.axis] = self.level;
            p[u] = self.lo[0] + (self.hi[0] - self.lo[0]) * i as f64 / cells.0 as f64;
            p[v] = self.lo[1] + (self.hi[1] - self.lo[1]) * j as f64 / cells.1 as f64;
            p
        };
        let mut out = Vec::with_capacity(cells.0 * cells.1);
        for i in 0..cells.0 {
            for j in 0..cells.1 {
                // (u, v, axis) is right-handed, so this order is counter-clockwise seen from +axis.
                let mut corners = [
                    point(i, j),
                    point(i + 1, j),
                    point(i + 1, j + 1),
                    point(i, j + 1),
                ];
                if !self.positive {
                    corners.reverse();
                }
                out.push(GridCell { i, j, corners });
            }
        }
        out
    }
}

/// The six faces of the axis-aligned box `lo..hi`: for each axis in turn, the face at `lo` then at `hi`.
pub fn box_faces(lo: Point, hi: Point, facing: Facing) -> [Rect; 6] {
    std::array::from_fn(|k| {
        let (axis, at_hi) = (k / 2, k % 2 == 1);
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        Rect {
            axis,
            level: if at_hi { hi[axis] } else { lo[axis] },
            lo: [lo[u], lo[v]],
            hi: [hi[u], hi[v]],
            // A face at hi looks towards +axis from outside.
            positive: at_hi == (facing == Facing::Out),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every face's corners wind counter-clockwise seen from its front: outwards for a solid, inwards
    /// for an enclosure, and the grid cells tile the face.
    #[test]
    fn box_faces_face_the_right_way_and_grids_tile_them() {
        let (lo, hi) = (DVec3::new(0.0, 1.0, 2.0), DVec3::new(1.0, 3.0, 5.0));
        let centre = 0.5 * (lo + hi);
        for facing in [Facing::Out, Facing::In] {
            for face in box_faces(lo, hi, facing) {
                let cells = face.grid((2, 3));
                assert_eq!(cells.len(), 6);
                let mut area = 0.0;
                for c in &cells {
                    let [a, b, _, d] = c.corners;
                    let normal = (b - a).cross(d - a);
                    area += normal.length();
                    let outward = normal.dot(a - centre) > 0.0;
                    assert_eq!(outward, facing == Facing::Out, "{face:?}");
                }
                let (u, v) = ((face.axis + 1) % 3, (face.axis + 2) % 3);
                assert!((area - (hi[u] - lo[u]) * (hi[v] - lo[v])).abs() < 1e-12);
            }
        }
    }
}
