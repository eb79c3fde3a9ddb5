//! A meshed, turned room as OBJ text, shared by the integration tests (`tests/it/rust_bvh.rs`) and the
//! BVH benchmark (`benches/bvh_layouts.rs`), each of which includes this file by its path.

/// An OBJ of the cube [-1, 1]^3, each face meshed into `n` x `n` quads facing inward, turned by
/// `turn` radians about the x axis and then the z axis; with `inner_box`, an unmeshed box inside; with
/// `grading` above 1, patches growing by that factor across each wall (long thin patches, patches
/// spanning several cells, cells holding several patches).
pub fn turned_meshed_room(n: usize, turn: f64, inner_box: bool, grading: f64) -> String {
    let (s, c) = turn.sin_cos();
    let rotate = |p: [f64; 3]| {
        let q = [p[0], c * p[1] - s * p[2], s * p[1] + c * p[2]];
        [c * q[0] - s * q[1], s * q[0] + c * q[1], q[2]]
    };
    let mut obj = String::from("o room\n");
    let mut count = 0;
    let mut quad = |obj: &mut String, corners: [[f64; 3]; 4]| {
        for p in corners.map(rotate) {
            obj.push_str(&format!("v {} {} {}\n", p[0], p[1], p[2]));
        }
        obj.push_str(&format!(
            "f {} {} {} {}\n",
            count + 1,
            count + 2,
            count + 3,
            count + 4
        ));
        count += 4;
    };
    // Patch sides grow by `grading` from one side of a wall to the other (1: a regular mesh).
    let at = |i: usize| {
        let share = if grading == 1.0 {
            i as f64 / n as f64
        } else {
            (grading.powi(i as i32) - 1.0) / (grading.powi(n as i32) - 1.0)
        };
        -1.0 + 2.0 * share
    };
    for axis in 0..3 {
        for side in [-1.0, 1.0] {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for i in 0..n {
                for j in 0..n {
                    let point = |a: f64, b: f64| {
                        let mut p = [0.0; 3];
                        p[axis] = side;
                        p[u] = a;
                        p[v] = b;
                        p
                    };
                    let (a0, a1, b0, b1) = (at(i), at(i + 1), at(j), at(j + 1));
                    let mut q = [point(a0, b0), point(a1, b0), point(a1, b1), point(a0, b1)];
                    if side > 0.0 {
                        q.reverse();
                    }
                    quad(&mut obj, q);
                }
            }
        }
    }
    if inner_box {
        obj.push_str("o box\n");
        let (lo, hi) = (-0.3, 0.25);
        for axis in 0..3 {
            for (side, value) in [(-1.0, lo), (1.0, hi)] {
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let point = |a: f64, b: f64| {
                    let mut p = [0.0; 3];
                    p[axis] = value;
                    p[u] = a;
                    p[v] = b;
                    p
                };
                let mut q = [point(lo, lo), point(hi, lo), point(hi, hi), point(lo, hi)];
                if side < 0.0 {
                    q.reverse();
                }
                quad(&mut obj, q);
            }
        }
    }
    obj
}
