//! Many velocity groups: the kinetic group tree finds every group a ray can meet (never fewer),
//! and renders with and without it, or with equal velocities merged or not, are identical.

use super::common::*;
use super::EIGHT_SEGMENTS;
use crate::geometry::Aabb;
use crate::render::{render_world, Frame, GroupTree, SlicedGroupTree, World, WorldOptions};
use crate::spacetime::{Boost, Event, NullRay, Velocity};
use glam::DVec3;

/// Exact: whether the ray meets a group's bounds in lookback (0, tmax), tested in the group's
/// rest frame against its rest-frame bounds.
fn meets(b: &Aabb, v: &Velocity, ray: &NullRay, tmax: f64) -> bool {
    let boost = Boost::to_rest(v);
    let (d, _) = boost.null_dir(ray.dir);
    b.clip(boost.event(ray.origin).x, d.recip(), 0.0, tmax)
        .is_some()
}

#[test]
fn group_tree_visits_every_group_a_ray_meets() {
    let mut r = Rng(3);
    let groups: Vec<(Aabb, Velocity)> = (0..500)
        .map(|_| {
            let c = DVec3::new(
                r.range(-50.0, 50.0),
                r.range(-50.0, 50.0),
                r.range(-50.0, 50.0),
            );
            let h = DVec3::new(r.range(0.1, 2.0), r.range(0.1, 2.0), r.range(0.1, 2.0));
            let v = Velocity::from_rapidity(r.unit(), r.range(0.0, 3.0)).unwrap();
            (Aabb::new(c - h, c + h), v)
        })
        .collect();
    let t_ref = 20.0;
    let tree = GroupTree::build(&groups, t_ref);
    // Sliced: inner slices first test each node's static box over their time span.
    let sliced = SlicedGroupTree::build(&groups, -80.0, 80.0, 16);
    let mut checked = 0;
    for k in 0..24000 {
        // Rays from arbitrary events, before and after the reference time.
        let o = Event::new(
            r.range(-100.0, 100.0),
            DVec3::new(
                r.range(-60.0, 60.0),
                r.range(-60.0, 60.0),
                r.range(-60.0, 60.0),
            ),
        );
        let ray = NullRay::new(o, r.unit());
        let tmax = if r.f() < 0.5 {
            f64::INFINITY
        } else {
            r.range(1.0, 200.0)
        };
        let mut visited = vec![false; groups.len()];
        let mark = |g: u32, t: f64| {
            visited[g as usize] = true;
            t
        };
        if k % 2 == 0 {
            tree.traverse(&ray, 0.0, tmax, mark);
        } else {
            sliced.traverse(&ray, 0.0, tmax, mark);
        }
        for (i, (b, v)) in groups.iter().enumerate() {
            if meets(b, v, &ray, tmax) {
                checked += 1;
                assert!(
                    visited[i],
                    "group {i} is met by the ray but the tree skipped it"
                );
            }
        }
    }
    assert!(
        checked > 1200,
        "enough ray-group meetings were checked ({checked})"
    );
}

/// `n` small objects, each in its own group with its own velocity (some groups share one),
/// a light and a mirror, all in front of the camera.
fn many_groups_scene(n: usize) -> String {
    let mut r = Rng(11);
    let mut s = String::from(
        r#"
[camera]
position = [0, -30, 0]
look_at = [0, 0, 0]
fov_y = 60
time = 30
[image]
width = 120
height = 90
[[material]]
name = "mirror"
color = 0.1
reflect = 0.7
[[light]]
position = [0, -20, 30]
"#,
    );
    for i in 0..n {
        let c = DVec3::new(
            r.range(-15.0, 15.0),
            r.range(-10.0, 10.0),
            r.range(-12.0, 12.0),
        );
        // Every fifth group shares the velocity of the one before it.
        let v = if i % 5 == 4 {
            DVec3::new(0.3, 0.1, 0.0)
        } else {
            r.unit() * r.range(0.0, 0.6)
        };
        let v = if i % 5 == 3 {
            DVec3::new(0.3, 0.1, 0.0)
        } else {
            v
        };
        s += &format!(
            "[[group]]\nname = \"g{i}\"\nvelocity = [{:?}, {:?}, {:?}]\n[[group.object]]\n",
            v.x, v.y, v.z
        );
        if i % 3 == 0 {
            s += &format!(
                "type = \"sphere\"\ncenter = [{:?}, {:?}, {:?}]\nradius = 0.8\nmaterial = \"mirror\"\n",
                c.x, c.y, c.z
            );
        } else {
            s += &format!(
                "type = \"box\"\nmin = [{:?}, {:?}, {:?}]\nmax = [{:?}, {:?}, {:?}]\n",
                c.x - 0.6,
                c.y - 0.6,
                c.z - 0.6,
                c.x + 0.6,
                c.y + 0.6,
                c.z + 0.6
            );
        }
    }
    s
}

#[test]
fn group_tree_and_merging_do_not_change_the_picture() {
    let s = scene(&many_groups_scene(200));
    for name in backends() {
        let backend = crate::accel::backend_by_name(name).unwrap();
        let plain = World::build_with(
            &s,
            backend.as_ref(),
            WorldOptions {
                merge_equal_velocities: false,
                bounds_cull: true,
                group_tree: false,
                ..Default::default()
            },
        )
        .unwrap();
        let fast = World::build(&s, backend.as_ref()).unwrap();
        assert!(fast.uses_group_tree() && !plain.uses_group_tree());
        assert!(
            fast.groups.len() < plain.groups.len(),
            "equal velocities were merged"
        );
        let a = render_world(&s, &plain).0;
        let b = render_world(&s, &fast).0;
        let hit = a.pixels.iter().filter(|p| p.object_id != 0).count();
        assert!(hit > 1000, "{name}: the objects are in view ({hit})");
        // The tree alone changes nothing at all.
        let tree_only = World::build_with(
            &s,
            backend.as_ref(),
            WorldOptions {
                merge_equal_velocities: false,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(
            render_world(&s, &tree_only).0,
            a,
            "{name}: the group tree changes no bit"
        );
        // Merging moves each scene's bounds, so rays are rebased at other points: rounding only.
        same_picture(&a, &b, &format!("{name}, with merging"), 0.0, 1e-4);
    }
}

#[test]
fn apparent_boxes_hold_every_apparent_position() {
    use crate::render::apparent_box;
    use crate::spacetime::retarded_position;
    let mut r = Rng(5);
    for _ in 0..400 {
        let c = DVec3::new(
            r.range(-30.0, 30.0),
            r.range(-30.0, 30.0),
            r.range(-30.0, 30.0),
        );
        let h = DVec3::new(r.range(0.1, 3.0), r.range(0.1, 3.0), r.range(0.1, 3.0));
        let rest = Aabb::new(c - h, c + h);
        let v = Velocity::from_rapidity(r.unit(), r.range(0.0, 3.0)).unwrap();
        let event = Event::new(
            r.range(-20.0, 20.0),
            DVec3::new(
                r.range(-40.0, 40.0),
                r.range(-40.0, 40.0),
                r.range(-40.0, 40.0),
            ),
        );
        let b = apparent_box(&rest, &v, event);
        let now = crate::render::world_box(&rest, &v, event.t);
        // Points of the body (lab-simultaneous at the view time) and where they are seen.
        for _ in 0..50 {
            let p = now.min + (now.max - now.min) * DVec3::new(r.f(), r.f(), r.f());
            // world_box is the AABB of the contracted box; keep points inside the body itself.
            let back = p - v.beta_vec() * event.t;
            let g = v.gamma();
            let rest_p = back + (g - 1.0) * back.dot(v.direction()) * v.direction();
            if !(rest_p.cmpge(rest.min - 1e-9).all() && rest_p.cmple(rest.max + 1e-9).all()) {
                continue;
            }
            let seen = event.x + retarded_position(p - event.x, &v);
            let tol = 1e-7 * (1.0 + seen.abs().max_element());
            assert!(
                seen.cmpge(b.min - tol).all() && seen.cmple(b.max + tol).all(),
                "apparent point {seen} outside {b:?}"
            );
        }
    }
}

/// A random group: rest-frame box and velocity (up to rapidity 3, β ≈ 0.995).
fn random_group(r: &mut Rng, spread: f64) -> (Aabb, Velocity) {
    let c = DVec3::new(
        r.range(-spread, spread),
        r.range(-spread, spread),
        r.range(-spread, spread),
    );
    let h = DVec3::new(r.range(0.1, 3.0), r.range(0.1, 3.0), r.range(0.1, 3.0));
    let v = Velocity::from_rapidity(r.unit(), r.range(0.0, 3.0)).unwrap();
    (Aabb::new(c - h, c + h), v)
}

#[test]
fn reach_boxes_hold_every_point_light_from_the_slice_meets() {
    use crate::render::reach_box;
    let mut r = Rng(17);
    let mut checked = 0;
    for _ in 0..400 {
        let (rest, v) = random_group(&mut r, 30.0);
        let light = DVec3::new(
            r.range(-40.0, 40.0),
            r.range(-40.0, 40.0),
            r.range(-40.0, 40.0),
        );
        let t_a = r.range(-60.0, 20.0);
        let t_b = t_a + r.range(0.0, 10.0);
        let b = reach_box(&rest, &v, light, t_a, t_b);
        let (u, g) = (v.direction(), v.gamma());
        for _ in 0..50 {
            // A point of the body (rest frame), where it is at world time 0, and the light that
            // left `light` at t_e: it reaches the point τ later, τ = |d0 + v τ|.
            let q = rest.min + (rest.max - rest.min) * DVec3::new(r.f(), r.f(), r.f());
            let at_zero = q + (1.0 / g - 1.0) * q.dot(u) * u;
            let t_e = r.range(t_a, t_b);
            let vel = v.beta_vec();
            let d0 = at_zero + vel * t_e - light;
            let (vd, b2) = (vel.dot(d0), vel.length_squared());
            let tau = (vd + (vd * vd + (1.0 - b2) * d0.length_squared()).sqrt()) / (1.0 - b2);
            let met = d0 + vel * tau + light;
            assert!(
                ((met - light).length() - tau).abs() <= 1e-9 * (1.0 + tau),
                "the meeting point is on the light's cone"
            );
            let tol = 1e-7 * (1.0 + met.abs().max_element());
            assert!(
                met.cmpge(b.min - tol).all() && met.cmple(b.max + tol).all(),
                "light from {light} at {t_e} meets the group at {met}, outside {b:?}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 20_000);
}

/// Where a shadow ray starts: an event among the groups, or (a share `on_cone` of the time, as
/// from a primary hit) on the imaging event's past light cone.
fn shadow_origin(r: &mut Rng, event: Event, on_cone: f64) -> Event {
    if r.f() >= on_cone {
        Event::new(
            r.range(-100.0, 40.0),
            DVec3::new(
                r.range(-60.0, 60.0),
                r.range(-60.0, 60.0),
                r.range(-60.0, 60.0),
            ),
        )
    } else {
        let back = r.range(10.0, 120.0);
        Event::new(event.t - back, event.x + back * r.unit())
    }
}

#[test]
fn light_tree_visits_every_group_a_shadow_ray_meets() {
    use crate::render::LightTree;
    let mut r = Rng(23);
    let groups: Vec<(Aabb, Velocity)> = (0..500).map(|_| random_group(&mut r, 50.0)).collect();
    let light = DVec3::new(10.0, -70.0, 30.0);
    // An imaging event far in the future of every ray (each slice holds every group), and one
    // close by, whose causal past leaves the later slices only the groups near it.
    // Thin slices in the second case, so that a run of slices sharing a tree shape is short.
    // Every backend's culling structure (the f64 box tree refitted, Embree's built per slice),
    // and light buffers around the light (what the renderer uses).
    let names = backends().into_iter().chain(["light-buffer"]);
    let cases = names.flat_map(|name| {
        [
            (name, Event::new(400.0, DVec3::ZERO), 0.0, 32, 5000),
            (
                name,
                Event::new(60.0, DVec3::new(0.0, -40.0, 0.0)),
                0.5,
                512,
                3000,
            ),
        ]
    });
    for (name, event, on_cone, slices, min_served) in cases {
        let cullers = match name {
            "light-buffer" => crate::accel::light_buffers(light),
            _ => crate::accel::backend_by_name(name).unwrap().cullers(),
        };
        let tree = LightTree::new(
            groups.clone().into(),
            cullers,
            light,
            event,
            -200.0,
            40.0,
            slices,
        );
        let (mut served, mut checked) = (0, 0);
        for _ in 0..10_000 {
            let o = shadow_origin(&mut r, event, on_cone);
            let to = light - o.x;
            let ray = NullRay::new(o, to / to.length());
            let tmax = to.length() * (1.0 - 1e-9);
            let mut visited = vec![false; groups.len()];
            let mark = |g: u32| {
                visited[g as usize] = true;
                false
            };
            let in_past = (o.x - event.x).length() <= (event.t - o.t) * (1.0 + 1e-12);
            if tree.occluded(&ray, 0.0, tmax, mark).is_none() {
                continue;
            }
            assert!(
                in_past,
                "a ray from outside the imaging event's past was served"
            );
            served += 1;
            for (i, (b, v)) in groups.iter().enumerate() {
                if meets(b, v, &ray, tmax) {
                    checked += 1;
                    assert!(visited[i], "group {i} is met by the shadow ray but skipped");
                }
            }
        }
        // Rays that left the light before -200 or after 40 are not served (the kinetic trees
        // take them), nor rays from outside the imaging event's causal past.
        assert!(served > min_served, "enough rays are served ({served})");
        assert!(
            checked > min_served / 4,
            "enough ray-group meetings were checked ({checked})"
        );
        // A ray that does not head for the light is never served.
        let o = Event::new(0.0, DVec3::ZERO);
        let off = NullRay::new(o, (light - o.x).normalize() + DVec3::new(0.0, 0.0, 1e-3));
        assert!(tree.occluded(&off, 0.0, 10.0, |_| false).is_none());

        // In packets: the same rays served, and every group a ray meets offered to the test.
        let rays: Vec<NullRay> = (0..2000)
            .map(|_| {
                let o = shadow_origin(&mut r, event, on_cone);
                let to = light - o.x;
                NullRay::new(o, to / to.length())
            })
            .collect();
        let tmax: Vec<f64> = rays
            .iter()
            .map(|ray| (light - ray.origin.x).length() * (1.0 - 1e-9))
            .collect();
        let (mut served, mut blocked) = (vec![false; rays.len()], vec![false; rays.len()]);
        let mut offered = vec![Vec::new(); rays.len()];
        let mut order = Vec::new();
        let buffers = (served.as_mut_slice(), &mut order);
        tree.occluded_many(&rays, &tmax, buffers, &mut blocked, |g, i| {
            offered[i].push(g as usize);
            false
        });
        assert!(
            blocked.iter().all(|&b| !b),
            "nothing blocks when the test never holds"
        );
        // A test that holds blocks the ray, and stops offering it groups.
        let mut offers = vec![0; rays.len()];
        let (mut served2, mut blocked) = (vec![false; rays.len()], vec![false; rays.len()]);
        let buffers = (served2.as_mut_slice(), &mut order);
        tree.occluded_many(&rays, &tmax, buffers, &mut blocked, |_, i| {
            offers[i] += 1;
            true
        });
        assert_eq!(served, served2);
        let mut met = 0;
        for (i, ray) in rays.iter().enumerate() {
            assert_eq!(
                served[i],
                tree.occluded(ray, 0.0, tmax[i], |_| false).is_some(),
                "{name}: ray {i}"
            );
            assert!(
                offers[i] <= 1,
                "{name}: ray {i} was tested after it was blocked"
            );
            if !served[i] {
                continue;
            }
            // (Candidates may be more than the groups met: Embree offers a packet's lanes
            // every box of a leaf the packet reaches.)
            for (g, (b, v)) in groups.iter().enumerate() {
                if meets(b, v, ray, tmax[i]) {
                    met += 1;
                    assert!(
                        offered[i].contains(&g),
                        "{name}: packets skip group {g} on ray {i}"
                    );
                    assert!(
                        blocked[i],
                        "{name}: ray {i} meets group {g} but was not blocked"
                    );
                }
            }
        }
        assert!(met > 100, "enough meetings checked in packets ({met})");
    }
}

#[test]
fn refitted_trees_bound_their_new_boxes() {
    use crate::geometry::BoxTree;
    let mut r = Rng(29);
    let boxes: Vec<Aabb> = (0..300).map(|_| random_group(&mut r, 40.0).0).collect();
    let tree = BoxTree::build(&boxes);
    let moved: Vec<Aabb> = boxes
        .iter()
        .map(|b| {
            let d = DVec3::new(r.range(-5.0, 5.0), r.range(-5.0, 5.0), r.range(-5.0, 5.0));
            Aabb::new(b.min + d, b.max + d)
        })
        .collect();
    let refit = tree.refit_with(|k| moved[k as usize]);
    assert_eq!(refit.indices, tree.indices);
    // Every node holds exactly the union of the moved boxes beneath it.
    fn under(t: &BoxTree, i: usize, boxes: &[Aabb]) -> Aabb {
        let n = &t.nodes[i];
        if n.count > 0 {
            t.indices[n.first as usize..(n.first + n.count) as usize]
                .iter()
                .fold(Aabb::EMPTY, |b, &k| b.union(&boxes[k as usize]))
        } else {
            under(t, n.first as usize, boxes).union(&under(t, n.first as usize + 1, boxes))
        }
    }
    for i in 0..refit.nodes.len() {
        let (want, got) = (under(&refit, i, &moved), refit.nodes[i].bounds);
        assert_eq!((got.min, got.max), (want.min, want.max), "node {i}");
    }
    // A tree of nothing refits to a tree of nothing.
    let empty = BoxTree::build(&[]).refit_with(|_| unreachable!());
    assert!(empty.indices.is_empty());
}

/// The scene rendered on `backend` without the group trees and with them (the picture they
/// must not change), equal velocities merged or not as `merge` says.
fn without_and_with_trees(s: &crate::scene::Scene, backend: &str, merge: bool) -> (Frame, Frame) {
    let backend = crate::accel::backend_by_name(backend).unwrap();
    let options = |group_tree| WorldOptions {
        merge_equal_velocities: merge,
        group_tree,
        ..Default::default()
    };
    let plain = World::build_with(s, backend.as_ref(), options(false)).unwrap();
    let fast = World::build_with(s, backend.as_ref(), options(true)).unwrap();
    assert!(fast.uses_group_tree() && !plain.uses_group_tree());
    (render_world(s, &plain).0, render_world(s, &fast).0)
}

#[test]
fn shadows_toward_a_moving_light_are_the_same_with_the_trees() {
    // A moving light has no light tree: its shadow rays take the kinetic trees.
    let text = many_groups_scene(120).replace(
        "[[light]]\nposition = [0, -20, 30]\n",
        "[[light]]\nposition = [0, -20, 30]\nvelocity = [0.4, 0, 0.2]\n",
    );
    assert!(text.contains("velocity = [0.4, 0, 0.2]"));
    let s = scene(&text);
    let (a, b) = without_and_with_trees(&s, "bvh", false);
    let lit = a
        .pixels
        .iter()
        .filter(|p| p.color.iter().any(|&c| c > 0.05))
        .count();
    assert!(
        lit > 500,
        "the light reaches the objects ({lit} lit pixels)"
    );
    assert_eq!(a, b, "the trees change no bit");
}

#[test]
fn a_light_among_the_groups_casts_the_same_shadows_with_the_light_buffers() {
    // The light in the middle of the groups: shadow rays leave it on every face of its light
    // buffers' cubes, and some groups' reach holds the light itself.
    let text = many_groups_scene(200).replace(
        "[[light]]\nposition = [0, -20, 30]\n",
        "[[light]]\nposition = [0.5, 0.3, -0.2]\n",
    );
    assert!(text.contains("position = [0.5, 0.3, -0.2]"));
    let s = scene(&text);
    for name in backends() {
        let (a, b) = without_and_with_trees(&s, name, false);
        let hit = a.pixels.iter().filter(|p| p.object_id != 0).count();
        let lit = a
            .pixels
            .iter()
            .filter(|p| p.object_id != 0 && p.color.iter().any(|&c| c > 0.05))
            .count();
        assert!(
            lit > 300 && hit - lit > 300,
            "{name}: lit and shadowed surfaces in view ({lit} lit of {hit})"
        );
        let differ = super::differing_pixels(&a, &b);
        assert_eq!(
            differ, 0,
            "{name}: the light buffers change {differ} pixels"
        );
    }
}

#[test]
fn a_far_camera_sees_the_same_groups_with_the_trees() {
    // 300 slow groups (so their apparent boxes stay ~30 across) seen from 1e7 away, off every
    // axis, through a long lens: f32 coordinates of the camera about the groups' centre are
    // then off by ~0.5, and must not lose a group the f64 test finds, on any backend's culler.
    let mut r = Rng(31);
    let mut text = String::from(
        "[camera]\nposition = [7000000.37, -7000000, 0.21]\nlook_at = [0, 0, 0]\n\
         fov_y = 0.0002\ntime = 10000000\n[image]\nwidth = 120\nheight = 90\n",
    );
    for i in 0..300 {
        let c = DVec3::new(
            r.range(-15.0, 15.0),
            r.range(-10.0, 10.0),
            r.range(-12.0, 12.0),
        );
        let v = r.unit() * r.range(1e-9, 1e-7);
        text += &format!(
            "[[group]]\nname = \"g{i}\"\nvelocity = [{:?}, {:?}, {:?}]\n[[group.object]]\n\
             type = \"box\"\nmin = [{:?}, {:?}, {:?}]\nmax = [{:?}, {:?}, {:?}]\n",
            v.x,
            v.y,
            v.z,
            c.x - 0.4,
            c.y - 0.4,
            c.z - 0.4,
            c.x + 0.4,
            c.y + 0.4,
            c.z + 0.4
        );
    }
    let s = scene(&text);
    for name in backends() {
        let (a, b) = without_and_with_trees(&s, name, true);
        let hit = a.pixels.iter().filter(|p| p.object_id != 0).count();
        assert!(hit > 1000, "{name}: the objects are in view ({hit})");
        // The same object in every pixel (the clearer message), then every bit.
        same_picture(&a, &b, name, 0.0, 0.0);
        assert!(a == b, "{name}: the trees change no bit");
    }
}

#[test]
fn the_moving_bounds_test_turns_away_no_hit() {
    // Bounds culling off: no group's bounds are tested before its boost, in either frame, so
    // every group a tree hands a ray is boosted and intersected. The pictures must agree but
    // for rounding (rays are rebased at the bounds only with the cull); a world-frame test that
    // turned a ray away from a group it meets would change which object a pixel sees.
    let s = scene(&many_groups_scene(200));
    for name in backends() {
        let backend = crate::accel::backend_by_name(name).unwrap();
        let culled = World::build(&s, backend.as_ref()).unwrap();
        let plain = World::build_with(
            &s,
            backend.as_ref(),
            WorldOptions {
                bounds_cull: false,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(culled.uses_group_tree() && plain.uses_group_tree());
        let a = render_world(&s, &plain).0;
        let b = render_world(&s, &culled).0;
        let hit = a.pixels.iter().filter(|p| p.object_id != 0).count();
        assert!(hit > 1000, "{name}: the objects are in view ({hit})");
        // Colours too: a shadow ray wrongly let through lights a pixel.
        same_picture(&a, &b, name, 0.0, 1e-4);
    }
}

/// The trees count bodies, not groups: a body on a worldline of eight segments (eight groups
/// of one name, each met only in its window) goes without them, and eight bodies in groups of
/// their own take them. Both draw what the f64 BVH draws.
#[test]
fn the_group_trees_count_bodies_not_a_worldlines_segments() {
    let segments = EIGHT_SEGMENTS;
    let head = "[camera]\nposition = [0, -30, 0]\nlook_at = [0, 0, 0]\ntime = 3\n\
                [image]\nwidth = 64\nheight = 48\n[[light]]\nposition = [5, -30, 20]\n";
    let body = format!(
        "{head}[[group]]\nname = \"bar\"\nworldline = {segments}\n[[group.object]]\n\
         type = \"box\"\nmin = [-40, -3, -3]\nmax = [-8, 3, 3]\n"
    );
    let mut bodies = head.to_string();
    for i in 0..8 {
        let x = -14.0 + 4.0 * i as f64;
        bodies += &format!(
            "[[group]]\nname = \"b{i}\"\nvelocity = [0, 0, 0.0{i}]\n[[group.object]]\n\
             type = \"box\"\nmin = [{x}, -1, -1]\nmax = [{}, 1, 1]\n",
            x + 2.0
        );
    }
    for (text, trees) in [(body, false), (bodies, true)] {
        let s = crate::scene::load_str("t.toml", &text, &[]).unwrap();
        assert_eq!(s.groups.len(), 8);
        let frames: Vec<Frame> = backends()
            .into_iter()
            .map(|name| {
                let backend = crate::accel::backend_by_name(name).unwrap();
                let w = World::build(&s, backend.as_ref()).unwrap();
                assert_eq!(w.uses_group_tree(), trees, "{name}");
                render_world(&s, &w).0
            })
            .collect();
        let hit = frames[0].pixels.iter().filter(|p| p.object_id != 0).count();
        assert!(hit > 100, "in view ({hit})");
        for f in &frames[1..] {
            same_picture(&frames[0], f, "embree against bvh", 0.0, 1e-4);
        }
    }
}
