//! Each test checks against something computed independently: closed forms written here,
//! quadrature written here, or a second formulation of the same problem.

use super::finite::Problem;
use super::*;
use nalgebra::Matrix2;
use std::f64::consts::PI;

pub(super) fn solver(b: &Bearing) -> FilmSolver {
    b.solver().expect("valid bearing")
}

pub(super) fn finite(lambda: f64, nt: usize, nz: usize, cav: Cavitation) -> FilmSolver {
    let mut b = Bearing::plain(
        lambda,
        FilmModel::Finite {
            n_theta: nt,
            n_zeta: nz,
        },
    );
    b.cavitation = cav;
    solver(&b)
}

pub(super) fn herringbone(depth: f64, side: GrooveSide) -> Grooves {
    Grooves {
        count: 8,
        angle: 30f64.to_radians(),
        depth,
        width: 0.5,
        length_fraction: 1.0,
        side,
    }
}

pub(super) fn grooved(lambda: f64, nt: usize, nz: usize, g: Grooves) -> FilmSolver {
    solver(&Bearing {
        lambda,
        grooves: Some(g),
        cavitation: Cavitation::HalfSommerfeld,
        model: FilmModel::Finite {
            n_theta: nt,
            n_zeta: nz,
        },
    })
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// Ocvirk, half-Sommerfeld, in units F_S (`F0 = (2 lambda)^2 F_S`).
fn ocvirk(lambda: f64, eps: f64) -> (f64, f64) {
    let f0 = 4.0 * lambda * lambda;
    let s2 = 1.0 - eps * eps;
    (
        f0 * eps * eps / (s2 * s2),
        f0 * PI * eps / (4.0 * s2.powf(1.5)),
    )
}

/// Gümbel (long, half-Sommerfeld) and Sommerfeld (long, full) per unit length.
fn gumbel(eps: f64) -> (f64, f64) {
    let s2 = 1.0 - eps * eps;
    (
        12.0 * eps * eps / ((2.0 + eps * eps) * s2),
        6.0 * PI * eps / ((2.0 + eps * eps) * s2.sqrt()),
    )
}

fn sommerfeld_ft(eps: f64) -> f64 {
    12.0 * PI * eps / ((2.0 + eps * eps) * (1.0 - eps * eps).sqrt())
}

#[test]
fn bearing_short_static_is_ocvirk() {
    for lambda in [0.1, 0.5] {
        let mut s = solver(&Bearing::plain(lambda, FilmModel::Short));
        let mut full = solver(&Bearing {
            cavitation: Cavitation::None,
            ..Bearing::plain(lambda, FilmModel::Short)
        });
        for (eps, ang) in [
            (0.02, 0.3),
            (0.09, 2.0),
            (0.3, -1.0),
            (0.6, 4.0),
            (0.95, 1.0),
        ] {
            let st = JournalState::at(eps * f64::cos(ang), eps * f64::sin(ang));
            let f = s.force(&st, false).unwrap();
            let (fr, ft) = ocvirk(lambda, eps);
            assert!(
                rel(f.f_radial, fr) < 1e-11,
                "eps {eps}: {} vs {fr}",
                f.f_radial
            );
            assert!(
                rel(f.f_tangential, ft) < 1e-11,
                "eps {eps}: {} vs {ft}",
                f.f_tangential
            );
            let tan_att = PI * (1.0 - eps * eps).sqrt() / (4.0 * eps);
            assert!(rel(f.attitude.tan(), tan_att) < 1e-10);
            // Full Sommerfeld: no radial force, twice the tangential one.
            let g = full.force(&st, false).unwrap();
            assert!(g.f_radial.abs() < 1e-12 * ft, "{}", g.f_radial);
            assert!(rel(g.f_tangential, 2.0 * ft) < 1e-11);
        }
    }
}

/// Direct quadrature of the short-bearing pressure `g/(2H^3)(zeta^2 - lambda^2)` clipped:
/// Simpson in zeta, midpoint in theta on 200 000 cells, force `-(1/2 lambda) int int P n`.
fn short_quadrature(lambda: f64, s: &JournalState, clip: bool) -> (f64, f64) {
    let n = 200_000;
    let dt = 2.0 * PI / n as f64;
    let nzq = 20;
    let dzq = 2.0 * lambda / nzq as f64;
    let (mut fx, mut fy) = (0.0, 0.0);
    for i in 0..n {
        let th = (i as f64 + 0.5) * dt;
        let (st, ct) = th.sin_cos();
        let h = 1.0 - s.x * ct - s.y * st;
        let dhdth = s.x * st - s.y * ct;
        let dhdtau = -(s.vx * ct + s.vy * st);
        let g = 6.0 * dhdth + 12.0 * dhdtau;
        let mut pz = 0.0;
        for j in 0..=nzq {
            let z = -lambda + j as f64 * dzq;
            let w = if j == 0 || j == nzq {
                1.0
            } else if j % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let p = g / (2.0 * h * h * h) * (z * z - lambda * lambda);
            pz += w * if clip { p.max(0.0) } else { p };
        }
        pz *= dzq / 3.0;
        fx -= pz * ct * dt;
        fy -= pz * st * dt;
    }
    (fx / (2.0 * lambda), fy / (2.0 * lambda))
}

#[test]
fn bearing_short_dynamic_matches_quadrature() {
    let lambda = 0.25;
    let mut s = solver(&Bearing::plain(lambda, FilmModel::Short));
    let mut full = solver(&Bearing {
        cavitation: Cavitation::None,
        ..Bearing::plain(lambda, FilmModel::Short)
    });
    let states = [
        (0.0, 0.0, 0.2, -0.1),
        (0.05, -0.03, -0.3, 0.4),
        (0.4, 0.2, 0.1, 0.3),
        (-0.5, 0.6, -0.2, -0.05),
        (0.1, -0.85, 0.7, 0.0),
        (0.3, 0.0, 0.0, 0.5), // whirl at half speed: the wedge vanishes
    ];
    for (x, y, vx, vy) in states {
        let st = JournalState {
            x,
            y,
            vx,
            vy,
            tau: 0.0,
        };
        let f = s.force(&st, false).unwrap();
        let (qx, qy) = short_quadrature(lambda, &st, true);
        let scale = qx.hypot(qy);
        assert!(
            (f.fx - qx).abs() + (f.fy - qy).abs() < 1e-8 * scale,
            "{st:?}: ({}, {}) vs ({qx}, {qy})",
            f.fx,
            f.fy
        );
        let g = full.force(&st, false).unwrap();
        let (qx, qy) = short_quadrature(lambda, &st, false);
        assert!((g.fx - qx).abs() + (g.fy - qy).abs() < 1e-8 * qx.hypot(qy));
    }
}

#[test]
fn bearing_long_static_is_gumbel_and_sommerfeld() {
    let mut hs = solver(&Bearing::plain(1.0, FilmModel::Long));
    let mut full = solver(&Bearing {
        cavitation: Cavitation::None,
        ..Bearing::plain(1.0, FilmModel::Long)
    });
    for eps in [0.05, 0.4, 0.8, 0.95] {
        let st = JournalState::at(0.0, -eps);
        let f = hs.force(&st, false).unwrap();
        let (fr, ft) = gumbel(eps);
        assert!(rel(f.f_radial, fr) < 1e-10, "{eps}: {} vs {fr}", f.f_radial);
        assert!(rel(f.f_tangential, ft) < 1e-10);
        let g = full.force(&st, false).unwrap();
        assert!(g.f_radial.abs() < 1e-10 * ft);
        assert!(rel(g.f_tangential, sommerfeld_ft(eps)) < 1e-12);
    }
}

/// The finite solver's force for a problem, through the sparse path or the fast path.
fn finite_force(s: &mut FilmSolver, st: &JournalState) -> FilmForce {
    s.force(st, false).unwrap()
}

#[test]
fn bearing_finite_tends_to_ocvirk_as_lambda_to_zero() {
    let eps = 0.6;
    let st = JournalState::at(eps, 0.0);
    let (fr0, ft0) = ocvirk(1.0, eps);
    let mut errs = Vec::new();
    for lambda in [0.1, 0.05, 0.025] {
        let mut s = finite(lambda, 512, 64, Cavitation::HalfSommerfeld);
        let f = finite_force(&mut s, &st);
        let k = lambda * lambda;
        let e = (rel(f.f_radial, fr0 * k), rel(f.f_tangential, ft0 * k));
        println!(
            "L/D {lambda}: F/F_ocvirk - 1 = radial {:.3e}, tangential {:.3e}",
            e.0, e.1
        );
        errs.push(e.0.max(e.1));
    }
    // The deficit is O(lambda^2) down to the grid error (O(1/n^2), ~1e-3 here).
    assert!(errs[2] < 0.01, "{errs:?}");
    assert!(errs[1] < errs[0] && errs[2] < errs[1]);
    // With squeeze too.
    let lambda = 0.025;
    let dyn_state = JournalState {
        x: 0.3,
        y: -0.4,
        vx: 0.2,
        vy: 0.1,
        tau: 0.0,
    };
    let mut s = finite(lambda, 512, 64, Cavitation::HalfSommerfeld);
    let f = finite_force(&mut s, &dyn_state);
    let (qx, qy) = short_quadrature(lambda, &dyn_state, true);
    let err = (f.fx - qx).hypot(f.fy - qy) / qx.hypot(qy);
    println!("L/D {lambda} with squeeze: |F - F_short| / |F_short| = {err:.3e}");
    assert!(err < 0.01);
}

#[test]
fn bearing_finite_tends_to_gumbel_as_lambda_to_infinity() {
    let eps = 0.6;
    let st = JournalState::at(-eps, 0.0);
    let (fr, ft) = gumbel(eps);
    let mut errs = Vec::new();
    for lambda in [4.0, 8.0, 16.0] {
        // ~12 cells per unit of zeta resolves the end layers.
        let nz = (24.0 * lambda) as usize;
        let mut s = finite(lambda, 256, nz, Cavitation::HalfSommerfeld);
        let f = finite_force(&mut s, &st);
        let e = (1.0 - f.f_radial / fr, 1.0 - f.f_tangential / ft);
        println!(
            "L/D {lambda}: deficit vs Gumbel radial {:.4}, tangential {:.4}",
            e.0, e.1
        );
        errs.push(e);
        let mut s = finite(lambda, 256, nz, Cavitation::None);
        let g = finite_force(&mut s, &st);
        let ef = 1.0 - g.f_tangential / sommerfeld_ft(eps);
        println!(
            "L/D {lambda}: full film F_r/F_t = {:.2e}, deficit vs Sommerfeld {ef:.4}",
            g.f_radial / g.f_tangential
        );
        assert!(g.f_radial.abs() < 1e-9 * g.f_tangential);
        assert!(ef > 0.0 && ef < 2.0 / lambda);
    }
    // A deficit like D/L: halving each time L/D doubles.
    for w in errs.windows(2) {
        let r = w[0].1 / w[1].1;
        assert!((1.6..2.4).contains(&r), "{errs:?}");
        assert!(w[1].0 > 0.0 && w[1].0 < w[0].0);
    }
}

#[test]
fn bearing_finite_long_squeeze_matches_long_closed_form() {
    // Full film: the long-bearing closed-form pressure with squeeze against the finite solver.
    let st = JournalState {
        x: 0.2,
        y: 0.5,
        vx: -0.3,
        vy: 0.15,
        tau: 0.0,
    };
    let mut long = solver(&Bearing {
        cavitation: Cavitation::None,
        ..Bearing::plain(1.0, FilmModel::Long)
    });
    let fl = long.force(&st, false).unwrap();
    let mut d = Vec::new();
    for lambda in [8.0, 16.0] {
        let mut s = finite(lambda, 256, (24.0 * lambda) as usize, Cavitation::None);
        let f = finite_force(&mut s, &st);
        d.push((f.fx - fl.fx).hypot(f.fy - fl.fy) / fl.fx.hypot(fl.fy));
    }
    println!("finite vs long closed form with squeeze: {d:?}");
    assert!(d[1] < 0.15 && d[1] < 0.6 * d[0]);
}

#[test]
fn bearing_finite_grid_convergence_order() {
    let st = JournalState {
        x: 0.5,
        y: 0.2,
        vx: 0.05,
        vy: -0.1,
        tau: 0.0,
    };
    for cav in [Cavitation::None, Cavitation::HalfSommerfeld] {
        let f: Vec<[f64; 2]> = [(32, 8), (64, 16), (128, 32), (256, 64)]
            .iter()
            .map(|&(nt, nz)| {
                let ff = finite_force(&mut finite(1.0, nt, nz, cav), &st);
                [ff.fx, ff.fy]
            })
            .collect();
        let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
        let o1 = (d(f[0], f[1]) / d(f[1], f[2])).log2();
        let o2 = (d(f[1], f[2]) / d(f[2], f[3])).log2();
        println!("{cav:?}: measured grid-convergence order {o1:.3}, {o2:.3}");
        assert!((1.8..2.2).contains(&o2), "{cav:?}: order {o2}");
    }
}

#[test]
fn bearing_fast_path_equals_sparse_solve() {
    let mut s = finite(0.75, 128, 32, Cavitation::None);
    let pb = Problem {
        x: -0.3,
        y: 0.55,
        vx: 0.2,
        vy: -0.4,
        couette: 1.0,
        groove_speed: 0.0,
        groove_offset: 0.0,
    };
    let SolverKindRef::Finite(fs) = kind(&mut s) else {
        unreachable!()
    };
    let a = fs.solve(&pb, false).unwrap();
    let b = fs.solve(&pb, true).unwrap();
    let scale = b.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    let diff = a
        .iter()
        .zip(&b)
        .fold(0.0_f64, |m, (u, v)| m.max((u - v).abs()));
    println!(
        "fast path vs sparse Cholesky: max |dP| / max |P| = {:.2e}",
        diff / scale
    );
    assert!(diff < 1e-12 * scale);
}

pub(super) enum SolverKindRef<'a> {
    Finite(&'a mut finite::FiniteSolver),
    Other,
}

pub(super) fn kind(s: &mut FilmSolver) -> SolverKindRef<'_> {
    match &mut s.kind {
        super::SolverKind::Finite(f) => SolverKindRef::Finite(f),
        _ => SolverKindRef::Other,
    }
}

#[test]
fn bearing_groove_depth_zero_is_plain() {
    // Depth 0 runs the grooved (sparse, face-fraction) path; the plain film takes the
    // sine-transform path.
    let st = JournalState {
        x: 0.4,
        y: -0.3,
        vx: 0.1,
        vy: 0.2,
        tau: 0.7,
    };
    let mut plain = finite(1.0, 128, 32, Cavitation::HalfSommerfeld);
    let fp = plain.force(&st, false).unwrap();
    for side in [GrooveSide::Sleeve, GrooveSide::Journal] {
        let mut g = grooved(1.0, 128, 32, herringbone(0.0, side));
        let fg = g.force(&st, false).unwrap();
        assert!(
            (fg.fx - fp.fx).abs() + (fg.fy - fp.fy).abs() < 1e-12 * fp.fx.hypot(fp.fy),
            "{side:?}: ({}, {}) vs ({}, {})",
            fg.fx,
            fg.fy,
            fp.fx,
            fp.fy
        );
    }
}

#[test]
fn bearing_concentric_grooved_carries_no_load() {
    for side in [GrooveSide::Sleeve, GrooveSide::Journal] {
        let mut g = grooved(1.0, 128, 32, herringbone(1.0, side));
        let f0 = g.force(&JournalState::at(0.0, 0.0), false).unwrap();
        let f1 = g.force(&JournalState::at(0.05, 0.0), false).unwrap();
        let scale = f1.fx.hypot(f1.fy);
        println!(
            "{side:?}: |F(0)| = {:.2e}, |F(eps = 0.05)| = {scale:.3e}, p_max(0) = {:.3}",
            f0.fx.hypot(f0.fy),
            f0.p_max
        );
        assert!(f0.p_max > 0.1, "the grooves pump: pressure without load");
        assert!(f0.fx.hypot(f0.fy) < 1e-12 * scale);
    }
}

#[test]
fn bearing_grooves_give_direct_stiffness_at_centre() {
    let mut plain = finite(1.0, 128, 32, Cavitation::HalfSommerfeld);
    let kp = linear_coefficients(&mut plain, 0.0, 0.0).unwrap();
    let mut g = grooved(1.0, 128, 32, herringbone(1.0, GrooveSide::Sleeve));
    let kg = linear_coefficients(&mut g, 0.0, 0.0).unwrap();
    println!(
        "plain K at centre {:?}\ngrooved K at centre {:?}",
        kp.k, kg.k
    );
    assert!(kp.k[(0, 0)].abs() < 1e-6 * kp.k[(0, 1)].abs());
    assert!(kp.k[(1, 1)].abs() < 1e-6 * kp.k[(0, 1)].abs());
    assert!(kg.k[(0, 0)] > 0.1 * kg.k[(0, 1)].abs());
    assert!(
        rel(kg.k[(1, 1)], kg.k[(0, 0)]) < 1e-4,
        "isotropic for 8 grooves"
    );
}

#[test]
fn bearing_grooved_journal_same_force_in_both_frames() {
    let (nt, nz) = (128, 32);
    let g = herringbone(1.0, GrooveSide::Journal);
    let mut fixed = grooved(1.0, nt, nz, g);
    let mut journal = grooved(1.0, nt, nz, g);
    for (k, x, y, vx, vy) in [(5, 0.3, -0.4, 0.1, 0.2), (-37, -0.6, 0.1, 0.0, -0.3)] {
        // tau on a grid line, so both frames see the same cells.
        let tau = k as f64 * 2.0 * PI / nt as f64;
        let st = JournalState { x, y, vx, vy, tau };
        let ff = fixed.force(&st, false).unwrap();
        // Journal frame: q_j = R(-tau) q, q_j' = R(-tau) q' - J q_j; the sleeve moves at -1,
        // the grooves stand still, and the force turns back by R(tau).
        let (s, c) = tau.sin_cos();
        let (xj, yj) = (c * x + s * y, -s * x + c * y);
        let (vxj, vyj) = (c * vx + s * vy + yj, -s * vx + c * vy - xj);
        let pb = Problem {
            x: xj,
            y: yj,
            vx: vxj,
            vy: vyj,
            couette: -1.0,
            groove_speed: 0.0,
            groove_offset: 0.0,
        };
        let SolverKindRef::Finite(fs) = kind(&mut journal) else {
            unreachable!()
        };
        let p = fs.solve(&pb, false).unwrap();
        let (fxj, fyj) = fs.integrate(&p);
        let (fx, fy) = (c * fxj - s * fyj, s * fxj + c * fyj);
        let scale = ff.fx.hypot(ff.fy);
        println!(
            "tau {tau:.3}: fixed ({:.6}, {:.6}) journal ({fx:.6}, {fy:.6})",
            ff.fx, ff.fy
        );
        assert!((ff.fx - fx).hypot(ff.fy - fy) < 1e-11 * scale);
    }
}

#[test]
fn bearing_reynolds_cavitation_dominates_half_sommerfeld() {
    let st = JournalState::at(0.6, 0.0);
    let mut hs = finite(1.0, 128, 32, Cavitation::HalfSommerfeld);
    let mut re = finite(1.0, 128, 32, Cavitation::Reynolds);
    let fh = hs.force(&st, true).unwrap();
    let fr = re.force(&st, true).unwrap();
    let (wh, wr) = (fh.fx.hypot(fh.fy), fr.fx.hypot(fr.fy));
    println!(
        "L/D 1, eps 0.6: load Reynolds / half-Sommerfeld = {:.4}; Sommerfeld number S = 1/(pi W/F_S): {:.4} vs {:.4}; attitude {:.2} vs {:.2} deg",
        wr / wh,
        1.0 / (PI * wr),
        1.0 / (PI * wh),
        fr.attitude.to_degrees(),
        fh.attitude.to_degrees()
    );
    // M is an M-matrix, so the obstacle problem's solution is at least the linear solution
    // and at least 0: P_Reynolds >= max(P_linear, 0) = P_half-Sommerfeld cell by cell.
    let ph = fh.pressure.unwrap().values;
    let pr = fr.pressure.unwrap().values;
    assert!(pr.iter().zip(&ph).all(|(r, h)| *r >= h - 1e-12 * fh.p_max));
    assert!(pr.contains(&0.0), "the film cavitates");
    // bearing.md: the two differ by 10-15 % in load at L/D = 1.
    assert!((1.05..1.2).contains(&(wr / wh)));
}

/// Friswell et al. (2010), Dynamics of Rotating Machines, section 5.5.1 (short bearing,
/// half-Sommerfeld): `K = (f0/c) a`, `C = (f0/(c w)) b` in axes (u, v) with `h0 =
/// 1/(pi^2 (1 - e^2) + 16 e^2)^(3/2)`.
fn friswell(eps: f64) -> (Matrix2<f64>, Matrix2<f64>) {
    let e2 = eps * eps;
    let p2 = PI * PI;
    let s = (1.0 - e2).sqrt();
    let h0 = 1.0 / (p2 * (1.0 - e2) + 16.0 * e2).powf(1.5);
    let auu = h0 * 4.0 * (p2 * (2.0 - e2) + 16.0 * e2);
    let auv = h0 * PI * (p2 * (1.0 - e2).powi(2) - 16.0 * e2 * e2) / (eps * s);
    let avu = -h0 * PI * (p2 * (1.0 - e2) * (1.0 + 2.0 * e2) + 32.0 * e2 * (1.0 + e2)) / (eps * s);
    let avv = h0 * 4.0 * (p2 * (1.0 + 2.0 * e2) + 32.0 * e2 * (1.0 + e2) / (1.0 - e2));
    let buu = h0 * 2.0 * PI * s * (p2 * (1.0 + 2.0 * e2) - 16.0 * e2) / eps;
    let buv = -h0 * 8.0 * (p2 * (1.0 + 2.0 * e2) - 16.0 * e2);
    let bvv = h0 * 2.0 * PI * (p2 * (1.0 - e2).powi(2) + 48.0 * e2) / (eps * s);
    (
        Matrix2::new(auu, auv, avu, avv),
        Matrix2::new(buu, buv, buv, bvv),
    )
}

#[test]
fn bearing_short_coefficients_match_friswell() {
    let lambda = 0.25;
    let mut s = solver(&Bearing::plain(lambda, FilmModel::Short));
    for eps in [0.1, 0.3, 0.5, 0.7, 0.9] {
        // Load along -y; find the journal by Newton, then linearise there.
        let (fr, ft) = ocvirk(lambda, eps);
        let w = fr.hypot(ft);
        let eq = equilibrium(&mut s, [0.0, -w]).unwrap();
        assert!(rel(eq.eccentricity, eps) < 1e-9, "{eq:?}");
        let lc = linear_coefficients(&mut s, eq.x, eq.y).unwrap();
        let (a, b) = friswell(eps);
        // Friswell's axes: u horizontal, v vertical with the weight along -v, the shaft
        // turning counter-clockwise; here the load is along -y and the spin positive: u = x, v = y.
        let k = lc.k / w;
        let c = lc.c / w;
        println!("eps {eps}: K/(f0/c) {k:?} Friswell {a:?}");
        println!("eps {eps}: C/(f0/cw) {c:?} Friswell {b:?}");
        for i in 0..2 {
            for j in 0..2 {
                assert!(
                    (k[(i, j)] - a[(i, j)]).abs() < 1e-6 * a.abs().max(),
                    "K {i}{j}"
                );
                assert!(
                    (c[(i, j)] - b[(i, j)]).abs() < 1e-6 * b.abs().max(),
                    "C {i}{j}"
                );
            }
        }
    }
}

#[test]
fn bearing_rigid_rotor_on_short_bearing_threshold() {
    let lambda = 0.25;
    let mut s = solver(&Bearing::plain(lambda, FilmModel::Short));
    let stab = |s: &mut FilmSolver, eps: f64| {
        let lc = linear_coefficients(s, 0.0, -eps).unwrap();
        let f = s.force(&JournalState::at(0.0, -eps), false).unwrap();
        (lc, rigid_rotor_stability(&lc, f.fx.hypot(f.fy)))
    };
    for eps in [0.05, 0.2, 0.4, 0.6, 0.7, 0.74, 0.76, 0.8, 0.9] {
        let (lc, w) = stab(&mut s, eps);
        println!(
            "eps {eps}: critical mass {:.4e}, whirl ratio {:.4}, threshold speed {:.4}",
            w.critical_mass, w.whirl_ratio, w.threshold_speed
        );
        let max_re = |m: f64| {
            lc.eigenvalues(m)
                .unwrap()
                .iter()
                .map(|z| z.0)
                .fold(f64::MIN, f64::max)
        };
        if w.critical_mass.is_finite() {
            // The eigenvalues cross the imaginary axis there, at the whirl ratio.
            assert!(max_re(0.99 * w.critical_mass) < 0.0);
            assert!(max_re(1.01 * w.critical_mass) > 0.0);
            let ev = lc.eigenvalues(w.critical_mass).unwrap();
            assert!(
                ev.iter()
                    .any(|z| z.0.abs() < 1e-8 && rel(z.1.abs(), w.whirl_ratio) < 1e-6),
                "{ev:?}"
            );
        } else {
            for m in [1e-3, 1e-1, 1.0, 1e2, 1e4, 1e6] {
                assert!(max_re(m) < 0.0, "eps {eps}, m {m}");
            }
        }
    }
    // The boundary of stability at every speed, by bisection on eps.
    let (mut lo, mut hi) = (0.5, 0.95);
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if stab(&mut s, mid).1.critical_mass.is_finite() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    println!("short bearing: stable at every speed above eps = {lo:.5}");
    assert!((lo - 0.756).abs() < 0.002, "{lo}");
    let w = stab(&mut s, 0.1).1;
    assert!((w.whirl_ratio - 0.5).abs() < 0.03, "{w:?}");
}

#[test]
fn bearing_centred_unloaded_rotor_is_unstable() {
    for model in [
        FilmModel::Short,
        FilmModel::Finite {
            n_theta: 64,
            n_zeta: 16,
        },
    ] {
        let mut s = solver(&Bearing::plain(1.0, model));
        let lc = linear_coefficients(&mut s, 0.0, 0.0).unwrap();
        // No direct stiffness at the centre (F_r = O(eps^2)); the central difference leaves
        // O(h) = 1e-6 of it, so the threshold mass is ~0 rather than exactly 0.
        let crit = rigid_rotor_stability(&lc, 1.0).critical_mass;
        assert!(crit < 1e-4, "{model:?}: {crit}");
        for m in [1e-2, 1.0, 1e2] {
            let max_re = lc
                .eigenvalues(m)
                .unwrap()
                .iter()
                .map(|z| z.0)
                .fold(f64::MIN, f64::max);
            assert!(max_re > 0.0, "{model:?} m {m}: {max_re}");
        }
    }
}

#[test]
fn bearing_bad_input_names_the_parameter() {
    let name = |e: crate::error::Error| match e {
        crate::error::Error::InvalidParameter { name, .. } => name,
        other => panic!("{other:?}"),
    };
    assert_eq!(
        name(Dimensions::new(0.01, 0.02, -1e-5, 0.01).unwrap_err()),
        "clearance"
    );
    let fin = FilmModel::Finite {
        n_theta: 128,
        n_zeta: 32,
    };
    let with = |g: Grooves, model: FilmModel| Bearing {
        lambda: 1.0,
        grooves: Some(g),
        cavitation: Cavitation::HalfSommerfeld,
        model,
    };
    let g = herringbone(1.0, GrooveSide::Sleeve);
    let cases = [
        (
            with(Grooves { depth: -0.1, ..g }, fin),
            "grooves.depth_ratio",
        ),
        (
            with(Grooves { width: 0.0, ..g }, fin),
            "grooves.width_ratio",
        ),
        (
            with(Grooves { width: 1.0, ..g }, fin),
            "grooves.width_ratio",
        ),
        (with(Grooves { angle: 0.0, ..g }, fin), "grooves.angle"),
        (
            with(
                Grooves {
                    angle: PI / 2.0,
                    ..g
                },
                fin,
            ),
            "grooves.angle",
        ),
        (with(Grooves { angle: 2.0, ..g }, fin), "grooves.angle"),
        (with(Grooves { count: 0, ..g }, fin), "grooves.count"),
        (
            with(
                g,
                FilmModel::Finite {
                    n_theta: 100,
                    n_zeta: 32,
                },
            ),
            "grid.n_theta",
        ),
        (
            with(
                g,
                FilmModel::Finite {
                    n_theta: 32,
                    n_zeta: 32,
                },
            ),
            "grid.n_theta",
        ),
        (
            with(
                g,
                FilmModel::Finite {
                    n_theta: 128,
                    n_zeta: 15,
                },
            ),
            "grid.n_zeta",
        ),
        (with(g, FilmModel::Short), "model"),
        (Bearing::plain(-1.0, FilmModel::Short), "length_ratio"),
        (
            Bearing {
                cavitation: Cavitation::Reynolds,
                ..Bearing::plain(1.0, FilmModel::Short)
            },
            "cavitation",
        ),
    ];
    for (b, want) in cases {
        assert_eq!(
            name(b.solver().err().expect("must be rejected")),
            want,
            "{b:?}"
        );
    }
    let mut s = solver(&Bearing::plain(1.0, FilmModel::Short));
    assert_eq!(
        name(s.force(&JournalState::at(0.8, 0.7), false).unwrap_err()),
        "eccentricity"
    );
}

#[test]
fn bearing_factor_reuse_derivatives_match_finite_differences() {
    let cases = [
        (finite(1.0, 64, 16, Cavitation::HalfSommerfeld), 0.5, -0.2),
        (finite(0.5, 64, 16, Cavitation::None), -0.3, 0.6),
        (
            grooved(1.0, 128, 16, herringbone(1.0, GrooveSide::Sleeve)),
            0.3,
            0.25,
        ),
        (
            grooved(1.0, 128, 16, herringbone(0.7, GrooveSide::Journal)),
            -0.2,
            -0.4,
        ),
    ];
    for (mut s, x, y) in cases {
        let a = linear_coefficients(&mut s, x, y).unwrap();
        let f = linear_coefficients_fd(&mut s, x, y).unwrap();
        let scale = a.k.abs().max().max(a.c.abs().max());
        let d = (a.k - f.k).abs().max().max((a.c - f.c).abs().max());
        println!(
            "factor reuse vs central differences: max |d| / max |K, C| = {:.2e}",
            d / scale
        );
        assert!(d < 1e-6 * scale, "{a:?} vs {f:?}");
    }
}

#[test]
fn bearing_old_factor_preconditioner_matches_direct_solve() {
    // Grooves on the sleeve (Yen's (2005) case): only the smooth film moves. (Journal grooves
    // move the O(1) groove-land jump across cells, and an old factor helps far less.)
    let g = herringbone(1.0, GrooveSide::Sleeve);
    let mut direct = grooved(1.0, 128, 16, g);
    let mut reuse = grooved(1.0, 128, 16, g);
    reuse.set_factor_reuse(Some(1e-12));
    // A short stretch of a whirl orbit: the film changes a little per step.
    for k in 0..20 {
        let t = 0.05 * k as f64;
        let st = JournalState {
            x: 0.4 * t.cos(),
            y: 0.4 * t.sin(),
            vx: -0.2 * t.sin(),
            vy: 0.2 * t.cos(),
            tau: t,
        };
        let a = direct.force(&st, false).unwrap();
        let b = reuse.force(&st, false).unwrap();
        assert!(
            (a.fx - b.fx).hypot(a.fy - b.fy) < 1e-8 * a.fx.hypot(a.fy),
            "step {k}"
        );
    }
    let SolverKindRef::Finite(fs) = kind(&mut reuse) else {
        unreachable!()
    };
    println!(
        "old factor as preconditioner: {} factorisations, {} CG iterations for 20 solves",
        fs.factorisations, fs.cg_iterations
    );
    assert!(fs.factorisations < 20);
}

#[test]
fn bearing_sommerfeld_number_matches_dimensional_definition() {
    // R = 25 mm, L = 30 mm, c = 40 um, mu = 0.02 Pa s, 300 rad/s.
    let dims = Dimensions::new(0.025, 0.03, 40e-6, 0.02).unwrap();
    let omega = 300.0;
    let mut s = solver(&Bearing::plain(dims.lambda(), FilmModel::Short));
    let f = s.force(&JournalState::at(0.5, 0.1), false).unwrap();
    let w = f.fx.hypot(f.fy) * dims.force_scale(omega);
    // S = mu N L D (R/c)^2 / W with N in rev/s, written out here.
    let n = omega / (2.0 * PI);
    let s_def = 0.02 * n * 0.03 * 0.05 * (0.025f64 / 40e-6).powi(2) / w;
    assert!(rel(f.sommerfeld, s_def) < 1e-12);
    assert!(rel(dims.sommerfeld(omega, w), s_def) < 1e-12);
}
