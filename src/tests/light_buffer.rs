//! The light buffer (Haines & Greenberg 1986) that culls shadow rays read backwards from a
//! light: every box a ray from the light meets in its interval is offered, once, nearest
//! boxes first; rays from elsewhere still find every box.

use super::common::Rng;
use crate::geometry::{Aabb, LightBuffer};
use glam::DVec3;

/// Boxes of every kind around the light at `o`: small and far, large, straddling the planes
/// through the light that part the cube's faces, flat ones, and some that hold the light.
fn boxes(r: &mut Rng, o: DVec3) -> Vec<Aabb> {
    (0..600)
        .map(|i| {
            let c = o + match i % 6 {
                0 => r.unit() * r.range(0.5, 3.0),
                _ => r.unit() * r.range(1.0, 60.0),
            };
            let h = match i % 5 {
                0 => DVec3::new(r.range(0.0, 8.0), r.range(0.0, 8.0), r.range(0.0, 8.0)),
                1 => DVec3::new(r.range(0.0, 0.3), 0.0, r.range(0.0, 2.0)),
                _ => DVec3::splat(r.range(0.05, 1.5)),
            };
            Aabb::new(c - h, c + h)
        })
        .collect()
}

/// A direction, often on or next to a face boundary (two or three equal components).
fn direction(r: &mut Rng) -> DVec3 {
    let d = r.unit();
    let s = |x: f64| if x < 0.0 { -1.0 } else { 1.0 };
    match r.next_u64() % 4 {
        0 => DVec3::new(s(d.x) * d.y.abs(), d.y, d.z),
        1 => DVec3::new(s(d.x), s(d.y), s(d.z)),
        2 => DVec3::new(d.x, s(d.y) * d.x.abs() * (1.0 + 1e-15), d.z),
        _ => d,
    }
}

/// Many large boxes in a cone before the light, their shadows dozens deep (as many groups'
/// boxes swept over a slice of time are): the grid's cells follow the rectangles' size.
fn deep_boxes(r: &mut Rng, o: DVec3) -> Vec<Aabb> {
    (0..3000)
        .map(|_| {
            let c = o + (DVec3::Y + 0.4 * r.unit()).normalize() * r.range(10.0, 30.0);
            let h = DVec3::new(r.range(1.0, 4.0), r.range(0.5, 2.0), r.range(1.0, 3.0));
            Aabb::new(c - h, c + h)
        })
        .collect()
}

#[test]
fn light_buffer_offers_every_box_a_ray_meets_once_nearest_first() {
    let mut r = Rng(77);
    let o = DVec3::new(3.0, -20.0, 7.0);
    let boxes = boxes(&mut r, o);
    let lb = LightBuffer::build(o, &boxes);
    offers_every_met_box(&mut r, o, &lb, &boxes, 20_000);
}

/// Where the boxes' shadows lie dozens deep, cells finer than the boxes' rectangles would list
/// each box in ever more of them for no fewer boxes per ray: the grid stops at about two cells
/// across the median rectangle, and still offers every box a ray meets.
#[test]
fn light_buffer_cells_follow_deep_shadows() {
    let mut r = Rng(79);
    let o = DVec3::new(-2.0, 5.0, 1.0);
    let boxes = deep_boxes(&mut r, o);
    let lb = LightBuffer::build(o, &boxes);
    let per_box = lb.entries() as f64 / boxes.len() as f64;
    assert!(per_box < 16.0, "each box listed in {per_box} cells");
    offers_every_met_box(&mut r, o, &lb, &boxes, 4000);
}

/// Rays from the light at `o` (and, every tenth, from elsewhere) through `lb`, the buffer of
/// `boxes`: each box a ray meets in its interval is offered once, nearest first, and no other.
fn offers_every_met_box(r: &mut Rng, o: DVec3, lb: &LightBuffer, boxes: &[Aabb], rays: usize) {
    assert_eq!(lb.len(), boxes.len());
    let mut met = 0;
    for k in 0..rays {
        // Rays from the light, and (every tenth) from elsewhere.
        let from = if k % 10 == 0 {
            o + r.unit() * r.range(0.0, 30.0)
        } else {
            o
        };
        let d = direction(r) * r.range(0.2, 3.0);
        let tmin = if k % 3 == 0 { r.range(0.0, 10.0) } else { 0.0 };
        let mut tmax = [if k % 7 == 0 {
            f64::INFINITY
        } else {
            r.range(tmin, 60.0)
        }];
        let want: Vec<usize> = (0..boxes.len())
            .filter(|&i| boxes[i].clip(from, d.recip(), tmin, tmax[0]).is_some())
            .collect();
        let mut got = Vec::new();
        lb.traverse(from, &[d], &[tmin], &mut tmax, &mut |item, ray, t| {
            assert_eq!(ray, 0);
            got.push(item as usize);
            t
        });
        for i in &want {
            assert!(got.contains(i), "box {i} is met by ray {k} but not offered");
        }
        let mut once = got.clone();
        once.sort_unstable();
        once.dedup();
        assert_eq!(once.len(), got.len(), "ray {k}: a box was offered twice");
        for i in &got {
            assert!(want.contains(i), "ray {k}: box {i} offered but not met");
        }
        if from == o {
            let near = |i: &usize| {
                let b = &boxes[*i];
                (b.min - o).max(o - b.max).max(DVec3::ZERO).length()
            };
            assert!(
                got.windows(2).all(|w| near(&w[0]) <= near(&w[1])),
                "ray {k}: boxes not offered nearest first"
            );
        }
        met += want.len();
    }
    assert!(met > rays, "enough meetings checked ({met})");
}

#[test]
fn light_buffer_stops_a_ray_once_blocked_and_handles_empty_sets() {
    let mut r = Rng(78);
    let o = DVec3::ZERO;
    let boxes = boxes(&mut r, o);
    let lb = LightBuffer::build(o, &boxes);
    for _ in 0..2000 {
        let d = direction(&mut r);
        let mut tmax = [f64::INFINITY];
        let mut offers = 0;
        lb.traverse(o, &[d], &[0.0], &mut tmax, &mut |_, _, _| {
            offers += 1;
            f64::NEG_INFINITY
        });
        assert!(
            offers <= 1,
            "offered {offers} boxes after the first blocked"
        );
    }
    let empty = LightBuffer::build(o, &[]);
    assert!(empty.is_empty());
    let mut tmax = [1.0];
    empty.traverse(o, &[DVec3::X], &[0.0], &mut tmax, &mut |_, _, _| {
        panic!("nothing to offer")
    });
}
