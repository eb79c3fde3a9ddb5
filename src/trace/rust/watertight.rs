//! The watertight ray/triangle test of Woop, Benthin and Wald, "Watertight ray/triangle intersection",
//! JCGT 2(1), 2013: no ray passes between two triangles that share an edge, whatever f32 rounding does.
//! Both faces are hit; hits on an edge or vertex are reported for every triangle that owns it.

/// A coordinate axis, as an index that needs no bounds check (its values are 0, 1, 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(usize)]
enum Axis {
    X = 0,
    Y = 1,
    Z = 2,
}

impl Axis {
    const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    fn next(self) -> Axis {
        Axis::ALL[(self as usize + 1) % 3]
    }
}

/// A ray prepared for the test: the shear that maps its direction onto +z.
#[derive(Clone, Copy, Debug)]
pub struct ShearedRay {
    kx: Axis,
    ky: Axis,
    kz: Axis,
    /// The origin's coordinates along `kx`, `ky`, `kz`.
    ox: f32,
    oy: f32,
    oz: f32,
    sx: f32,
    sy: f32,
    sz: f32,
}

impl ShearedRay {
    /// Prepares a ray with origin `origin` and direction `dir` (need not be unit).
    pub fn new(origin: [f32; 3], dir: [f32; 3]) -> Self {
        let abs = dir.map(f32::abs);
        let kz = if abs[0] > abs[1] {
            if abs[0] > abs[2] {
                Axis::X
            } else {
                Axis::Z
            }
        } else if abs[1] > abs[2] {
            Axis::Y
        } else {
            Axis::Z
        };
        let mut kx = kz.next();
        let mut ky = kx.next();
        // Keep the winding: swap when the dominant component is negative.
        if dir[kz as usize] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let (x, y, z) = (kx as usize, ky as usize, kz as usize);
        ShearedRay {
            kx,
            ky,
            kz,
            ox: origin[x],
            oy: origin[y],
            oz: origin[z],
            sx: dir[x] / dir[z],
            sy: dir[y] / dir[z],
            sz: 1.0 / dir[z],
        }
    }

    /// The ray parameter `t` of the intersection with triangle `(a, b, c)`, if within `[t_min, t_max]`.
    #[inline]
    pub fn intersect(
        &self,
        a: [f32; 3],
        b: [f32; 3],
        c: [f32; 3],
        t_min: f32,
        t_max: f32,
    ) -> Option<f32> {
        // Relative to the origin, then sheared; only the components the shear reads are computed (each in
        // the same operations as computing the whole difference first).
        let (kx, ky, kz) = (self.kx as usize, self.ky as usize, self.kz as usize);
        let shear = |p: [f32; 3]| {
            let z = p[kz] - self.oz;
            (
                (p[kx] - self.ox) - self.sx * z,
                (p[ky] - self.oy) - self.sy * z,
                z,
            )
        };
        let (ax, ay, az) = shear(a);
        let (bx, by, bz) = shear(b);
        let (cx, cy, cz) = shear(c);

        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        // On an edge in f32: decide it exactly (enough) in f64 so both neighbours agree.
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let d = |x: f32| x as f64;
            u = (d(cx) * d(by) - d(cy) * d(bx)) as f32;
            v = (d(ax) * d(cy) - d(ay) * d(cx)) as f32;
            w = (d(bx) * d(ay) - d(by) * d(ax)) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let (az, bz, cz) = (self.sz * az, self.sz * bz, self.sz * cz);
        let t = (u * az + v * bz + w * cz) / det;
        (t >= t_min && t <= t_max).then_some(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: [f32; 3] = [0.0, 0.0, 0.0];
    const B: [f32; 3] = [1.0, 0.0, 0.0];
    const C: [f32; 3] = [0.0, 1.0, 0.0];

    #[test]
    fn hits_both_faces_at_the_right_distance() {
        let down = ShearedRay::new([0.25, 0.25, 2.0], [0.0, 0.0, -1.0]);
        assert_eq!(down.intersect(A, B, C, 0.0, 10.0), Some(2.0));
        let up = ShearedRay::new([0.25, 0.25, -3.0], [0.0, 0.0, 1.0]);
        assert_eq!(up.intersect(A, B, C, 0.0, 10.0), Some(3.0));
        assert_eq!(up.intersect(A, B, C, 0.0, 2.5), None);
    }

    #[test]
    fn misses_outside_and_hits_edges_inclusively() {
        let outside = ShearedRay::new([0.75, 0.75, 1.0], [0.0, 0.0, -1.0]);
        assert_eq!(outside.intersect(A, B, C, 0.0, 10.0), None);
        let on_edge = ShearedRay::new([0.5, 0.5, 1.0], [0.0, 0.0, -1.0]);
        assert_eq!(on_edge.intersect(A, B, C, 0.0, 10.0), Some(1.0));
        // The neighbour across the hypotenuse also owns the edge.
        assert_eq!(
            on_edge.intersect(B, [1.0, 1.0, 0.0], C, 0.0, 10.0),
            Some(1.0)
        );
    }

    #[test]
    fn a_ray_in_the_plane_misses() {
        let grazing = ShearedRay::new([-1.0, 0.25, 0.0], [1.0, 0.0, 0.0]);
        assert_eq!(grazing.intersect(A, B, C, 0.0, 10.0), None);
    }
}
