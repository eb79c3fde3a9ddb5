//! The watertight ray/triangle test of Woop, Benthin and Wald, "Watertight ray/triangle intersection",
//! JCGT 2(1), 2013: no ray passes between two triangles that share an edge, whatever f32 rounding does.
//! Both faces are hit; hits on an edge or vertex are reported for every triangle that owns it.

use glam::Vec4;

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

/// Four triangles in the lanes of SSE vectors, for [`ShearedRay::intersect4`]: `v[vertex][axis]`.
/// Unused lanes hold NaN, which no test accepts.
#[derive(Clone, Copy, Debug)]
pub struct Triangles4 {
    v: [[Vec4; 3]; 3],
}

impl Triangles4 {
    /// Up to four triangles (lanes beyond `triangles.len()` unused).
    pub fn new(triangles: &[[[f32; 3]; 3]]) -> Self {
        assert!(triangles.len() <= 4, "four triangles at most");
        let mut lanes = [[[f32::NAN; 4]; 3]; 3];
        for (lane, triangle) in triangles.iter().enumerate() {
            for (vertex, p) in triangle.iter().enumerate() {
                for axis in 0..3 {
                    lanes[vertex][axis][lane] = p[axis];
                }
            }
        }
        Triangles4 {
            v: lanes.map(|vertex| vertex.map(Vec4::from_array)),
        }
    }

    /// Lane `lane`'s triangle (NaN corners for an unused lane).
    pub fn triangle(&self, lane: usize) -> [[f32; 3]; 3] {
        self.v
            .map(|vertex| vertex.map(|axis| axis.to_array()[lane]))
    }
}

impl ShearedRay {
    /// [`ShearedRay::intersect`] on four triangles at once: bit `k` of the mask for a hit of lane `k`'s
    /// triangle, at `t[k]`. Each lane computes what the scalar test computes, in the same f32 operations
    /// (so the same bits); a lane with an edge function exactly 0, which the scalar test decides in f64,
    /// is handed to the scalar test.
    #[inline]
    pub fn intersect4(&self, tri: &Triangles4, t_min: f32, t_max: f32) -> (u32, [f32; 4]) {
        let (kx, ky, kz) = (self.kx as usize, self.ky as usize, self.kz as usize);
        let (ox, oy, oz) = (
            Vec4::splat(self.ox),
            Vec4::splat(self.oy),
            Vec4::splat(self.oz),
        );
        let (sx, sy) = (Vec4::splat(self.sx), Vec4::splat(self.sy));
        let shear = |p: &[Vec4; 3]| {
            let z = p[kz] - oz;
            ((p[kx] - ox) - sx * z, (p[ky] - oy) - sy * z, z)
        };
        let (ax, ay, az) = shear(&tri.v[0]);
        let (bx, by, bz) = shear(&tri.v[1]);
        let (cx, cy, cz) = shear(&tri.v[2]);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = Vec4::ZERO;
        let on_edge = (u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero)).bitmask();
        let negative = u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero);
        let positive = u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero);
        let det = u + v + w;
        let sz = Vec4::splat(self.sz);
        let t = (u * (sz * az) + v * (sz * bz) + w * (sz * cz)) / det;
        let inside = !(negative & positive).bitmask() & 0xf;
        let accepted =
            (det.cmpne(zero) & t.cmpge(Vec4::splat(t_min)) & t.cmple(Vec4::splat(t_max))).bitmask();
        let mut hits = inside & accepted & !on_edge;
        let mut ts = t.to_array();
        let mut edges = on_edge;
        while edges != 0 {
            let k = edges.trailing_zeros() as usize;
            edges &= edges - 1;
            let [a, b, c] = tri.triangle(k);
            if let Some(tk) = self.intersect(a, b, c, t_min, t_max) {
                hits |= 1 << k;
                ts[k] = tk;
            }
        }
        (hits, ts)
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

    /// The four-lane test gives the scalar test's answers to the bit: on triangles with corners on a
    /// coarse lattice (so that many lines pass exactly through edges and vertices, the f64 path), with
    /// one to four lanes used, lines from lattice points and random ones.
    #[test]
    fn four_lanes_are_the_scalar_test_bit_for_bit() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut lattice = || (next() % 9) as f32 * 0.25 - 1.0;
        let (mut hits, mut edges) = (0, 0);
        for k in 0..20_000 {
            let used = 1 + k % 4;
            let triangles: Vec<[[f32; 3]; 3]> = (0..used)
                .map(|_| {
                    [(); 3].map(|_| {
                        [
                            lattice(),
                            lattice(),
                            if k % 3 == 0 { 0.0 } else { lattice() },
                        ]
                    })
                })
                .collect();
            let packet = Triangles4::new(&triangles);
            let origin = [lattice(), lattice(), 2.0];
            let target = [
                lattice(),
                lattice(),
                if k % 2 == 0 { 0.0 } else { lattice() },
            ];
            let dir = [0, 1, 2].map(|a| target[a] - origin[a]);
            let ray = ShearedRay::new(origin, dir);
            let (mask, t) = ray.intersect4(&packet, 0.0, 10.0);
            for (lane, [a, b, c]) in triangles.iter().enumerate() {
                let scalar = ray.intersect(*a, *b, *c, 0.0, 10.0);
                let four = (mask >> lane & 1 == 1).then_some(t[lane]);
                assert_eq!(
                    four.map(f32::to_bits),
                    scalar.map(f32::to_bits),
                    "{k} {lane}"
                );
                hits += usize::from(scalar.is_some());
            }
            edges += usize::from(mask != 0 && k % 2 == 0);
            assert_eq!(mask >> used, 0, "unused lanes never hit");
        }
        assert!(
            hits > 3_000 && edges > 1_000,
            "{hits} hits, {edges} lattice lines hitting"
        );
    }

    #[test]
    fn a_ray_in_the_plane_misses() {
        let grazing = ShearedRay::new([-1.0, 0.25, 0.0], [1.0, 0.0, 0.0]);
        assert_eq!(grazing.intersect(A, B, C, 0.0, 10.0), None);
    }
}
