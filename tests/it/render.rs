//! Pictures of a scene (`scene_complexity::render`): the default camera stands inside an enclosure
//! (every sample sees the front of a wall) and outside an object (background around it, no back side
//! seen); a camera behind a wall sees its back side.

use scene_complexity::internals::geom::{Point, Vector};
use scene_complexity::internals::scene::{obj, Scene};
use scene_complexity::internals::scenes;
use scene_complexity::internals::trace::{make_tracer, Backend, Query};
use scene_complexity::render::{default_camera, trace_view, Camera, Sample};

fn samples(scene: &Scene, camera: Option<Camera>) -> Vec<Sample> {
    let tracer = make_tracer(Backend::Rust, scene, Query::Single).unwrap();
    let camera = camera.unwrap_or_else(|| default_camera(scene, tracer.as_ref()).unwrap());
    camera.validate().unwrap();
    trace_view(scene, tracer.as_ref(), &camera, 64, 48)
        .unwrap()
        .samples
}

fn count(s: &[Sample], f: impl Fn(&Sample) -> bool) -> usize {
    s.iter().filter(|x| f(x)).count()
}

#[test]
fn the_default_view_of_a_room_is_from_inside() {
    for spec in ["@cube:4", "@cornell", "@fig2:a", "@labyrinth"] {
        let scene = scenes::load(spec).unwrap();
        let s = samples(&scene, None);
        let front = count(&s, |x| matches!(x, Sample::Front { .. }));
        assert_eq!(
            front,
            s.len(),
            "{spec}: every sample sees the front of a surface"
        );
        let seen: std::collections::BTreeSet<u32> = s.iter().filter_map(Sample::patch).collect();
        assert!(seen.len() > 3, "{spec}: the view shows several patches");
    }
}

/// A box with outward faces (an object in open space).
fn a_box() -> Scene {
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n\
                f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\nf 5 6 8 7\n";
    obj::load_text("box.obj", text, &|_| Err(obj::MtlError::other("no MTL"))).unwrap()
}

#[test]
fn the_default_view_of_an_object_is_from_outside() {
    let scene = a_box();
    let s = samples(&scene, None);
    assert!(count(&s, |x| *x == Sample::Background) > s.len() / 4);
    assert!(count(&s, |x| matches!(x, Sample::Front { .. })) > s.len() / 10);
    assert_eq!(count(&s, |x| matches!(x, Sample::Back { .. })), 0);
    // Three faces show from the front, above and to the right.
    let seen: std::collections::BTreeSet<u32> = s.iter().filter_map(Sample::patch).collect();
    assert_eq!(seen.len(), 3, "{seen:?}");
}

#[test]
fn a_camera_outside_a_room_sees_the_back_of_a_wall() {
    let scene = scenes::load("@cube:2").unwrap();
    let camera = Camera {
        eye: Point::new(0.5, 0.5, -2.0),
        target: Point::new(0.5, 0.5, 0.5),
        up: Vector::Y,
        fov_degrees: 20.0,
    };
    let s = samples(&scene, Some(camera));
    assert_eq!(count(&s, |x| matches!(x, Sample::Back { .. })), s.len());
    // And from inside, looking at the same wall from the far side, its front.
    let inside = Camera {
        eye: Point::new(0.5, 0.5, 0.9),
        target: Point::new(0.5, 0.5, 0.0),
        ..camera
    };
    let s = samples(&scene, Some(inside));
    assert_eq!(count(&s, |x| matches!(x, Sample::Front { .. })), s.len());
}
