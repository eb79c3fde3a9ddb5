//! `@fig4:a..f`: the room with tables and chairs of the paper's figure 4 (Table 5).
//!
//! The paper: "an object formed by a table and four chairs is situated in the middle of a room (4a). In
//! figures 4b and 4c, arrays of such objects have been situated in the middle of the same room. In
//! figures 4d, 4e and 4f, the same 16 objects have been distributed in different ways", and "the increase
//! of complexity is produced when there are objects near the walls". It gives no dimensions; ours
//! (metres, y up):
//!
//! * the room: 10 x 10 x 3, one patch per wall;
//! * a group ([`GROUP_HALF_WIDTH`] = 0.75 from its centre to its outer edge): a square table 0.9 x 0.9,
//!   its top 0.04 thick at 0.71..0.75, on four legs 0.06 square; four chairs, one per side, each a seat
//!   0.45 x 0.45, 0.05 thick at 0.42..0.47, on four legs 0.04 square, with a backrest 0.05 thick and 0.45
//!   high along the seat's far edge; the chairs are pushed 0.15 under the table;
//! * layouts of the group centres: `a` one in the middle; `b` 2 x 2 in the middle, 1.8 apart; `c` 4 x 4 in
//!   the middle, 1.8 apart (1.55 from the walls); `d` 4 x 4 spread evenly over the room, 2.5 apart (0.5
//!   from the walls); `e` four 2 x 2 blocks (1.8 apart) in the room's corners, 0.1 from the walls; `f`
//!   sixteen along the walls (five per wall, sharing the corners), 0.1 from them.
//!
//! So `c`..`f` move the same 16 groups from the middle towards the walls. Every part is a box with one
//! patch per face (2246 patches in `c`..`f`). Nothing overlaps, and every segment inside the room joins
//! two visible patches: a leg is four side faces standing on the floor, and the part above it has a
//! hole where the leg meets it (the bottom of a table top or seat is three rectangles around the four
//! leg tops; a seat's top stops at the backrest, which stands on it without a bottom face), so the inside
//! of a piece of furniture is closed and only ever seen from behind. The floor under the legs is hidden
//! but still part of the floor patch: 0.04 m^2 per group, 0.3% of the area with 16 groups, which
//! lowers I_s^c by at most log2(1.003) = 0.004 bits.
//!
//! Material: the grey `wall` of the other built-ins (R = 0.5, no light).

use super::parts::{add_rect, grey_wall};
use crate::geom::shapes::Rect;
use crate::scene::{Scene, SceneBuilder, SceneError};

/// Side of the square room.
pub const ROOM_SIDE: f64 = 10.0;
/// Height of the room.
pub const ROOM_HEIGHT: f64 = 3.0;
/// From a group's centre to the outer edge of its chairs.
pub const GROUP_HALF_WIDTH: f64 = TABLE_SIDE / 2.0 - CHAIR_TUCK + SEAT_SIDE;

const TABLE_SIDE: f64 = 0.9;
const TABLE_BOTTOM: f64 = 0.71;
const TABLE_TOP: f64 = 0.75;
const TABLE_LEG: f64 = 0.06;
const SEAT_SIDE: f64 = 0.45;
const SEAT_BOTTOM: f64 = 0.42;
const SEAT_TOP: f64 = 0.47;
const CHAIR_LEG: f64 = 0.04;
const BACKREST_DEPTH: f64 = 0.05;
const BACKREST_HEIGHT: f64 = 0.45;
const CHAIR_TUCK: f64 = 0.15;
/// Distance between neighbouring groups in the arrays `b`, `c` and the blocks of `e`.
const ARRAY_PITCH: f64 = 1.8;
/// Gap between a group's outer edge and the wall in the layouts `e` and `f`.
const WALL_GAP: f64 = 0.1;

/// The group centres (x, z) of a layout `a`..`f`.
pub fn layout(variant: char) -> Option<Vec<[f64; 2]>> {
    let mid = ROOM_SIDE / 2.0;
    let near = WALL_GAP + GROUP_HALF_WIDTH;
    let grid = |origin: [f64; 2], n: usize, pitch: f64| -> Vec<[f64; 2]> {
        (0..n * n)
            .map(|k| {
                [
                    origin[0] + (k / n) as f64 * pitch,
                    origin[1] + (k % n) as f64 * pitch,
                ]
            })
            .collect()
    };
    let centred = |n: usize, pitch: f64| {
        let o = mid - (n - 1) as f64 * pitch / 2.0;
        grid([o, o], n, pitch)
    };
    Some(match variant {
        'a' => vec![[mid, mid]],
        'b' => centred(2, ARRAY_PITCH),
        'c' => centred(4, ARRAY_PITCH),
        'd' => centred(4, ROOM_SIDE / 4.0),
        'e' => {
            let far = ROOM_SIDE - near - ARRAY_PITCH;
            [[near, near], [near, far], [far, near], [far, far]]
                .iter()
                .flat_map(|&o| grid(o, 2, ARRAY_PITCH))
                .collect()
        }
        'f' => {
            let step = (ROOM_SIDE - 2.0 * near) / 4.0;
            (0..4)
                .flat_map(|k| {
                    let t = near + k as f64 * step;
                    let (lo, hi) = (near, ROOM_SIDE - near);
                    [[t, lo], [hi, t], [ROOM_SIDE - t, hi], [lo, ROOM_SIDE - t]]
                })
                .collect()
        }
        _ => return None,
    })
}

/// `@fig4:a..f` (see the module documentation).
pub fn fig4(spec: &str, param: Option<&str>) -> Result<Scene, SceneError> {
    let centres = param
        .filter(|p| p.len() == 1)
        .and_then(|p| layout(p.chars().next()?))
        .ok_or_else(|| {
            SceneError::Builtin(format!(
                "{spec}: @fig4 needs a layout a..f (a: one table with four chairs, b: 2 x 2, c..f: 16 \
                 placed four ways)"
            ))
        })?;
    let mut b = SceneBuilder::new(spec);
    let m = grey_wall(&mut b);
    let mut f = Furnisher { b: &mut b, m };
    f.room();
    for (k, c) in centres.iter().enumerate() {
        f.group(*c, k);
    }
    b.build()
}

/// A footprint in the floor plane: `x[0]..x[1]` by `z[0]..z[1]`.
#[derive(Clone, Copy, Debug)]
struct Footprint {
    x: [f64; 2],
    z: [f64; 2],
}

impl Footprint {
    fn square(centre: [f64; 2], side: f64) -> Self {
        let h = side / 2.0;
        Footprint {
            x: [centre[0] - h, centre[0] + h],
            z: [centre[1] - h, centre[1] + h],
        }
    }

    /// The four corner squares of side `s`.
    fn corners(&self, s: f64) -> [Footprint; 4] {
        let [x0, x1] = self.x;
        let [z0, z1] = self.z;
        [[x0, z0], [x1 - s, z0], [x0, z1 - s], [x1 - s, z1 - s]].map(|[x, z]| Footprint {
            x: [x, x + s],
            z: [z, z + s],
        })
    }
}

/// Adds the room and the furniture to a scene.
struct Furnisher<'a> {
    b: &'a mut SceneBuilder,
    m: u32,
}

impl Furnisher<'_> {
    fn rect(&mut self, r: Rect, name: &str) {
        add_rect(self.b, &r, (1, 1), self.m, name);
    }

    /// A horizontal rectangle at height `y`, facing up or down.
    fn horizontal(&mut self, f: Footprint, y: f64, up: bool, name: &str) {
        // Axis y: the rectangle spans (z, x).
        let r = Rect {
            axis: 1,
            level: y,
            lo: [f.z[0], f.x[0]],
            hi: [f.z[1], f.x[1]],
            positive: up,
        };
        self.rect(r, name);
    }

    /// The four vertical sides of a box over `f` from `y0` to `y1`, facing `outward` or in.
    fn sides(&mut self, f: Footprint, y: [f64; 2], outward: bool, name: &str) {
        for (level, positive) in [(f.x[0], false), (f.x[1], true)] {
            // Axis x: the rectangle spans (y, z).
            let r = Rect {
                axis: 0,
                level,
                lo: [y[0], f.z[0]],
                hi: [y[1], f.z[1]],
                positive: positive == outward,
            };
            self.rect(r, name);
        }
        for (level, positive) in [(f.z[0], false), (f.z[1], true)] {
            // Axis z: the rectangle spans (x, y).
            let r = Rect {
                axis: 2,
                level,
                lo: [f.x[0], y[0]],
                hi: [f.x[1], y[1]],
                positive: positive == outward,
            };
            self.rect(r, name);
        }
    }

    fn room(&mut self) {
        let all = Footprint {
            x: [0.0, ROOM_SIDE],
            z: [0.0, ROOM_SIDE],
        };
        self.horizontal(all, 0.0, true, "floor");
        self.horizontal(all, ROOM_HEIGHT, false, "ceiling");
        self.sides(all, [0.0, ROOM_HEIGHT], false, "room wall");
    }

    /// A slab over `f` from `y[0]` to `y[1]` on four legs of side `leg` at its corners: the slab's sides,
    /// its bottom around the leg tops, and the legs' sides (its top is left to the caller).
    fn slab_on_legs(&mut self, f: Footprint, y: [f64; 2], leg: f64, name: &str) {
        self.sides(f, y, true, name);
        let [x0, x1] = f.x;
        let [z0, z1] = f.z;
        let pieces = [
            Footprint {
                x: [x0 + leg, x1 - leg],
                z: [z0, z1],
            },
            Footprint {
                x: [x0, x0 + leg],
                z: [z0 + leg, z1 - leg],
            },
            Footprint {
                x: [x1 - leg, x1],
                z: [z0 + leg, z1 - leg],
            },
        ];
        for p in pieces {
            self.horizontal(p, y[0], false, name);
        }
        for c in f.corners(leg) {
            self.sides(c, [0.0, y[0]], true, &format!("{name} leg"));
        }
    }

    /// A table with four chairs around `centre`.
    fn group(&mut self, centre: [f64; 2], k: usize) {
        let name = format!("group {k} table");
        let top = Footprint::square(centre, TABLE_SIDE);
        self.slab_on_legs(top, [TABLE_BOTTOM, TABLE_TOP], TABLE_LEG, &name);
        self.horizontal(top, TABLE_TOP, true, &name);
        let offset = TABLE_SIDE / 2.0 - CHAIR_TUCK + SEAT_SIDE / 2.0;
        for (n, dir) in [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]]
            .iter()
            .enumerate()
        {
            let c = [centre[0] + dir[0] * offset, centre[1] + dir[1] * offset];
            self.chair(c, *dir, &format!("group {k} chair {n}"));
        }
    }

    /// A chair centred at `c` whose backrest is on the side `away` points to (a unit axis vector).
    fn chair(&mut self, c: [f64; 2], away: [f64; 2], name: &str) {
        let seat = Footprint::square(c, SEAT_SIDE);
        self.slab_on_legs(seat, [SEAT_BOTTOM, SEAT_TOP], CHAIR_LEG, name);
        let (rest, back) = split_off_edge(seat, away, BACKREST_DEPTH);
        self.horizontal(rest, SEAT_TOP, true, name);
        let top = SEAT_TOP + BACKREST_HEIGHT;
        self.sides(back, [SEAT_TOP, top], true, &format!("{name} backrest"));
        self.horizontal(back, top, true, &format!("{name} backrest"));
    }
}

/// Cuts a strip of width `w` off the edge of `f` that `dir` (a unit axis vector) points to: (the rest,
/// the strip).
fn split_off_edge(f: Footprint, dir: [f64; 2], w: f64) -> (Footprint, Footprint) {
    let (mut rest, mut strip) = (f, f);
    match dir {
        [x, _] if x > 0.0 => (rest.x[1], strip.x[0]) = (f.x[1] - w, f.x[1] - w),
        [x, _] if x < 0.0 => (rest.x[0], strip.x[1]) = (f.x[0] + w, f.x[0] + w),
        [_, z] if z > 0.0 => (rest.z[1], strip.z[0]) = (f.z[1] - w, f.z[1] - w),
        _ => (rest.z[0], strip.z[1]) = (f.z[0] + w, f.z[0] + w),
    }
    (rest, strip)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_stay_apart_and_inside_the_room() {
        for v in "abcdef".chars() {
            let c = layout(v).unwrap();
            assert_eq!(c.len(), [1, 4, 16, 16, 16, 16]["abcdef".find(v).unwrap()]);
            for (i, p) in c.iter().enumerate() {
                for x in p {
                    assert!(x - GROUP_HALF_WIDTH >= WALL_GAP - 1e-12, "{v}: group {i}");
                    assert!(
                        x + GROUP_HALF_WIDTH <= ROOM_SIDE - WALL_GAP + 1e-12,
                        "{v}: group {i}"
                    );
                }
                for q in &c[..i] {
                    let apart = (0..2).any(|a| (p[a] - q[a]).abs() >= 2.0 * GROUP_HALF_WIDTH + 0.1);
                    assert!(apart, "{v}: group {i} overlaps another");
                }
            }
        }
        assert!(layout('g').is_none());
    }

    #[test]
    fn a_backrest_strip_and_the_rest_tile_the_seat() {
        let f = Footprint::square([1.0, 2.0], 0.45);
        for dir in [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]] {
            let (rest, strip) = split_off_edge(f, dir, 0.05);
            let area = |g: Footprint| (g.x[1] - g.x[0]) * (g.z[1] - g.z[0]);
            assert!((area(rest) + area(strip) - area(f)).abs() < 1e-12);
            assert!((area(strip) - 0.45 * 0.05).abs() < 1e-12);
            // The strip's middle is 0.225 - 0.025 from the seat's centre, on the side `dir` points to.
            let mid = |g: Footprint| [(g.x[0] + g.x[1]) / 2.0 - 1.0, (g.z[0] + g.z[1]) / 2.0 - 2.0];
            let along = mid(strip)[0] * dir[0] + mid(strip)[1] * dir[1];
            assert!((along - 0.2).abs() < 1e-12, "{dir:?}: {along}");
        }
    }
}
