//! The model seam is open: a support the core does not have, added here through the
//! crate's public API only (one new struct implementing `Component`, no change to the
//! solvers), then assembled with the core's planar disk and free balls and handed to
//! the equilibrium search, the eigenvalue analysis and harmonic balance unchanged.
//!
//! The support: a linear shaft turning with the disk whose stiffness and damping differ
//! between the two body axes (a shaft with a flat, say): force
//! `(k_x x + c_x x', k_y y + c_y y')` in the rotating frame, nondimensional as in
//! `model.md`. It is written as a residual only, so its Jacobians are the component
//! default's finite differences (as a Reynolds-film bearing's would be).

use ballbal_core::equilibria::{analyse_model, equilibria_of, EquilibriumKind};
use ballbal_core::hb::{solve, HbOptions, Status};
use ballbal_core::model::components::{FreeBalls, IsotropicSupport, PlanarDisk};
use ballbal_core::model::{Component, Composed, Ctx, Drive, Dynamics, Layout};
use ballbal_core::ode::Options;
use ballbal_core::periodic::{guess_from_state, GuessOptions};
use ballbal_core::simulate::simulate;
use std::f64::consts::PI;
use std::sync::Arc;

#[derive(Debug)]
struct AnisotropicShaft {
    kx: f64,
    ky: f64,
    cx: f64,
    cy: f64,
}

impl Component for AnisotropicShaft {
    fn name(&self) -> &'static str {
        "support"
    }
    fn has_inertia(&self) -> bool {
        false
    }
    fn add_residual(&self, cx: &Ctx, q: &[f64], v: &[f64], _a: &[f64], out: &mut [f64]) {
        let (x, y) = (cx.layout.x, cx.layout.y);
        out[x] += self.kx * q[x] + self.cx * v[x];
        out[y] += self.ky * q[y] + self.cy * v[y];
    }
}

const MU: f64 = 0.1;
const DELTA: f64 = 50.0;

/// Planar disk (unbalance `MU`) on the shaft, with free balls of capacities `eta`.
fn model(shaft: AnisotropicShaft, omega: f64, eta: &[f64], zeta_b: f64) -> Composed {
    let n = eta.len();
    Composed::new(
        Layout::planar(n),
        Drive::Constant(omega),
        eta.iter().map(|e| MU * e).collect(),
        vec![
            Arc::new(PlanarDisk { mu: MU }),
            Arc::new(shaft),
            Arc::new(FreeBalls {
                zeta_b: vec![zeta_b; n],
                delta: DELTA,
            }),
        ],
    )
}

fn wrap(a: f64) -> f64 {
    let r = a.rem_euclid(2.0 * PI);
    if r > PI {
        r - 2.0 * PI
    } else {
        r
    }
}

#[test]
fn equilibria_of_one_ball_are_the_closed_form() {
    // At rest in the rotating frame (v = a = 0) the damping drops out. With W = Omega^2,
    // a = k_x - W, b = k_y - W and the ball's unbalance m = mu eta at angle beta:
    //   x row:    a x - mu W - m W cos(beta) = 0  ->  x = W (mu + m cos beta) / a
    //   y row:    b y - m W sin(beta) = 0         ->  y = W m sin(beta) / b
    //   ball row: W (x sin beta - y cos beta) = 0 (the support displaced along the ball)
    // so either sin(beta) = 0 (beta = 0 or pi, y = 0), or (mu + m cos beta) / a =
    // m cos(beta) / b, i.e. cos(beta) = mu b / (m (a - b)): a pair +-beta that exists
    // only because k_x != k_y (an isotropic shaft has no equilibrium off the axis).
    let (kx, ky, omega, eta) = (1.0, 1.8, 1.2, 1.2);
    let m = model(
        AnisotropicShaft {
            kx,
            ky,
            cx: 0.04,
            cy: 0.1,
        },
        omega,
        &[eta],
        0.05,
    );
    let w = omega * omega;
    let (a, b, mb) = (kx - w, ky - w, MU * eta);
    let mut want: Vec<[f64; 3]> = vec![[w * (MU + mb) / a, 0.0, 0.0], [w * (MU - mb) / a, 0.0, PI]];
    let cb = MU * b / (mb * (a - b));
    assert!(
        cb.abs() < 1.0,
        "the off-axis pair must exist here: cos {cb}"
    );
    for beta in [cb.acos(), -cb.acos()] {
        want.push([w * (MU + mb * cb) / a, w * mb * beta.sin() / b, beta]);
    }
    let found = equilibria_of(&m, true, false);
    assert_eq!(found.len(), want.len(), "{found:?}");
    for e in &want {
        let hit = found.iter().find(|f| {
            (f.q[0] - e[0]).abs() < 1e-9
                && (f.q[1] - e[1]).abs() < 1e-9
                && wrap(f.q[2] - e[2]).abs() < 1e-9
        });
        assert!(hit.is_some(), "closed form {e:?} not among {found:?}");
        assert!(hit.unwrap().residual < 1e-12);
    }
}

#[test]
fn free_vibration_of_the_anisotropic_rotor_is_the_closed_form() {
    // No balls: the rotor alone, linear in the rotating frame,
    //   x'' - 2 Omega y' + (k_x - W) x + c_x x' = mu W
    //   y'' + 2 Omega x' + (k_y - W) y + c_y y' = 0,
    // static deflection x = mu W / a, y = 0; free vibration e^(s t) with
    //   (s^2 + c_x s + a)(s^2 + c_y s + b) + 4 W s^2 = 0.
    // Undamped (c = 0), s = i lam: lam^4 - (a + b + 4 W) lam^2 + a b = 0, so
    //   lam^2 = [(a + b + 4 W) +- sqrt((a + b + 4 W)^2 - 4 a b)] / 2,
    // real (a whirl at two rotating-frame frequencies) when a b > 0, and one positive
    // real s when a b < 0: the classic instability of an anisotropic shaft between
    // its two critical speeds sqrt(k_x) < Omega < sqrt(k_y).
    let (kx, ky) = (1.0, 1.8);
    for omega in [0.6, 1.2, 1.7] {
        let m = model(
            AnisotropicShaft {
                kx,
                ky,
                cx: 0.0,
                cy: 0.0,
            },
            omega,
            &[],
            0.0,
        );
        let w = omega * omega;
        let (a, b) = (kx - w, ky - w);
        let q = [MU * w / a, 0.0];
        let eq = analyse_model(&m, &q, EquilibriumKind::Unbalanced, false);
        assert!(eq.residual < 1e-14, "{}", eq.residual);
        let p = a + b + 4.0 * w;
        let disc = (p * p - 4.0 * a * b).sqrt();
        let (l1, l2) = ((p + disc) / 2.0, (p - disc) / 2.0);
        // the four roots s of the quartic, as (re, im)
        let mut want: Vec<(f64, f64)> = vec![];
        for l in [l1, l2] {
            if l >= 0.0 {
                want.extend([(0.0, l.sqrt()), (0.0, -l.sqrt())]);
            } else {
                want.extend([((-l).sqrt(), 0.0), (-(-l).sqrt(), 0.0)]);
            }
        }
        assert_eq!(eq.eigenvalues.len(), 4);
        for s in &want {
            let near = eq
                .eigenvalues
                .iter()
                .map(|e| (e.0 - s.0).hypot(e.1 - s.1))
                .fold(f64::INFINITY, f64::min);
            assert!(near < 1e-7, "Omega {omega}: {s:?} vs {:?}", eq.eigenvalues);
        }
        let unstable = a * b < 0.0;
        assert_eq!(eq.eigenvalues[0].0 > 1e-6, unstable, "Omega {omega}");
    }
}

#[test]
fn damped_eigenvalues_solve_the_characteristic_quartic() {
    // With damping every eigenvalue s must be a root of
    //   P(s) = (s^2 + c_x s + a)(s^2 + c_y s + b) + 4 W s^2
    // (the 2 x 2 determinant above); its four roots are the state matrix's four.
    let (kx, ky, cx, cy, omega) = (1.0, 1.8, 0.07, 0.2, 0.9);
    let m = model(AnisotropicShaft { kx, ky, cx, cy }, omega, &[], 0.0);
    let w = omega * omega;
    let (a, b) = (kx - w, ky - w);
    let eq = analyse_model(&m, &[MU * w / a, 0.0], EquilibriumKind::Unbalanced, false);
    assert_eq!(eq.eigenvalues.len(), 4);
    // complex arithmetic on (re, im) pairs
    let mul = |p: (f64, f64), q: (f64, f64)| (p.0 * q.0 - p.1 * q.1, p.0 * q.1 + p.1 * q.0);
    let add = |p: (f64, f64), q: (f64, f64)| (p.0 + q.0, p.1 + q.1);
    let scale = |k: f64, p: (f64, f64)| (k * p.0, k * p.1);
    for &s in &eq.eigenvalues {
        let s2 = mul(s, s);
        let f1 = add(add(s2, scale(cx, s)), (a, 0.0));
        let f2 = add(add(s2, scale(cy, s)), (b, 0.0));
        let p = add(mul(f1, f2), scale(4.0 * w, s2));
        let size = 1.0 + s.0.hypot(s.1).powi(4);
        assert!(p.0.hypot(p.1) < 1e-9 * size, "P({s:?}) = {p:?}");
    }
    // the sum of the roots is minus the s^3 coefficient, -(c_x + c_y)
    let sum: f64 = eq.eigenvalues.iter().map(|e| e.0).sum();
    assert!((sum + cx + cy).abs() < 1e-9, "{sum}");
}

#[test]
fn harmonic_balance_runs_unchanged_and_its_orbit_closes_under_simulation() {
    // Tien (2011) balancer (mu 0.2, zeta 0.05, zeta_b 0.05, delta 50, two balls of
    // eta 1) near its R-R branch at Omega = 1.19, on the isotropic support plus the new
    // shaft adding stiffness 0.1 along y only: four components. The generic guess from
    // a simulated attractor and the Newton solve run with nothing told about the new
    // support; the orbit is then checked by a second method, a time integration over
    // one period.
    let (mu, omega, eta) = (0.2, 1.19, [1.0, 1.0]);
    let m = Composed::new(
        Layout::planar(2),
        Drive::Constant(omega),
        eta.iter().map(|e| mu * e).collect(),
        vec![
            Arc::new(PlanarDisk { mu }),
            Arc::new(IsotropicSupport { zeta: 0.05 }),
            Arc::new(AnisotropicShaft {
                kx: 0.0,
                ky: 0.1,
                cx: 0.0,
                cy: 0.0,
            }),
            Arc::new(FreeBalls {
                zeta_b: vec![0.05; 2],
                delta: DELTA,
            }),
        ],
    );
    assert_eq!(m.time_dependence(), None);
    let y0 = [0.1, 0.0, 0.3, 2.0, 0.0, 0.0, -omega, -omega];
    let guess = guess_from_state(&m, &y0, Some(&[true, true]), 8, &GuessOptions::default())
        .expect("a rotating attractor to start from");
    // 24 harmonics: the truncation error of the series is below the closure tolerance
    let opts = HbOptions {
        n_harm: 24,
        ..HbOptions::default()
    };
    let sol = solve(&m, &guess.resized(24), &opts);
    assert_eq!(sol.status, Status::Converged, "{sol:?}");
    let period = sol.period();
    let start = sol.state(0.0);
    let traj = simulate(&m, &start, 0.0, &[period], &Options::new(1e-11, 1e-13)).unwrap();
    let end = &traj.y[0];
    let d = m.ndof();
    for j in 0..2 * d {
        // the balls come back whole turns behind (winding -1)
        let turn = if j < d {
            sol.winding[j] * 2.0 * PI
        } else {
            0.0
        };
        let err = (end[j] - start[j] - turn).abs();
        assert!(err < 1e-8, "coordinate {j}: closes to {err:e}");
    }
    // the new support is in what was solved: without it the same guess converges to
    // another orbit (the integration above checks the orbit against the model with it)
    let iso = Composed::new(
        Layout::planar(2),
        Drive::Constant(omega),
        eta.iter().map(|e| mu * e).collect(),
        vec![
            Arc::new(PlanarDisk { mu }),
            Arc::new(IsotropicSupport { zeta: 0.05 }),
            Arc::new(FreeBalls {
                zeta_b: vec![0.05; 2],
                delta: DELTA,
            }),
        ],
    );
    let plain = solve(&iso, &guess.resized(24), &opts);
    assert_eq!(plain.status, Status::Converged);
    assert!(
        (plain.omega - sol.omega).abs() > 1e-4 * sol.omega,
        "{} {}",
        plain.omega,
        sol.omega
    );
}
