//! The balancer on a journal-bearing support (bearing.md section 4): the transform from
//! the fixed-frame film force to the disk's frame and its scaling, held to independent
//! references.

use ballbal_core::analysis::balanced::balanced_state;
use ballbal_core::equilibria::Verdict;
use ballbal_core::hb::{solve, HbOptions, Status};
use ballbal_core::model::bearing::{
    Bearing, Cavitation, FilmModel, GrooveSide, Grooves, JournalState,
};
use ballbal_core::model::components::{JournalSupport, SupportFilm};
use ballbal_core::model::Dynamics;
use ballbal_core::model::Jacobians;
use ballbal_core::ode::Options;
use ballbal_core::periodic::{guess_from_state, require_autonomous, GuessOptions};
use ballbal_core::simulate::simulate;
use ballbal_core::{Error, Planar, Scene};
use std::f64::consts::PI;

fn planar(zeta: f64, omega: f64) -> Planar {
    Planar::new(0.2, zeta, &[0.05], 50.0, omega, &[1.0, 1.0]).unwrap()
}

fn on(p: Planar, film: SupportFilm, rho: f64) -> Scene {
    Scene::new(p, 0.0, None, 0.0, None, None)
        .unwrap()
        .with_bearing(Some(JournalSupport { film, rho }))
        .unwrap()
}

fn grooved(side: GrooveSide, depth: f64) -> Bearing {
    Bearing {
        lambda: 0.5,
        grooves: Some(Grooves {
            count: 4,
            angle: 30f64.to_radians(),
            depth,
            width: 0.5,
            length_fraction: 1.0,
            side,
        }),
        cavitation: Cavitation::HalfSommerfeld,
        model: FilmModel::Finite {
            n_theta: 32,
            n_zeta: 8,
        },
    }
}

fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |s, x| s.max(x.abs())).max(1e-300);
    a.iter()
        .zip(b)
        .fold(0.0f64, |e, (x, y)| e.max((x - y).abs()))
        / scale
}

const Q: [f64; 4] = [0.3, -0.2, 0.7, 2.4];
const V: [f64; 4] = [0.1, 0.4, -1.2, 0.3];
const A: [f64; 4] = [0.05, -0.3, 0.2, 0.6];

#[test]
fn a_linear_film_is_the_spring_damper_support() {
    // F = -k X - c V in bearing units with k = 1 / Omega, c = 2 zeta_film is, after the
    // scaling (Omega / rho) F(rho q, rho q_ground' / Omega), the planar support
    // q + 2 zeta_film q_ground'; the scene's own zeta adds in parallel. rho drops out.
    let omega = 1.2;
    let want = planar(0.05, omega);
    let film = SupportFilm::Linear {
        stiffness: 1.0 / omega,
        damping: 2.0 * 0.03,
    };
    let got = on(planar(0.02, omega), film, 0.37);
    assert_eq!(got.time_dependence(), None);
    let (mut r1, mut r2) = ([0.0; 4], [0.0; 4]);
    want.residual(0.7, &Q, &V, &A, &mut r1);
    got.residual(0.7, &Q, &V, &A, &mut r2);
    assert!(rel_err(&r1, &r2) < 1e-13, "{r1:?} {r2:?}");
    let jac = |m: &dyn Dynamics| {
        let (mut k, mut c, mut mm) = (vec![0.0; 16], vec![0.0; 16], vec![0.0; 16]);
        m.jacobians(0.7, &Q, &V, &A, Jacobians::new(&mut k, &mut c, &mut mm));
        [k, c, mm]
    };
    for (a, b) in jac(&want).iter().zip(&jac(&got)) {
        assert!(rel_err(a, b) < 1e-13, "{a:?} {b:?}");
    }
    // the same simulation, to round-off, through a transient onto the R-R attractor
    let y0 = [0.1, 0.0, 0.3, 2.0, 0.0, 0.0, -omega, -omega];
    let t: Vec<f64> = (0..=40).map(|i| 2.5 * i as f64).collect();
    let opts = Options {
        rtol: 1e-10,
        atol: vec![1e-12],
        ..Options::default()
    };
    let (a, b) = (
        simulate(&want, &y0, 0.0, &t, &opts).unwrap(),
        simulate(&got, &y0, 0.0, &t, &opts).unwrap(),
    );
    for (ya, yb) in a.y.iter().zip(&b.y) {
        assert!(rel_err(ya, yb) < 1e-7, "{ya:?} {yb:?}");
    }
    // the same R-R orbit by harmonic balance, from one guess
    let guess = guess_from_state(&want, &y0, Some(&[true, true]), 8, &GuessOptions::default())
        .expect("a rotating attractor to start from");
    let opts = HbOptions {
        n_harm: 8,
        ..HbOptions::default()
    };
    let (sa, sb) = (solve(&want, &guess, &opts), solve(&got, &guess, &opts));
    assert_eq!(sa.status, Status::Converged);
    assert_eq!(sb.status, Status::Converged);
    assert!(
        (sa.omega - sb.omega).abs() < 1e-10 * sa.omega,
        "{} {}",
        sa.omega,
        sb.omega
    );
    // and the same perfect balance with the same eigenvalues
    let (ea, eb) = (
        balanced_state(&Scene::new(want, 0.0, None, 0.0, None, None).unwrap()).unwrap(),
        balanced_state(&got).unwrap(),
    );
    assert!(rel_err(&ea.q, &eb.q) < 1e-12);
    for (x, y) in ea.eigenvalues.iter().zip(&eb.eigenvalues) {
        assert!((x.0 - y.0).hypot(x.1 - y.1) < 1e-9, "{x:?} {y:?}");
    }
}

/// Central differences of the scene's residual against its Jacobians.
fn check_jacobians(s: &Scene, t: f64, tol: f64) {
    let d = s.ndof();
    let (mut k, mut c, mut m) = (vec![0.0; d * d], vec![0.0; d * d], vec![0.0; d * d]);
    s.jacobians(t, &Q, &V, &A, Jacobians::new(&mut k, &mut c, &mut m));
    let h = 1e-6;
    for (which, jac) in [(0, &k), (1, &c)] {
        for j in 0..d {
            let mut plus = [Q.to_vec(), V.to_vec(), A.to_vec()];
            let mut minus = plus.clone();
            plus[which][j] += h;
            minus[which][j] -= h;
            let (mut rp, mut rm) = (vec![0.0; d], vec![0.0; d]);
            s.residual(t, &plus[0], &plus[1], &plus[2], &mut rp);
            s.residual(t, &minus[0], &minus[1], &minus[2], &mut rm);
            for i in 0..d {
                let fd = (rp[i] - rm[i]) / (2.0 * h);
                assert!(
                    (fd - jac[i * d + j]).abs() < tol * (1.0 + fd.abs()),
                    "jacobian {which} [{i}][{j}]: fd {fd} analytic {}",
                    jac[i * d + j]
                );
            }
        }
    }
}

#[test]
fn jacobians_are_the_residuals_derivatives() {
    let p = || planar(0.02, 1.5);
    let short = Bearing::plain(0.5, FilmModel::Short);
    check_jacobians(&on(p(), SupportFilm::Reynolds(short), 0.4), 0.0, 1e-6);
    // from the finite solver's one-factorisation derivatives, in the disk's frame and
    // (a grooved sleeve) turned from the fixed frame at theta(t)
    for side in [GrooveSide::Journal, GrooveSide::Sleeve] {
        let s = on(p(), SupportFilm::Reynolds(grooved(side, 1.0)), 0.4);
        check_jacobians(&s, 0.37, 1e-5);
    }
}

#[test]
fn a_grooved_journal_is_autonomous_and_a_grooved_sleeve_turns_with_its_grooves() {
    let omega = 1.5;
    let journal = on(
        planar(0.0, omega),
        SupportFilm::Reynolds(grooved(GrooveSide::Journal, 1.0)),
        0.4,
    );
    assert_eq!(journal.time_dependence(), None);
    let sleeve = on(
        planar(0.0, omega),
        SupportFilm::Reynolds(grooved(GrooveSide::Sleeve, 1.0)),
        0.4,
    );
    assert_eq!(sleeve.time_dependence().as_deref(), Some("grooved_sleeve"));
    match require_autonomous(&sleeve) {
        Err(Error::NotAutonomous { effect }) => assert_eq!(effect, "grooved_sleeve"),
        other => panic!("{other:?}"),
    }
    // The support in the disk's frame at time t is the fixed-frame film at the turned
    // state, turned back: written out here with the film solver itself.
    let rho: f64 = 0.4;
    let mut solver = grooved(GrooveSide::Sleeve, 1.0).solver().unwrap();
    let (mut r, mut r0) = ([0.0; 4], [0.0; 4]);
    let t = 0.37;
    let th = omega * t;
    sleeve.residual(t, &Q, &V, &A, &mut r);
    let no_film = Scene::new(planar(0.0, omega), 0.0, None, 0.0, None, None).unwrap();
    no_film.residual(t, &Q, &V, &A, &mut r0);
    // the planar scene's support (stiffness 1, zeta = 0) is not the bearing's: remove it
    let (x, y) = (Q[0], Q[1]);
    let (gx, gy) = (V[0] - omega * y, V[1] + omega * x);
    let (sn, cs) = th.sin_cos();
    let st = JournalState {
        x: rho * (cs * x - sn * y),
        y: rho * (sn * x + cs * y),
        vx: rho / omega * (cs * gx - sn * gy),
        vy: rho / omega * (sn * gx + cs * gy),
        tau: th,
    };
    let [fx, fy] = solver.force_xy(&st).unwrap();
    let f = [
        omega / rho * (cs * fx + sn * fy),
        omega / rho * (-sn * fx + cs * fy),
    ];
    let want = [r0[0] - x - f[0], r0[1] - y - f[1]];
    assert!(rel_err(&want, &r[..2]) < 1e-12, "{want:?} {r:?}");
    assert!(rel_err(&r[2..], &r0[2..]) < 1e-13);
    // Periodic with one groove pitch (2 pi / (N_g Omega); the grid has whole cells
    // per pitch), and not constant between.
    let pitch = 2.0 * PI / (4.0 * omega);
    let mut later = [0.0; 4];
    sleeve.residual(t + pitch, &Q, &V, &A, &mut later);
    assert!(rel_err(&r, &later) < 1e-10, "{r:?} {later:?}");
    sleeve.residual(t + pitch / 3.0, &Q, &V, &A, &mut later);
    assert!(rel_err(&r, &later) > 1e-4, "{r:?} {later:?}");
    // The grooved journal: the disk-frame force equals the fixed-frame solve with the
    // journal (and its grooves) turned by theta, at angles of whole cells.
    let mut jsolver = grooved(GrooveSide::Journal, 1.0).solver().unwrap();
    let mut base = [0.0; 4];
    journal.residual(0.0, &Q, &V, &A, &mut base);
    let cell = 2.0 * PI / 32.0;
    for cells in [3.0, 11.0] {
        let th = cells * cell;
        let (sn, cs) = th.sin_cos();
        let st = JournalState {
            x: rho * (cs * x - sn * y),
            y: rho * (sn * x + cs * y),
            vx: rho / omega * (cs * gx - sn * gy),
            vy: rho / omega * (sn * gx + cs * gy),
            tau: th,
        };
        let [fx, fy] = jsolver.force_xy(&st).unwrap();
        let f = [
            omega / rho * (cs * fx + sn * fy),
            omega / rho * (-sn * fx + cs * fy),
        ];
        let mut r0 = [0.0; 4];
        no_film.residual(0.0, &Q, &V, &A, &mut r0);
        let want = [r0[0] - x - f[0], r0[1] - y - f[1]];
        assert!(rel_err(&want, &base[..2]) < 1e-9, "{want:?} {base:?}");
    }
}

#[test]
fn perfect_balance_on_a_plain_bearing_is_unstable_and_centred() {
    // A plain film at the centre has cross-coupled stiffness only: the centred rotor is
    // unstable at every speed (bearing.md section 2), balls or not.
    for omega in [0.3, 1.0, 3.0, 10.0] {
        let s = on(
            planar(0.0, omega),
            SupportFilm::Reynolds(Bearing::plain(0.5, FilmModel::Short)),
            0.3,
        );
        let e = balanced_state(&s).expect("the perfect balance exists for eta = 1");
        assert!(e.q[0].abs() < 1e-12 && e.q[1].abs() < 1e-12, "{:?}", e.q);
        assert!(e.residual < 1e-12);
        assert_eq!(
            e.verdict,
            Verdict::Unstable,
            "Omega {omega}: {:?}",
            e.eigenvalues
        );
    }
}

#[test]
fn bad_bearing_input_names_the_parameter() {
    let name = |e: Error| match e {
        Error::InvalidParameter { name, .. } => name,
        other => panic!("{other:?}"),
    };
    let base = || Scene::new(planar(0.0, 1.0), 0.0, None, 0.0, None, None).unwrap();
    let short = || SupportFilm::Reynolds(Bearing::plain(0.5, FilmModel::Short));
    let e = base()
        .with_bearing(Some(JournalSupport {
            film: short(),
            rho: 0.0,
        }))
        .unwrap_err();
    assert_eq!(name(e), "rho");
    let e = Scene::new(planar(0.0, 0.0), 0.0, None, 0.0, None, None)
        .unwrap()
        .with_bearing(Some(JournalSupport {
            film: short(),
            rho: 0.3,
        }))
        .unwrap_err();
    assert_eq!(name(e), "Omega");
    let s = on(planar(0.0, 1.0), short(), 0.3);
    assert_eq!(
        name(s.with_param("depth_ratio", 0.5).unwrap_err()),
        "depth_ratio"
    );
    assert_eq!(name(base().with_param("rho", 0.5).unwrap_err()), "rho");
    assert_eq!(name(s.with_param("rho", -1.0).unwrap_err()), "rho");
    let g = on(
        planar(0.0, 1.0),
        SupportFilm::Reynolds(grooved(GrooveSide::Journal, 1.0)),
        0.3,
    );
    assert_eq!(
        name(g.with_param("groove_angle", 95.0).unwrap_err()),
        "grooves.angle"
    );
    assert_eq!(
        name(g.with_param("depth_ratio", -0.1).unwrap_err()),
        "grooves.depth_ratio"
    );
    let g2 = g.with_param("groove_angle", 45.0).unwrap();
    assert!(
        (g2.get(ballbal_core::model::ParamId::GrooveAngle.into())
            .unwrap()
            - 45.0)
            .abs()
            < 1e-12
    );
    assert!(g2 != g);
}
