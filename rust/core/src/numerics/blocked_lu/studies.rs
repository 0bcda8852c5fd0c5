//! Timings of the blocked LU and the longest wait of a cancellation during one (results
//! in docs/measurements.md). Compiled only with the `studies` feature, and `#[ignore]`d:
//! run one by name with `--ignored --nocapture`.

use super::tests::matrix;
use super::*;

/// How long Ctrl-C can wait during `lu_factor` of harmonic-balance-sized systems (the
/// copy into column-major order included): the call's time and the longest stretch
/// between two cancellation polls. `BLU_N=4105,6157 cargo test --release -p
/// ballbal-core --features studies lu_cancel_latency -- --ignored --nocapture`.
#[test]
#[ignore]
fn lu_cancel_latency() {
    let sizes: Vec<usize> = std::env::var("BLU_N").map_or(vec![4105, 6157], |v| {
        v.split(',').map(|x| x.parse().unwrap()).collect()
    });
    for n in sizes {
        let m = matrix(n);
        let a: Vec<f64> = (0..n * n).map(|k| m[(k / n, k % n)]).collect();
        drop(m);
        let (ok, total, longest) =
            crate::cancel::gaps::longest(|| crate::numerics::linalg::lu_factor(&a, n).is_some());
        assert!(ok);
        println!("n {n}: lu_factor {total:.3} s, longest between polls {longest:.3} s");
    }
}

/// Wall time against faer's one-call LU at harmonic-balance sizes:
/// `cargo test --release -p ballbal-core --features studies blocked_lu_timing -- --ignored
/// --nocapture`.
#[test]
#[ignore]
fn blocked_lu_timing() {
    // BLU_N / BLU_ONLY (blocked | faer): one size, one method (for callgrind).
    let sizes: Vec<usize> =
        std::env::var("BLU_N").map_or(vec![1024, 2048, 4105], |v| vec![v.parse().unwrap()]);
    let only = std::env::var("BLU_ONLY").unwrap_or_default();
    for n in sizes {
        let a = matrix(n);
        let t = std::time::Instant::now();
        if only != "faer" {
            let _ = BlockedLu::factor(a.clone()).unwrap();
        }
        let blocked = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        if only != "blocked" {
            let _ = a.partial_piv_lu();
        }
        let faer = t.elapsed().as_secs_f64();
        println!(
            "n {n}: blocked {blocked:.3} s, faer {faer:.3} s, ratio {:.2}",
            blocked / faer
        );
    }
}
