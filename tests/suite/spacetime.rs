//! Spacetime math against docs/physics.md §1, §5.1 and §8, plus property tests.

use crate::common::*;
use glam::DVec3;
use rest_embree::spacetime::{wigner_rotation, Boost, Event, Velocity};

fn vx(beta: f64) -> Velocity {
    Velocity::from_beta(DVec3::X, beta).unwrap()
}

fn random_velocity(r: &mut Rng) -> Velocity {
    Velocity::from_rapidity(r.unit(), r.range(0.0, 6.0)).unwrap()
}

#[test]
fn boost_then_inverse_is_identity_and_interval_is_preserved() {
    let mut r = Rng(1);
    for _ in 0..5000 {
        let v = random_velocity(&mut r);
        let b = Boost::to_rest(&v);
        let e = Event::new(
            r.range(-10.0, 10.0),
            DVec3::new(
                r.range(-10.0, 10.0),
                r.range(-10.0, 10.0),
                r.range(-10.0, 10.0),
            ),
        );
        let e2 = b.inverse().event(b.event(e));
        let scale = v.gamma().powi(2) * 40.0;
        assert!(
            (e2.t - e.t).abs() < 1e-14 * scale && (e2.x - e.x).length() < 1e-14 * scale,
            "{e:?} -> {e2:?} for {v:?}"
        );
        let e1 = b.event(e);
        let mag = (e1.t.abs() + e1.x.length()).powi(2);
        assert!(
            (e1.interval() - e.interval()).abs() <= 1e-14 * mag.max(1.0),
            "interval not preserved"
        );
    }
}

/// `Boost::null_dir` as it was written before it became one branch-free form for one lane or
/// four (`1 ± a∥` by two branches): the reference for `null_dir_is_the_branching_form_to_the_bit`.
fn null_dir_branching(v: &Velocity, a: DVec3) -> (DVec3, f64) {
    let (axis, phi) = (v.direction(), v.rapidity());
    let (e_pos, e_neg) = (phi.exp(), (-phi).exp());
    let ap = a.dot(axis);
    let perp = a - ap * axis;
    let p2 = perp.length_squared();
    let one_plus = if ap >= 0.0 { 1.0 + ap } else { p2 / (1.0 - ap) };
    let one_minus = if ap <= 0.0 { 1.0 - ap } else { p2 / (1.0 + ap) };
    let up = e_pos * one_plus;
    let wp = e_neg * one_minus;
    (perp + 0.5 * (up - wp) * axis, 0.5 * (up + wp))
}

#[test]
fn null_dir_is_the_branching_form_to_the_bit() {
    let mut r = Rng(11);
    // Bit for bit, but for the sign of a zero (motion along a coordinate axis skips the
    // products with the axis' zeros, whose signs the branching form carries).
    let bits =
        |(d, s): (DVec3, f64)| [d.x, d.y, d.z, s].map(|x| if x == 0.0 { 0 } else { x.to_bits() });
    let unit_axes = [
        DVec3::X,
        DVec3::Y,
        DVec3::Z,
        -DVec3::X,
        -DVec3::Y,
        -DVec3::Z,
    ];
    for k in 0..20_000 {
        let v = match k % 4 {
            0 => Velocity::from_one_minus_beta(r.unit(), 10f64.powf(r.range(-13.0, -1.0))).unwrap(),
            // Along x, y or z, either way (the aligned path), near c or not.
            1 => {
                let axis = unit_axes[(k / 4) % 6];
                match k % 8 {
                    1 => Velocity::from_one_minus_beta(axis, 10f64.powf(r.range(-13.0, -1.0))),
                    _ => Velocity::from_rapidity(axis, r.range(1e-9, 8.0)),
                }
                .unwrap()
            }
            _ => Velocity::from_rapidity(r.unit(), r.range(1e-9, 8.0)).unwrap(),
        };
        let axis = v.direction();
        let side = axis.any_orthonormal_vector();
        // Random directions, along the axis either way, across it (a∥ = ±0), and within a
        // hair of the axis, where 1 ± a∥ cancels.
        let tilt = 10f64.powf(r.range(-9.0, -1.0));
        for a in [
            r.unit(),
            axis,
            -axis,
            side,
            -side,
            (axis + tilt * side).normalize(),
            (-axis + tilt * side).normalize(),
        ] {
            let got = Boost::to_rest(&v).null_dir(a);
            assert_eq!(
                bits(got),
                bits(null_dir_branching(&v, a)),
                "v {v:?}, a {a:?}"
            );
        }
    }
}

#[test]
fn null_stays_null_and_view_dir_is_unit() {
    let mut r = Rng(2);
    for _ in 0..5000 {
        let v = random_velocity(&mut r);
        let a = r.unit();
        let (d, s) = Boost::to_rest(&v).null_dir(a);
        assert!(s > 0.0);
        assert_rel(d.length(), s, 1e-13, "|d'| = s (null)");
        // Same as the plain 4-vector boost: s = γ(1 + β·a).
        let expect = v.gamma() * (1.0 + v.beta_vec().dot(a));
        assert!(
            (s - expect).abs() <= 1e-12 * v.gamma() * 2.0,
            "s {s} vs {expect}"
        );
    }
}

#[test]
fn aberration_table_1_1() {
    let table = [
        (
            0.1,
            [
                0.0, 27.248028, 55.150095, 84.260830, 114.901062, 146.998369, 178.894465, 180.0,
            ],
        ),
        (
            0.5,
            [
                0.0, 17.587954, 36.869898, 60.000000, 90.000000, 130.207819, 178.268037, 180.0,
            ],
        ),
        (
            0.9,
            [
                0.0, 7.035292, 15.090185, 25.841933, 43.341758, 81.139693, 175.643091, 180.0,
            ],
        ),
        (
            0.99,
            [
                0.0, 2.176338, 4.687304, 8.109614, 13.999691, 29.637130, 165.963531, 180.0,
            ],
        ),
    ];
    let thetas: [f64; 8] = [0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 179.0, 180.0];
    for (beta, expect) in table {
        let b = Boost::to_rest(&vx(beta));
        for (th, want) in thetas.iter().zip(expect) {
            let t = th.to_radians();
            let (a, _) = b.view_dir(DVec3::new(t.cos(), t.sin(), 0.0));
            let got = a.y.atan2(a.x).to_degrees();
            assert_close(got, want, 2e-6, &format!("beta {beta} theta {th}"));
        }
    }
    // Inverse direction θ' → θ (the boost back out of the moving frame).
    let inverse = [
        (0.5, [0.0, 71.31426, 120.0, 153.101049, 180.0]),
        (0.9, [0.0, 122.039495, 154.158067, 169.143296, 180.0]),
        (0.99, [0.0, 160.577073, 171.890386, 176.636235, 180.0]),
    ];
    for (beta, expect) in inverse {
        let b = Boost::from_rest(&vx(beta));
        for (th, want) in [0.0f64, 45.0, 90.0, 135.0, 180.0].iter().zip(expect) {
            let t = th.to_radians();
            let (a, _) = b.view_dir(DVec3::new(t.cos(), t.sin(), 0.0));
            assert_close(
                a.y.atan2(a.x).to_degrees(),
                want,
                2e-5,
                &format!("inverse beta {beta} theta' {th}"),
            );
        }
    }
}

#[test]
fn vector_forms_1_2() {
    let cases = [
        (
            DVec3::new(0.6, 0.0, 0.0),
            DVec3::Y,
            DVec3::new(0.6, 0.8, 0.0),
            0.8,
        ),
        (
            DVec3::new(0.3, 0.4, 0.0),
            DVec3::Z,
            DVec3::new(0.3, 0.4, 0.866025403784),
            0.866025403784,
        ),
        (
            DVec3::new(0.0, 0.0, -0.9),
            DVec3::ONE / 3f64.sqrt(),
            DVec3::new(0.52387413171, 0.52387413171, -0.671648560074),
            0.907376612893,
        ),
    ];
    for (beta, s, s_obj, d) in cases {
        let v = Velocity::from_beta_vec(beta).unwrap();
        let (a, k) = Boost::to_rest(&v).view_dir(s);
        assert!((a - s_obj).length() < 1e-11, "{a} vs {s_obj}");
        // D = ν_cam/ν_obj = 1/(γ(1 + β·ŝ)) = 1/s.
        assert_close(1.0 / k, d, 1e-11, "Doppler factor");
    }
}

#[test]
fn boost_matrix_1_3() {
    let beta = DVec3::new(0.3, -0.4, 0.5);
    let v = Velocity::from_beta_vec(beta).unwrap();
    let e = Boost::to_rest(&v).event(Event::new(2.0, 2.0 * beta));
    // 2/γ = 1.41421356 for this β (docs/physics.md §1.3).
    assert_close(e.t, std::f64::consts::SQRT_2, 1e-10, "t'");
    assert!(e.x.length() < 1e-14, "worldline maps to x' = 0");
    // Λ(β)^-1 = Λ(−β).
    let w = Event::new(0.7, DVec3::new(-1.0, 2.0, 0.3));
    let a = Boost::to_rest(&v).inverse().event(w);
    let b = Boost::to_rest(&Velocity::from_beta_vec(-beta).unwrap()).event(w);
    assert!((a.t - b.t).abs() < 1e-14 && (a.x - b.x).length() < 1e-14);
}

/// Apply boosts in turn to the four basis 4-vectors: the columns of the composed matrix.
fn compose(boosts: &[Boost], e: Event) -> Event {
    boosts.iter().fold(e, |e, b| b.event(e))
}

#[test]
fn wigner_rotation_1_4() {
    let table = [
        (
            DVec3::new(0.6, 0.0, 0.0),
            DVec3::new(0.0, 0.8, 0.0),
            DVec3::new(0.6, 0.64, 0.0),
            18.9246444161,
        ),
        (
            DVec3::new(0.9, 0.0, 0.0),
            DVec3::new(0.0, 0.9, 0.0),
            DVec3::new(0.9, 0.392300904919, 0.0),
            42.8961988683,
        ),
        (
            DVec3::new(0.99, 0.0, 0.0),
            DVec3::new(0.0, 0.99, 0.0),
            DVec3::new(0.99, 0.139656686199, 0.0),
            73.9408376112,
        ),
        (
            DVec3::new(0.5, 0.0, 0.0),
            DVec3::new(0.3, 0.4, 0.0),
            DVec3::new(0.695652173913, 0.301226227403, 0.0),
            6.3036534614,
        ),
        (
            DVec3::new(0.3, 0.2, 0.1),
            DVec3::new(-0.2, 0.5, 0.4),
            DVec3::new(0.117573967086, 0.622205951559, 0.439903232661),
            7.9199589527,
        ),
    ];
    for (b1, b2, w_expect, omega) in table {
        let l1 = Boost::to_rest(&Velocity::from_beta_vec(b1).unwrap());
        let l2 = Boost::to_rest(&Velocity::from_beta_vec(b2).unwrap());
        // The S2 origin at S2-time 1, written in S0: (γ_w, γ_w w).
        let o = compose(&[l2.inverse(), l1.inverse()], Event::new(1.0, DVec3::ZERO));
        let w = o.x / o.t;
        assert!(
            (w - w_expect).length() < 1e-11,
            "w = {w}, expected {w_expect}"
        );
        // R = Λ(β2) Λ(β1) Λ(w)^-1 is a pure rotation by ω about β1 × β2.
        let lw = Boost::to_rest(&Velocity::from_beta_vec(w).unwrap());
        let axis = b1.cross(b2).normalize();
        let u = axis.any_orthonormal_vector();
        let ru = compose(&[lw.inverse(), l1, l2], Event::new(0.0, u));
        assert!(ru.t.abs() < 1e-12, "rotation keeps time: {}", ru.t);
        let angle = u.cross(ru.x).dot(axis).atan2(u.dot(ru.x)).to_degrees();
        assert_close(angle, omega, 1e-8, "Wigner angle");
        // The closed form the renderer turns a body's axes by, against the composed boosts.
        let (v1, v2) = (
            Velocity::from_beta_vec(b1).unwrap(),
            Velocity::from_beta_vec(b2).unwrap(),
        );
        let r = wigner_rotation(&v1, &v2);
        assert!(
            (r * u - ru.x).length() < 1e-12,
            "{} against {}",
            r * u,
            ru.x
        );
        let turned = lw.turned(r);
        for e in [
            Event::new(0.7, DVec3::new(-1.0, 2.0, 0.3)),
            Event::new(-3.0, DVec3::new(0.2, 0.0, 5.0)),
        ] {
            let (x, y) = (compose(&[l1, l2], e), turned.event(e));
            let tol = 1e-12 * x.t.abs().max(1.0);
            assert!(
                (x.t - y.t).abs() < tol && (x.x - y.x).length() < tol,
                "{x:?} {y:?}"
            );
            // And its inverse undoes it.
            let back = turned.inverse().event(y);
            assert!((back.t - e.t).abs() < tol && (back.x - e.x).length() < tol);
        }
        let dir = DVec3::new(0.6, -0.48, 0.64);
        let (d1, s1) = l2.null_dir(l1.view_dir(dir).0);
        let (d2, s2) = turned.null_dir(dir);
        let s0 = l1.null_dir(dir).1;
        let tol = 1e-12 * s2;
        assert!(
            (d1 * s0 - d2).length() < tol && (s1 * s0 - s2).abs() < tol,
            "{d1} {s0} {d2}, {s1} {s2}"
        );
    }
    // Near the speed of light across each other the turn nears a right angle, the closed form
    // keeping its digits where the composed matrices lose them.
    let fast = |d: DVec3| Velocity::from_rapidity(d, 30.0).unwrap();
    let r = wigner_rotation(&fast(DVec3::X), &fast(DVec3::Y));
    let x = r * DVec3::X;
    assert!((x - DVec3::Y).length() < 1e-12, "{x}");
}

#[test]
fn doppler_table_5_1() {
    let table = [
        (
            0.1,
            [
                1.10554, 1.08933, 1.04736, 0.99499, 0.94761, 0.91569, 0.90453,
            ],
        ),
        (
            0.5,
            [
                1.73205, 1.52742, 1.15470, 0.86603, 0.69282, 0.60434, 0.57735,
            ],
        ),
        (
            0.9,
            [
                4.35890, 1.97613, 0.79253, 0.43589, 0.30061, 0.24496, 0.22942,
            ],
        ),
        (
            0.99,
            [
                14.10674, 0.98901, 0.27934, 0.14107, 0.09436, 0.07595, 0.07089,
            ],
        ),
    ];
    for (beta, ds) in table {
        for (k, want) in ds.iter().enumerate() {
            let tk = (30.0 * k as f64).to_radians();
            // Photon direction k̂ at θ_k from the velocity; the camera looks along −k̂.
            let a = -DVec3::new(tk.cos(), tk.sin(), 0.0);
            let (_, s) = Boost::to_rest(&vx(beta)).null_dir(a);
            // The table is rounded to 5 decimals.
            assert_close(
                1.0 / s,
                *want,
                6e-6,
                &format!("D at beta {beta}, theta_k {}", 30 * k),
            );
        }
    }
}

#[test]
fn speed_forms_agree_and_stay_exact_near_light_8() {
    // γ for ε = 1 − β = 1e-12 is 707106.781186724 (docs/physics.md §8.1).
    let v = Velocity::from_one_minus_beta(DVec3::X, 1e-12).unwrap();
    assert_rel(
        v.gamma(),
        707106.781186724,
        1e-13,
        "gamma from one_minus_beta",
    );
    assert_rel(v.one_minus_beta(), 1e-12, 1e-12, "1 - beta round trip");
    let r = Velocity::from_rapidity(DVec3::X, v.rapidity()).unwrap();
    assert_eq!(r, v);
    let b = Velocity::from_beta(DVec3::X, 0.6).unwrap();
    assert_rel(b.gamma(), 1.25, 1e-15, "gamma(0.6)");
    assert_rel(
        Velocity::from_one_minus_beta(DVec3::X, 0.4)
            .unwrap()
            .gamma(),
        1.25,
        1e-15,
        "gamma via eps",
    );
    // Head-on Doppler e^φ and boosting a near-light-like event (t = x = 1000).
    let e = Boost::to_rest(&v).event(Event::new(1000.0, DVec3::new(1000.0, 0.0, 0.0)));
    assert_rel(
        e.t,
        7.071067811867e-4,
        1e-11,
        "t' of a near-light-like event",
    );
    let (_, s) = Boost::to_rest(&v).null_dir(-DVec3::X);
    assert_rel(1.0 / s, (v.rapidity()).exp(), 1e-14, "head-on Doppler");
    // Aberration near 180°: true angle 168.578813725° (naive formula gives 168.583223°). The
    // view angle the physics notes round to "π − 1.414e-7" is π − √2·1e-7 (checked with mpmath: with
    // 1.414e-7 exactly the true answer is 168.5805270°).
    let th = std::f64::consts::PI - 2f64.sqrt() * 1e-7;
    let (a, _) = Boost::to_rest(&v).view_dir(DVec3::new(th.cos(), th.sin(), 0.0));
    assert_close(
        a.y.atan2(a.x).to_degrees(),
        168.578813725,
        1e-6,
        "aberration near 180",
    );
    // Speeds of 1 and beyond are refused, not rounded.
    assert!(Velocity::from_beta(DVec3::X, 1.0).is_err());
    assert!(Velocity::from_beta_vec(DVec3::new(0.8, 0.7, 0.0)).is_err());
    assert!(Velocity::from_one_minus_beta(DVec3::X, 0.0).is_err());
}

#[test]
fn retarded_position_2_1_both_branches() {
    use rest_embree::spacetime::{retarded_delay, retarded_position};
    let mut r = Rng(9);
    for _ in 0..3000 {
        let v = Velocity::from_rapidity(r.unit(), r.range(0.0, 4.0)).unwrap();
        let r0 = r.unit() * r.range(0.1, 100.0);
        let d = retarded_delay(r0, &v);
        // Bisection on |r0 − βΔ| = Δ (the definition), independent of the closed form.
        let (mut lo, mut hi) = (0.0f64, 1e3 * v.gamma().powi(2) * r0.length());
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if (r0 - v.beta_vec() * mid).length() > mid {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        assert_rel(d, 0.5 * (lo + hi), 1e-12, "retarded delay vs bisection");
        let app = retarded_position(r0, &v);
        assert_rel(app.length(), d, 1e-12, "the apparent point is Δ away");
    }
    // Both branches at a speed near 1: approaching (β·r0 < 0) and receding (β·r0 > 0).
    let v = Velocity::from_one_minus_beta(DVec3::X, 1e-12).unwrap();
    let g2 = v.gamma().powi(2);
    // At −x and moving +x the point approaches: its light left long ago, Δ = d/(1−β) ≈ 2γ².
    let approaching = retarded_delay(DVec3::new(-1.0, 0.0, 0.0), &v);
    assert_rel(
        approaching,
        1.0 / v.one_minus_beta(),
        1e-12,
        "approaching: Δ = d/(1−β)",
    );
    assert!(approaching > g2, "approaching delay ~ 2γ² = {}", 2.0 * g2);
    // At +x it recedes: Δ = d/(1+β) ≈ 1/2.
    let receding = retarded_delay(DVec3::new(1.0, 0.0, 0.0), &v);
    assert_rel(
        receding,
        1.0 / (1.0 + v.beta()),
        1e-15,
        "receding: Δ = d/(1+β)",
    );
    // Abeam (r0 ⟂ v): |r0 − βΔ| = Δ gives 1 + β²Δ² = Δ², Δ = γ |r0| — where r0² − |β × r0|²
    // would be 1 − β², lost to cancellation (docs/physics.md §8).
    for one_minus in [1e-6, 1e-9, 1e-12] {
        let v = Velocity::from_one_minus_beta(DVec3::X, one_minus).unwrap();
        let abeam = retarded_delay(DVec3::new(0.0, 3.0, -4.0), &v);
        assert_rel(abeam, 5.0 * v.gamma(), 1e-12, "abeam: Δ = γ|r0|");
    }
    // The rest-frame form x_app = γ(X − β sqrt(X² + ρ²)) agrees (docs/physics.md §2.1).
    let v = Velocity::from_beta(DVec3::X, 0.9).unwrap();
    for (x0, rho) in [(5.0, 10.0), (-5.0, 10.0), (0.0, 3.0), (40.0, 1.0)] {
        let app = retarded_position(DVec3::new(x0, rho, 0.0), &v);
        let big_x = v.gamma() * x0;
        let want = v.gamma() * (big_x - v.beta() * (big_x * big_x + rho * rho).sqrt());
        assert_close(app.x, want, 1e-12 * want.abs().max(1.0), "rest-frame form");
        assert_eq!(app.y, rho, "the perpendicular offset is unchanged");
    }
}

#[test]
fn gamma_minus_one_at_small_speeds_8_1() {
    // docs/physics.md §8.1: naive γ − 1 gives 2.2e-16 at β = 1e-8 (truth 5e-17) and 0 at 1e-9.
    for beta in [1e-8f64, 1e-9, 1e-4] {
        let v = Velocity::from_beta(DVec3::X, beta).unwrap();
        let want = 0.5 * beta * beta * (1.0 + 0.75 * beta * beta);
        assert_rel(
            v.gamma_minus_one(),
            want,
            1e-12,
            &format!("γ − 1 at β = {beta}"),
        );
    }
    assert_eq!(Velocity::ZERO.gamma_minus_one(), 0.0);
}

#[test]
fn identity_keys_tell_frames_apart() {
    let a = Velocity::from_beta(DVec3::X, 0.5).unwrap();
    let b = Velocity::from_beta(DVec3::new(2.0, 0.0, 0.0), 0.5).unwrap();
    let c = Velocity::from_beta(DVec3::X, 0.5000000001).unwrap();
    assert_eq!(
        a.identity_key(),
        b.identity_key(),
        "same velocity, other spelling"
    );
    assert_ne!(
        a.identity_key(),
        c.identity_key(),
        "a different speed is another frame"
    );
    assert_ne!(a.identity_key(), a.reversed().identity_key());
    // Every way of saying "at rest" is one frame.
    let z1 = Velocity::from_beta_vec(DVec3::ZERO).unwrap();
    let z2 = Velocity::from_rapidity(DVec3::Y, 0.0).unwrap();
    assert_eq!(z1.identity_key(), z2.identity_key());
    assert_eq!(z1.identity_key(), Velocity::ZERO.identity_key());
}
