//! A body accelerated across the velocity it starts with comes out turned by the
//! Thomas-Wigner rotation (docs/physics.md §1.4, §12.7). Checked against independent models
//! that boost each event through the frames in turn, by the matrix of §1.3, and never form a
//! rotation. (The segments of constant proper acceleration themselves: tests/suite/acceleration.rs.)

use crate::common::*;
use glam::DVec3;
use rest_embree::spacetime::cosh_m1;

const W: u32 = 600;
const H: u32 = 41;
const F: f64 = 500.0;

/// A dumbbell (two balls two apart along y) moving at 0.8c along +y until world time 0, then
/// accelerating along +x at `a` until world time `until`, then coasting; the camera at rest
/// at `camera` at view time `time`, looking along +y.
fn across(a: f64, until: f64, camera: DVec3, time: f64) -> String {
    format!(
        r#"
[camera]
position = [{}, {}, {}]
direction = [0, 1, 0]
fov_y = {fov}
time = {time:?}
[image]
width = {W}
height = {H}
samples = 1
passes = ["all"]
[[light]]
position = [{}, {}, {}]
[[group]]
name = "dumbbell"
worldline = [{{ until = 0, velocity = [0, 0.8, 0] }}, {{ until = {until:?}, acceleration = [{a:?}, 0, 0] }}]
[[group.object]]
type = "sphere"
center = [0, 0, 0]
radius = 0.5
[[group.object]]
type = "sphere"
center = [0, 2, 0]
radius = 0.5
"#,
        camera.x,
        camera.y,
        camera.z,
        camera.x,
        camera.y,
        camera.z,
        fov = fov_for_focal(F, H),
    )
}

/// Accelerating across its motion, the body comes out turned: it is at rest in the frame
/// reached by boosting into S' (0.8c along y) and then, in S', by θ_end along x, whose axes
/// are those of the plain boost to its velocity turned by the Thomas-Wigner rotation (26°
/// here). The independent model maps each event through those two boosts in turn, written out
/// here, and never forms the rotation; the renderer forms only the rotation. Every pixel of
/// the centre row is covered where the model's search finds the dumbbell, at its lookback,
/// with the Doppler factor of the point's velocity (tanh θ / γ₀ along x, 0.8 along y), during
/// the segment and in the coast after it.
#[test]
fn a_body_accelerated_across_its_motion_comes_out_turned_by_the_wigner_rotation() {
    let (a, until) = (0.25f64, 8.0f64);
    let (b0, g0) = (0.8f64, 5.0 / 3.0);
    let theta_end = (a * until / g0).asinh();
    let (ce, se) = (theta_end.cosh(), theta_end.sinh());
    // The shape point of the event (t, p), its piece, and the point's rapidity along x in S'.
    let point = |t: f64, p: DVec3| -> (DVec3, u8, f64) {
        let (tp, yp) = (g0 * (t - b0 * p.y), g0 * (p.y - b0 * t));
        if tp < 0.0 {
            return (DVec3::new(p.x, yp, p.z), 0, 0.0);
        }
        let x = 1.0 / a + p.x;
        if tp * ce - x * se >= 0.0 {
            let x_end = x * ce - tp * se;
            return (DVec3::new(x_end - 1.0 / a, yp, p.z), 2, theta_end);
        }
        if x <= tp.abs() {
            return (DVec3::splat(f64::INFINITY), 1, 0.0);
        }
        let rho = (x * x - tp * tp).sqrt();
        (DVec3::new(rho - 1.0 / a, yp, p.z), 1, (tp / x).atanh())
    };
    let in_shape = |q: DVec3| q.length() < 0.5 || (q - DVec3::new(0.0, 2.0, 0.0)).length() < 0.5;
    // The origin's world position at world time t (it stays at y' = 0 in S', so t = γ₀ T).
    let origin = |t: f64| -> DVec3 {
        let tp = t / g0;
        let t_end = se / a;
        let x = if tp <= t_end {
            cosh_m1((a * tp).asinh()) / a
        } else {
            cosh_m1(theta_end) / a + theta_end.tanh() * (tp - t_end)
        };
        DVec3::new(x, g0 * b0 * tp, 0.0)
    };
    let row = (H / 2) as usize * W as usize;
    let mut pieces = [0; 3];
    // One view of the segment, one of the coast after it: the camera 12 behind the origin's
    // place at a time of emission, 12 later.
    for emitted in [0.5 * until, until + 10.0] {
        let camera = origin(emitted) - DVec3::new(0.0, 12.0, 0.0);
        let time = emitted + 12.0;
        let first = |u: f64| -> Option<(f64, u8, f64)> {
            let d = DVec3::new(u, F, 0.0).normalize();
            let at = |l: f64| point(time - l, camera + l * d);
            first_entry(|l| in_shape(at(l).0), 0.0, 40.0, 1e-3).map(|l| {
                let (_, piece, theta) = at(l);
                (l, piece, theta)
            })
        };
        for backend in backends() {
            let f = render_with(&scene(&across(a, until, camera, time)), backend);
            let (alpha, lookback, doppler) = (
                f.channel("A").unwrap(),
                f.channel("lookback.V").unwrap(),
                f.channel("doppler.V").unwrap(),
            );
            let (mut worst_lookback, mut worst_d) = (0.0f64, 0.0f64);
            for x in 0..W as usize {
                let u = x as f64 + 0.5 - W as f64 / 2.0;
                let truth = first(u);
                let i = row + x;
                assert_eq!(
                    alpha[i] > 0.0,
                    truth.is_some(),
                    "{backend}, emitted at {emitted}: pixel {x}"
                );
                let Some((lambda, piece, theta)) = truth else {
                    continue;
                };
                pieces[piece as usize] += 1;
                worst_lookback = worst_lookback.max((lookback[i] as f64 / lambda - 1.0).abs());
                let dir = DVec3::new(u, F, 0.0).normalize();
                let w = DVec3::new(theta.tanh() / g0, b0, 0.0);
                let d = (1.0 - w.length_squared()).sqrt() / (1.0 + w.dot(dir));
                worst_d = worst_d.max((doppler[i] as f64 / d - 1.0).abs());
            }
            report(
                "dumbbell accelerated across its motion: lookback",
                backend,
                0.0,
                worst_lookback,
                1e-6,
                "relative",
            );
            report(
                "dumbbell accelerated across its motion: each point's Doppler factor",
                backend,
                0.0,
                worst_d,
                1e-5,
                "relative",
            );
        }
    }
    assert!(
        pieces[1] > 20 && pieces[2] > 20,
        "the segment and the coast are both seen: {pieces:?}"
    );
    // The turned coast under a spacetime translation: the turned frame's shift moves it.
    let camera = origin(until + 10.0) - DVec3::new(0.0, 12.0, 0.0);
    let s = scene(&across(a, until, camera, until + 22.0));
    let shift = rest_embree::spacetime::Event::new(-7.0, DVec3::new(30.0, -4.0, 2.5));
    for backend in backends() {
        let (x, y) = (
            render_with(&s, backend),
            render_with(&s.translated(shift), backend),
        );
        same_picture(&x, &y, "translated", 2.0 / (W * H) as f64, 1e-4);
    }
}

/// The passive boost of the event (t, x) into the frame moving at `beta`, from the matrix
/// of docs/physics.md §1.3 (not the renderer's light-cone form).
fn lorentz(beta: DVec3, t: f64, x: DVec3) -> (f64, DVec3) {
    let b2 = beta.length_squared();
    if b2 == 0.0 {
        return (t, x);
    }
    let g = 1.0 / (1.0 - b2).sqrt();
    let bx = beta.dot(x);
    (g * (t - bx), x + ((g - 1.0) * bx / b2 - g * t) * beta)
}

/// Two accelerations across the motion in turn: the second starts with the body already
/// turned, and its acceleration is given in the axes of the plain boost to the velocity it
/// starts at. The model boosts each event through the frames in turn (world, S' at 0.8c
/// along y, S'' reached by the first acceleration), finds the second acceleration's direction
/// in S'' by carrying the 4-vector (0, â₂) from the plain frame through the world, and never
/// forms a rotation. Every pixel of the centre row matches it, at its lookback.
#[test]
fn a_second_acceleration_starts_from_the_turned_body() {
    let (a1, t1, a2, t2) = (0.25f64, 4.0f64, 0.25f64, 8.0f64);
    let v0 = DVec3::new(0.0, 0.8, 0.0);
    let g0 = 5.0 / 3.0;
    let th1 = (a1 * t1 / g0).asinh();
    let ux = DVec3::new(th1.tanh(), 0.0, 0.0);
    // The origin's end of the first segment in S', and S'' coordinates of a world event.
    let (o1t, o1x) = (th1.sinh() / a1, DVec3::new(cosh_m1(th1) / a1, 0.0, 0.0));
    let to_s1 = |t: f64, x: DVec3| lorentz(v0, t, x);
    let to_s2 = |t: f64, x: DVec3| {
        let (tp, xp) = to_s1(t, x);
        lorentz(ux, tp - o1t, xp - o1x)
    };
    let from_s2 = |t: f64, x: DVec3| {
        let (tp, xp) = lorentz(-ux, t, x);
        lorentz(-v0, tp + o1t, xp + o1x)
    };
    // The body's world velocity at the second start, and â₂ = −x of its plain frame in S''.
    let (ot, ox) = from_s2(1.0, DVec3::ZERO);
    let (st, sx) = from_s2(0.0, DVec3::ZERO);
    let w = (ox - sx) / (ot - st);
    let (wt, wx) = lorentz(-w, 0.0, DVec3::new(-1.0, 0.0, 0.0));
    let (n0, n) = to_s2(wt, wx);
    let (z0, z) = to_s2(0.0, DVec3::ZERO);
    assert!((n0 - z0).abs() < 1e-12, "a direction at rest in S''");
    let n = (n - z).normalize();
    // The origin's event at rapidity θ of the second segment (world), and θ at its end.
    let origin2 = |th: f64| from_s2(th.sinh() / a2, cosh_m1(th) / a2 * n);
    let (mut lo, mut hi) = (0.0f64, 10.0f64);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if origin2(mid).0 < t2 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let th2 = 0.5 * (lo + hi);
    let (ce1, se1, ce2, se2) = (th1.cosh(), th1.sinh(), th2.cosh(), th2.sinh());
    let point = |t: f64, p: DVec3| -> (DVec3, u8) {
        let (tp, xp) = to_s1(t, p);
        if tp < 0.0 {
            return (xp, 0);
        }
        let big_x = 1.0 / a1 + xp.x;
        if tp * ce1 - big_x * se1 < 0.0 {
            if big_x <= tp.abs() {
                return (DVec3::splat(f64::INFINITY), 1);
            }
            let rho = (big_x * big_x - tp * tp).sqrt();
            return (DVec3::new(rho - 1.0 / a1, xp.y, xp.z), 1);
        }
        let (tq, xq) = to_s2(t, p);
        if tq < 0.0 {
            return (xq, 1);
        }
        let along = xq.dot(n);
        let big_x = 1.0 / a2 + along;
        if tq * ce2 - big_x * se2 >= 0.0 {
            let x_end = big_x * ce2 - tq * se2;
            return (xq + (x_end - 1.0 / a2 - along) * n, 3);
        }
        if big_x <= tq.abs() {
            return (DVec3::splat(f64::INFINITY), 2);
        }
        let rho = (big_x * big_x - tq * tq).sqrt();
        (xq + (rho - 1.0 / a2 - along) * n, 2)
    };
    let in_shape = |q: DVec3| q.length() < 0.5 || (q - DVec3::new(0.0, 2.0, 0.0)).length() < 0.5;
    let text = |camera: DVec3, time: f64| {
        across(a1, t1, camera, time).replace(
            &format!("{{ until = {t1:?}, acceleration = [{a1:?}, 0, 0] }}]"),
            &format!("{{ until = {t1:?}, acceleration = [{a1:?}, 0, 0] }}, {{ until = {t2:?}, acceleration = [{:?}, 0, 0] }}]", -a2),
        )
    };
    let row = (H / 2) as usize * W as usize;
    let mut pieces = [0; 4];
    // Views of the second segment and of the coast after it.
    let coast = {
        let (tq, xq) = (th2.sinh() / a2, cosh_m1(th2) / a2 * n);
        from_s2(tq + 10.0 * th2.cosh(), xq + 10.0 * th2.sinh() * n)
    };
    for (emitted, at) in [origin2(0.5 * th2), coast] {
        let camera = at - DVec3::new(0.0, 12.0, 0.0);
        let time = emitted + 12.0;
        let s = scene(&text(camera, time));
        assert_eq!(s.groups.len(), 4, "four pieces");
        for backend in backends() {
            let f = render_with(&s, backend);
            let (alpha, lookback) = (f.channel("A").unwrap(), f.channel("lookback.V").unwrap());
            let mut worst = 0.0f64;
            for x in 0..W as usize {
                let u = x as f64 + 0.5 - W as f64 / 2.0;
                let d = DVec3::new(u, F, 0.0).normalize();
                let at = |l: f64| point(time - l, camera + l * d);
                let truth = first_entry(|l| in_shape(at(l).0), 0.0, 40.0, 1e-3);
                let i = row + x;
                assert_eq!(alpha[i] > 0.0, truth.is_some(), "{backend}: pixel {x}");
                let Some(lambda) = truth else { continue };
                pieces[at(lambda).1 as usize] += 1;
                worst = worst.max((lookback[i] as f64 / lambda - 1.0).abs());
            }
            report(
                "dumbbell on two accelerations across its motion: lookback",
                backend,
                0.0,
                worst,
                1e-6,
                "relative",
            );
        }
    }
    assert!(
        pieces[2] > 20 && pieces[3] > 20,
        "the second segment and the coast are both seen: {pieces:?}"
    );
}
