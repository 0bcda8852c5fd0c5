//! Studies and profiling hooks of the Floquet module: the calibrations behind its
//! constants and its instruction counts (results in docs/measurements.md). Compiled only
//! with the `studies` feature, and `#[ignore]`d: run one by name with `--ignored
//! --nocapture`.

use super::tests::{study_orbits, tight};
use super::*;
use crate::hb::HbOptions;
use crate::periodic::{periodic, PeriodicOptions};
use crate::Planar;

/// Cost and error of RK45 and Magnus monodromies at standard-map points (run with
/// `--ignored --nocapture`): the calibration behind the Magnus defaults.
#[test]
#[ignore]
fn magnus_study() {
    use std::time::Instant;
    study_orbits(|name, n_harm, p, sol, reference| {
        let time = |f: &dyn Fn() -> Floquet| {
            let t = Instant::now();
            let mut out = f();
            for _ in 0..19 {
                out = f();
            }
            (t.elapsed().as_secs_f64() / 20.0 * 1e6, out)
        };
        println!(
            "{name} N={n_harm} T={:.1} mults {:?}",
            sol.period(),
            reference
                .multipliers
                .iter()
                .map(|z| z.0.hypot(z.1))
                .collect::<Vec<_>>()
        );
        for rtol in [1e-5, 1e-6, 1e-7, 1e-8] {
            let o = FloquetOptions {
                rtol,
                atol: rtol * 1e-3,
                ..Default::default()
            };
            let (us, f) = time(&|| floquet(p, sol, &o).unwrap());
            let e = multiplier_distance(&f.multipliers, &reference.multipliers);
            println!(
                "  rk45   rtol {rtol:e}: {us:8.0} us steps {:5} err {e:.1e}",
                f.steps
            );
        }
        let n2 = 8;
        let rho = state_norm(&mut orbit_state_matrix(p, sol), n2, sol.period());
        println!("  ||A||_1 {rho:.2}");
        for k in [8, 16, 32, 64, 128, 256] {
            let t = Instant::now();
            let mut phi = vec![];
            for _ in 0..20 {
                phi = crate::numerics::magnus::monodromy_fixed(
                    orbit_state_matrix(p, sol),
                    n2,
                    sol.period(),
                    k,
                );
            }
            let us = t.elapsed().as_secs_f64() / 20.0 * 1e6;
            let ev = eigenvalues(&phi, n2).unwrap();
            let e = multiplier_distance(&ev, &reference.multipliers);
            let hr = sol.period() / k as f64 * rho;
            println!(
                "  magnus K {k:4}: {us:8.0} us err {e:.1e} h||A|| {hr:.2} C(1e-6) {:.1}",
                hr / e.powf(1.0 / 6.0)
            );
        }
        for rtol in [1e-5, 1e-6, 1e-7, 1e-8] {
            let o = FloquetOptions {
                method: FloquetMethod::Magnus,
                rtol,
                ..Default::default()
            };
            let (us, f) = time(&|| floquet(p, sol, &o).unwrap());
            let e = multiplier_distance(&f.multipliers, &reference.multipliers);
            println!(
                "  magnus rtol {rtol:e}: {us:8.0} us steps {:5} err {e:.1e} est {:.1e}",
                f.steps,
                f.method_error.unwrap()
            );
        }
    });
}

/// Hill's error estimate against the truncation error measured against a tight RK45
/// monodromy, truncation by truncation (run with `--ignored --nocapture`): the
/// calibration behind [`hill_start`].
#[test]
#[ignore]
fn hill_study() {
    study_orbits(|name, n_harm, p, sol, reference| {
        let old = hill_multipliers_dense(p, sol, (n_harm + 4).clamp(8, 24)).unwrap();
        println!(
            "{name} N={n_harm} T={:.1} omega {:.3} old err {:.1e} mods {:?}",
            sol.period(),
            sol.omega,
            multiplier_distance(&old, &reference.multipliers),
            reference
                .multipliers
                .iter()
                .map(|z| z.0.hypot(z.1))
                .collect::<Vec<_>>()
        );
        for h in 2..=16 {
            let hl = hill_at(p, sol, h).unwrap();
            let e = multiplier_distance(&hl.multipliers, &reference.multipliers);
            println!("  H {h:2}: est {:9.1e} err {e:9.1e}", hl.error);
        }
        let a = hill(p, sol, HILL_TOL, HILL_MAX).unwrap();
        println!(
            "  adaptive: H {} est {:.1e} err {:.1e}",
            a.n_hill,
            a.error,
            multiplier_distance(&a.multipliers, &reference.multipliers)
        );
    });
}

/// Hill's error estimate at H = 2 and 3 against the error measured against a tight
/// RK45 monodromy, and the verdict started at H = 2 (when `1.5 / sqrt(omega)` allows
/// it) against the tight verdict, on the studies' orbits and on the solutions of core
/// scans (all three two-ball types, N = 3): the 0.02-step fine grid at zeta_b = 0.05
/// and the 0.05-step one at zeta_b = 0.1 (run with `--ignored --nocapture`; minutes).
#[test]
#[ignore]
fn hill_h2_study() {
    use crate::scan::{scan, ScanSpec};
    use rayon::prelude::*;
    let (margin, max_trivial) = (1e-6, MAX_TRIVIAL);
    let mut cases: Vec<(String, Planar, HbSolution)> = vec![];
    study_orbits(|name, n_harm, p, sol, _| {
        cases.push((format!("{name} N={n_harm}"), p.clone(), sol.clone()));
    });
    let pats = [
        ("R-R", vec![true, true]),
        ("O-O", vec![false, false]),
        ("R-O", vec![true, false]),
    ];
    for (zb, step) in [(0.05, 0.02), (0.1, 0.05)] {
        let base = Planar::new(0.2, 0.05, &[zb], 50.0, 1.2, &[1.0, 1.0]).unwrap();
        let grid = |lo: f64, hi: f64| -> Vec<f64> {
            let n = ((hi - lo) / step).round() as usize;
            (0..=n).map(|i| lo + step * i as f64).collect()
        };
        let spec = ScanSpec {
            patterns: pats
                .iter()
                .map(|x| crate::periodic::plain_windings(&x.1))
                .collect(),
            seeds: 4,
            block: 8,
            chunk: 8,
            ..crate::scan::tests::spec(&base, &grid(1.0, 2.0), &grid(0.4, 1.5), 2)
        };
        for row in scan(&spec).unwrap() {
            let Some(res) = row.result else { continue };
            if res.sol.status != crate::hb::Status::Converged {
                continue;
            }
            let (om, eta) = (spec.values[0][row.index[0]], spec.values[1][row.index[1]]);
            let p = base
                .with_param("Omega", om)
                .unwrap()
                .with_param("eta", eta)
                .unwrap();
            let label = format!("{} zb {zb} Om {om:.2} eta {eta:.2}", pats[row.pattern].0);
            cases.push((label, p, res.sol));
        }
    }
    println!("{} solutions", cases.len());
    let tight = tight();
    let goal = verdict_goal(margin, max_trivial);
    struct Row {
        label: String,
        omega: f64,
        // [estimate, error, leading non-trivial modulus' error] at H = 2 and 3
        e: [[f64; 3]; 2],
        settles2: bool,
        ok: bool,
        h: usize,
        h_now: usize,
        got: Stability,
        now: Stability,
        want: Stability,
    }
    let rows: Vec<Row> = cases
        .par_iter()
        .filter(|(_, _, sol)| 1.5 / sol.omega.abs().sqrt() <= 2.0)
        .filter_map(|(label, p, sol)| {
            let reference = floquet(p, sol, &tight).ok()?;
            let rj = judge(&reference.multipliers, margin, max_trivial);
            let at = |h: usize| {
                let r = hill_at(p, sol, h).unwrap();
                let err = multiplier_distance(&r.multipliers, &reference.multipliers);
                let lead =
                    (judge(&r.multipliers, margin, max_trivial).max_modulus - rj.max_modulus).abs();
                [r.error, err, lead]
            };
            let h2 = hill_at(p, sol, 2).unwrap();
            let r = hill_until(p, sol, 2, HILL_MAX, &goal).unwrap();
            let j = judge(&r.multipliers, margin.max(r.error), max_trivial);
            // the verdict as started before at 3
            let rn = hill_until(p, sol, start_at(1.5, 3, sol), HILL_MAX, &goal).unwrap();
            let jn = judge(&rn.multipliers, margin.max(rn.error), max_trivial);
            Some(Row {
                label: label.clone(),
                omega: sol.omega,
                e: [at(2), at(3)],
                settles2: h2.error <= goal(&h2),
                ok: j.stability == rj.stability || j.stability == Stability::Undetermined,
                h: r.n_hill,
                h_now: rn.n_hill,
                got: j.stability,
                now: jn.stability,
                want: rj.stability,
            })
        })
        .collect();
    let floor = 1e-10;
    for (k, h) in [(0, 2), (1, 3)] {
        let mut min_all = (f64::INFINITY, String::new());
        let mut min_lead = (f64::INFINITY, String::new());
        let mut below = 0;
        let mut ratios: Vec<f64> = vec![];
        for r in &rows {
            let [est, err, lead] = r.e[k];
            let ra = est / err.max(floor);
            let rl = est / lead.max(floor);
            if est.is_finite() {
                ratios.push(ra);
            }
            if ra < 1.5 {
                below += 1;
                println!(
                    "  H {h} ratio {ra:.2} est {est:.1e} err {err:.1e} {}",
                    r.label
                );
            }
            if ra < min_all.0 {
                min_all = (ra, r.label.clone());
            }
            if rl < min_lead.0 {
                min_lead = (rl, r.label.clone());
            }
        }
        ratios.sort_by(f64::total_cmp);
        let q = |f: f64| {
            ratios
                .get(((ratios.len() as f64 - 1.0) * f) as usize)
                .copied()
        };
        println!(
            "H {h}: finite estimates {}, est/err min {:.2} ({}), quantiles 1% {:?} 50% {:?}; \
             est/lead-modulus err min {:.2} ({}); below 1.5: {below}",
            ratios.len(),
            min_all.0,
            min_all.1,
            q(0.01),
            q(0.5),
            min_lead.0,
            min_lead.1
        );
    }
    let count = |f: &dyn Fn(&Row) -> bool| rows.iter().filter(|r| f(r)).count();
    let mut hist = std::collections::BTreeMap::new();
    for r in &rows {
        *hist.entry((r.h_now, r.h)).or_insert(0) += 1;
    }
    println!(
        "start-2 solutions {}: settled at H = 2 {}, wrong verdicts {}, undetermined where \
         the reference is definite {}, verdict differs from today's {}; (today's H, H from \
         2): {hist:?}",
        rows.len(),
        count(&|r| r.settles2),
        count(&|r| !r.ok),
        count(&|r| r.got == Stability::Undetermined && r.want != Stability::Undetermined),
        count(&|r| r.got != r.now),
    );
    for r in rows
        .iter()
        .filter(|r| !r.ok || r.got != r.now || !r.settles2)
    {
        println!(
            "  {} omega {:.3}: got {:?} today {:?} reference {:?} H {} e {:?}",
            r.label, r.omega, r.got, r.now, r.want, r.h, r.e
        );
    }
    assert_eq!(count(&|r| !r.ok), 0);
}

/// Instruction counts of the scan's verdict target at H = 2 and 3 under callgrind:
/// `valgrind --tool=callgrind --toggle-collect='*hill_verdict_at*' <test binary>
/// --ignored --exact numerics::floquet::studies::hill_verdict_profile`.
#[test]
#[ignore]
fn hill_verdict_profile() {
    let mut acc = 0.0;
    // omega 0.25 (start 3) and 0.64 (start 2 allowed), R-R at N = 3
    for (om, eta) in [(1.2, 1.0), (1.6, 1.4)] {
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, om, &[eta, eta]).unwrap();
        let sol = periodic(&p, &[true, true], None, &PeriodicOptions::default()).sol;
        assert_eq!(sol.status, crate::hb::Status::Converged, "{om} {eta}");
        // HILL_PROFILE_H=2 or 3: that truncation alone
        let only: Option<usize> = std::env::var("HILL_PROFILE_H")
            .ok()
            .and_then(|v| v.parse().ok());
        for h in [2, 3].into_iter().filter(|h| only.is_none_or(|o| o == *h)) {
            let r = hill_verdict_at(&p, &sol, h);
            println!(
                "Omega {om} omega {:.3} H {h}: est {:.1e}",
                sol.omega, r.error
            );
            acc += r.multipliers[0].0;
        }
    }
    println!("{acc}");
}

#[inline(never)]
fn hill_verdict_at(p: &Planar, sol: &HbSolution, h: usize) -> Hill {
    hill_at(p, sol, h).unwrap()
}

/// Instruction counts under callgrind: `valgrind --tool=callgrind <test binary>
/// --ignored --exact numerics::floquet::studies::magnus_profile`.
#[test]
#[ignore]
fn magnus_profile() {
    let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
    let sol = periodic(&p, &[true, true], None, &PeriodicOptions::default()).sol;
    assert_eq!(sol.status, crate::hb::Status::Converged, "{sol:?}");
    let rk = FloquetOptions {
        rtol: 1e-6,
        atol: 1e-9,
        ..Default::default()
    };
    let mg = FloquetOptions {
        method: FloquetMethod::Magnus,
        rtol: 1e-6,
        ..Default::default()
    };
    let mut acc = 0.0;
    for _ in 0..10 {
        acc += profile_rk45(&p, &sol, &rk);
        acc += profile_magnus(&p, &sol, &mg);
        acc += profile_hill(&p, &sol);
    }
    println!("{acc}");
}

#[inline(never)]
fn profile_rk45(p: &Planar, sol: &HbSolution, o: &FloquetOptions) -> f64 {
    floquet(p, sol, o).unwrap().max_modulus
}

#[inline(never)]
fn profile_hill(p: &Planar, sol: &HbSolution) -> f64 {
    hill(p, sol, HILL_TOL, HILL_MAX).unwrap().multipliers[0].0
}

/// Hill's method alone at the standard case, N = 3 and 8, two and three balls, today's
/// ([`hill`]) and the former dense one ([`hill_multipliers_dense`] at the truncation
/// `periodic` used, `clamp(N + 4, 8, 24)`), under callgrind: `valgrind
/// --tool=callgrind <test binary> --ignored --exact
/// numerics::floquet::studies::hill_profile` (one function per case, so the inclusive
/// counts split by case).
#[test]
#[ignore]
fn hill_profile() {
    let mut acc = 0.0;
    for (n_harm, balls) in [(3, 2), (8, 2), (3, 3), (8, 3)] {
        let p = Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &vec![1.0; balls]).unwrap();
        let opts = PeriodicOptions {
            hb: HbOptions {
                n_harm,
                ..Default::default()
            },
            ..Default::default()
        };
        let sol = periodic(&p, &vec![true; balls], None, &opts).sol;
        assert_eq!(sol.status, crate::hb::Status::Converged, "{sol:?}");
        let t = std::time::Instant::now();
        let fast = match (n_harm, balls) {
            (3, 2) => hill_n3_b2(&p, &sol),
            (8, 2) => hill_n8_b2(&p, &sol),
            (3, _) => hill_n3_b3(&p, &sol),
            _ => hill_n8_b3(&p, &sol),
        };
        let t_fast = t.elapsed().as_secs_f64() * 1e3;
        let t = std::time::Instant::now();
        let h = (n_harm + 4).clamp(8, 24);
        let dense = match (n_harm, balls) {
            (3, 2) => dense_n3_b2(&p, &sol, h),
            (8, 2) => dense_n8_b2(&p, &sol, h),
            (3, _) => dense_n3_b3(&p, &sol, h),
            _ => dense_n8_b3(&p, &sol, h),
        };
        let t_dense = t.elapsed().as_secs_f64() * 1e3;
        println!(
            "N={n_harm} balls={balls}: hill H={} est {:.1e} {t_fast:.2} ms; dense H={h} \
             {t_dense:.2} ms; distance {:.1e}",
            fast.n_hill,
            fast.error,
            multiplier_distance(&fast.multipliers, &dense)
        );
        acc += fast.multipliers[0].0 + dense[0].0;
    }
    println!("{acc}");
}

#[inline(never)]
fn hill_n3_b2(p: &Planar, sol: &HbSolution) -> Hill {
    hill(p, sol, HILL_TOL, HILL_MAX).unwrap()
}

#[inline(never)]
fn hill_n8_b2(p: &Planar, sol: &HbSolution) -> Hill {
    hill(p, sol, HILL_TOL, HILL_MAX).unwrap()
}

#[inline(never)]
fn hill_n3_b3(p: &Planar, sol: &HbSolution) -> Hill {
    hill(p, sol, HILL_TOL, HILL_MAX).unwrap()
}

#[inline(never)]
fn hill_n8_b3(p: &Planar, sol: &HbSolution) -> Hill {
    hill(p, sol, HILL_TOL, HILL_MAX).unwrap()
}

#[inline(never)]
fn dense_n3_b2(p: &Planar, sol: &HbSolution, h: usize) -> Vec<(f64, f64)> {
    hill_multipliers_dense(p, sol, h).unwrap()
}

#[inline(never)]
fn dense_n8_b2(p: &Planar, sol: &HbSolution, h: usize) -> Vec<(f64, f64)> {
    hill_multipliers_dense(p, sol, h).unwrap()
}

#[inline(never)]
fn dense_n3_b3(p: &Planar, sol: &HbSolution, h: usize) -> Vec<(f64, f64)> {
    hill_multipliers_dense(p, sol, h).unwrap()
}

#[inline(never)]
fn dense_n8_b3(p: &Planar, sol: &HbSolution, h: usize) -> Vec<(f64, f64)> {
    hill_multipliers_dense(p, sol, h).unwrap()
}

#[inline(never)]
fn profile_magnus(p: &Planar, sol: &HbSolution, o: &FloquetOptions) -> f64 {
    floquet(p, sol, o).unwrap().max_modulus
}
