//! Shadow rays of a tile are traced together (packets per group): `World::occluded_many` must
//! answer exactly as `World::occluded` ray by ray, on every backend, with few groups and many.

use super::common::*;
use crate::render::World;
use crate::spacetime::{Event, NullRay};
use glam::DVec3;

fn scene_text(groups: usize) -> String {
    let mut r = Rng(5);
    let mut s = String::from(
        "[camera]\nposition = [0, -30, 0]\nlook_at = [0, 0, 0]\ntime = 30\n[image]\nwidth = 8\nheight = 8\n",
    );
    for g in 0..groups {
        let v = [r.range(-0.3, 0.3), r.range(-0.3, 0.3), r.range(-0.3, 0.3)];
        s += &format!(
            "[[group]]\nname = \"g{g}\"\nvelocity = [{:?}, {:?}, {:?}]\n",
            v[0], v[1], v[2]
        );
        for _ in 0..12 {
            let c = [r.range(-8.0, 8.0), r.range(-8.0, 8.0), r.range(-8.0, 8.0)];
            s += &match (r.f() * 3.0) as u32 {
                0 => format!(
                    "[[group.object]]\ntype = \"sphere\"\ncenter = [{:?}, {:?}, {:?}]\nradius = {:?}\n",
                    c[0], c[1], c[2], r.range(0.3, 1.5)
                ),
                1 => format!(
                    "[[group.object]]\ntype = \"box\"\nmin = [{:?}, {:?}, {:?}]\nmax = [{:?}, {:?}, {:?}]\n",
                    c[0] - 1.0, c[1] - 0.5, c[2] - 0.8, c[0] + 1.0, c[1] + 0.5, c[2] + 0.8
                ),
                _ => format!(
                    "[[group.object]]\ntype = \"rod\"\nfrom = [{:?}, {:?}, {:?}]\nto = [{:?}, {:?}, {:?}]\nradius = 0.3\n",
                    c[0], c[1], c[2], c[0] + 2.0, c[1] - 1.0, c[2] + 1.5
                ),
            };
        }
    }
    s
}

#[test]
fn batched_shadow_rays_equal_single_ones() {
    for groups in [1, 3, 40] {
        let s = scene(&scene_text(groups));
        for name in backends() {
            let backend = crate::accel::backend_by_name(name).unwrap();
            let world = World::build(&s, backend.as_ref()).unwrap();
            let mut r = Rng(9);
            let rays: Vec<NullRay> = (0..3000)
                .map(|_| {
                    // From anywhere near the objects, toward them, around the time they sit
                    // near their rest-frame places.
                    let x = DVec3::new(
                        r.range(-15.0, 15.0),
                        r.range(-15.0, 15.0),
                        r.range(-15.0, 15.0),
                    );
                    let target =
                        DVec3::new(r.range(-8.0, 8.0), r.range(-8.0, 8.0), r.range(-8.0, 8.0));
                    NullRay::new(Event::new(r.range(-3.0, 3.0), x), (target - x).normalize())
                })
                .collect();
            let tmax: Vec<f64> = (0..rays.len()).map(|_| r.range(0.5, 40.0)).collect();
            let mut batch = vec![false; rays.len()];
            world.occluded_many(&rays, &tmax, &mut batch);
            let single: Vec<bool> = rays
                .iter()
                .zip(&tmax)
                .map(|(ray, &t)| world.occluded(ray, 0.0, t))
                .collect();
            let blocked = single.iter().filter(|&&b| b).count();
            assert!(
                blocked > 150 && blocked < rays.len() - 150,
                "{groups} groups, {name}: a mix of shadowed and lit rays ({blocked})"
            );
            eprintln!(
                "{groups} groups, {name}: {blocked} of {} rays in shadow",
                rays.len()
            );
            assert_eq!(
                batch, single,
                "{groups} groups, {name}: batched = ray by ray"
            );
        }
    }
}
