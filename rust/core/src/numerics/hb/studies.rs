//! Profiling hooks of harmonic balance: warm solves for callgrind and the longest wait
//! of a cancellation (results in docs/measurements.md and docs/results.md). Compiled
//! only with the `studies` feature, and `#[ignore]`d: run one by name with `--ignored
//! --nocapture`.

use super::*;

/// Warm-started solves at N = 3, 6, 8, 12 for callgrind (`--ignored --exact
/// numerics::hb::studies::hb_profile`): 20 solves per N, all four N, or only the N in
/// `BALLBAL_HB_N`. Per solve: `warm_solve`'s inclusive count / 20 with
/// `BALLBAL_HB_N` set (the per-N copies of `warm_solve` compile to one function, so
/// callgrind cannot tell the N apart in a run of all four).
#[test]
#[ignore]
fn hb_profile() {
    use crate::periodic::{periodic, PeriodicOptions};
    let p = crate::Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &[1.0, 1.0]).unwrap();
    let near = crate::Planar::new(0.2, 0.05, &[0.05], 50.0, 1.19, &[1.0, 1.0]).unwrap();
    let seed = periodic(&near, &[true, true], None, &PeriodicOptions::default()).sol;
    let opts = |n_harm| PeriodicOptions {
        hb: HbOptions {
            n_harm,
            ..Default::default()
        },
        ..Default::default()
    };
    let seed12 = periodic(&near, &[true, true], Some(&seed), &opts(12)).sol;
    let only: Option<usize> = std::env::var("BALLBAL_HB_N")
        .ok()
        .map(|v| v.parse().expect("BALLBAL_HB_N: a harmonic count"));
    let ns: Vec<usize> = only.map_or(vec![3, 6, 8, 12], |n| vec![n]);
    let mut acc = 0.0;
    for _ in 0..20 {
        for &n in &ns {
            acc += warm_solve(&p, &seed12, &opts(n));
        }
    }
    println!("{acc}");
}

/// How long Ctrl-C can wait during `periodic` with many balls at N = 256 (stability
/// included), from an N = 3 guess as in `tests/test_interrupts.py`: the call's time and
/// the longest stretch between two cancellation polls. `BALLBAL_HB_BALLS=6,10 cargo test
/// --release -p ballbal-core --features studies hb_cancel_latency -- --ignored --nocapture`.
#[test]
#[ignore]
fn hb_cancel_latency() {
    use crate::periodic::{periodic, PeriodicOptions};
    let balls: Vec<usize> = std::env::var("BALLBAL_HB_BALLS").map_or(vec![6, 10], |v| {
        v.split(',').map(|x| x.parse().unwrap()).collect()
    });
    let opts = |n_harm| PeriodicOptions {
        hb: HbOptions {
            n_harm,
            ..Default::default()
        },
        ..Default::default()
    };
    for b in balls {
        let p = crate::Planar::new(0.2, 0.05, &[0.05], 50.0, 1.2, &vec![0.3; b]).unwrap();
        let pattern = vec![true; b];
        let guess = periodic(&p, &pattern, None, &opts(3)).sol;
        let (sol, total, longest) =
            crate::cancel::gaps::longest(|| periodic(&p, &pattern, Some(&guess), &opts(256)).sol);
        println!(
            "{b} balls, N = 256 ({} unknowns): {total:.3} s, longest between polls \
             {longest:.3} s (omega {:.6})",
            sol.coeffs.len() + 1,
            sol.omega
        );
    }
}

/// One warm solve (certificates included): the frame callgrind reports.
#[inline(never)]
fn warm_solve(p: &crate::Planar, g: &HbSolution, o: &crate::periodic::PeriodicOptions) -> f64 {
    crate::periodic::periodic(p, &[true, true], Some(g), o)
        .sol
        .omega
}
