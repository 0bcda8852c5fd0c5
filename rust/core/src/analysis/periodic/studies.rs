//! Measurement, not a check: the integrated defect of harmonic-balance solutions against
//! their simulated closure. Compiled only with the `studies` feature, and `#[ignore]`d:
//! run by name with `--ignored --nocapture`.

use super::*;
use crate::Planar;

/// `cargo test --release -p ballbal-core --features studies measure_certificates --
/// --ignored --nocapture` prints the integrated defect against the simulated closure on
/// the reproduction and on the Tien (2011) grid.
#[test]
#[ignore]
fn measure_certificates() {
    let fo = FloquetOptions::default();
    let b = |om: f64| Planar::new(0.2, 0.05, &[0.1], 50.0, om, &[1.0, 1.0]).unwrap();
    for n in [8, 3] {
        let opts = PeriodicOptions {
            hb: HbOptions {
                n_harm: n,
                ..Default::default()
            },
            floquet: Some(fo.clone()),
            max_closure: f64::INFINITY,
            max_tail: f64::INFINITY,
            ..Default::default()
        };
        let mut prev = periodic(&b(1.0), &[true, true], None, &opts);
        let mut w = 1.0;
        while w > 0.615 {
            let p = b(w);
            let r = periodic(&p, &[true, true], Some(&prev.sol), &opts);
            if r.sol.status != Status::Converged {
                println!("N={n} W={w:.3} {:?}", r.sol.status);
                break;
            }
            let sim = closure_error(&p, &r.sol, 1e-10, 1e-12).unwrap_or(f64::NAN);
            let f = r.floquet.as_ref();
            println!(
                "N={n} W={w:.3} omega={:.3e} defect={:.2e} sim={:.2e} tail={:.2e} triv={:.2e} sep={:?} maxmod={:.2e}",
                r.sol.omega,
                r.closure.unwrap(),
                sim,
                r.sol.tail_ratio(),
                f.map_or(f64::NAN, |f| f.trivial_error),
                f.and_then(|f| f.separation_error),
                f.map_or(f64::NAN, |f| f.max_modulus)
            );
            prev = r;
            w -= 0.02;
        }
    }
    // Tien (2011) grid at N = 3 with the scan's options, certificates off.
    use crate::scan::{scan, scan_floquet_default, ScanSpec};
    let base = Planar::new(0.2, 0.05, &[0.1], 50.0, 1.2, &[1.0, 1.0]).unwrap();
    let om: Vec<f64> = (0..=10).map(|i| 1.0 + 0.1 * i as f64).collect();
    let eta: Vec<f64> = (0..=11).map(|i| 0.4 + 0.1 * i as f64).collect();
    let spec = ScanSpec {
        base: &base,
        names: vec!["Omega".into(), "eta".into()],
        values: vec![om.clone(), eta.clone()],
        patterns: [[true, true], [false, false], [true, false]]
            .iter()
            .map(|r| plain_windings(r))
            .collect(),
        opts: PeriodicOptions {
            floquet: Some(scan_floquet_default()),
            guess: GuessOptions {
                settle: 1000.0,
                window: 2000.0,
                rtol: 1e-5,
                atol: 1e-8,
            },
            max_closure: f64::INFINITY,
            ..Default::default()
        },
        seeds: 4,
        starts: 4,
        chunk: 12,
        block: 12,
        threads: 2,
        max_tail: 0.25,
    };
    let rows = scan(&spec).unwrap();
    let mut worst_defect = 0.0f64;
    for r in rows.iter().filter(|r| r.result.is_some()) {
        let res = r.result.as_ref().unwrap();
        let p = base
            .with_param("Omega", om[r.index[0]])
            .unwrap()
            .with_param("eta", eta[r.index[1]])
            .unwrap();
        let sim = closure_error(&p, &res.sol, 1e-10, 1e-12).unwrap_or(f64::NAN);
        let f = res.floquet.as_ref();
        worst_defect = worst_defect.max(res.closure.unwrap());
        println!(
            "grid Om={:.2} eta={:.2} type={} omega={:.3e} defect={:.2e} sim={:.2e} tail={:.2e} triv={:.2e} sep={:?} maxmod={:.2e} {}",
            om[r.index[0]],
            eta[r.index[1]],
            r.pattern,
            res.sol.omega,
            res.closure.unwrap(),
            sim,
            res.sol.tail_ratio(),
            f.map_or(f64::NAN, |f| f.trivial_error),
            f.and_then(|f| f.separation_error),
            f.map_or(f64::NAN, |f| f.max_modulus),
            f.map_or("-", |f| f.stability.as_str()),
        );
    }
    println!("grid worst defect {worst_defect:.3e}");
}
