//! The longest wait of a cancellation during one film-force call (results in
//! docs/measurements.md). Compiled only with the `studies` feature, and `#[ignore]`d:
//! run by name with `--ignored --nocapture`.

use super::super::*;
use super::tests::{herringbone, moving_state};

/// How long Ctrl-C can wait during one film-force call as `ballbal.bearing.film_force`
/// makes it (a new solver, one force): the call's time and the longest stretch between
/// two cancellation polls. `FILM_GRIDS=1024x128,2048x256 cargo test --release -p
/// ballbal-core --features studies film_cancel_latency -- --ignored --nocapture` (`FILM_CASES`: some of
/// the labels, comma-separated).
#[test]
#[ignore]
fn film_cancel_latency() {
    let grids = std::env::var("FILM_GRIDS").unwrap_or("512x64,1024x128,2048x256".into());
    let grooves = herringbone();
    for g in grids.split(',') {
        let (a, b) = g.split_once('x').expect("grid as NTxNZ");
        let (n_theta, n_zeta): (usize, usize) = (a.parse().unwrap(), b.parse().unwrap());
        let cases = [
            ("plain finite", None, Cavitation::HalfSommerfeld, false),
            (
                "grooved finite",
                Some(grooves),
                Cavitation::HalfSommerfeld,
                false,
            ),
            (
                "grooved finite Reynolds",
                Some(grooves),
                Cavitation::Reynolds,
                false,
            ),
            (
                "narrow groove",
                Some(grooves),
                Cavitation::HalfSommerfeld,
                true,
            ),
        ];
        let only = std::env::var("FILM_CASES").unwrap_or_default();
        for (label, grooves, cavitation, narrow) in cases {
            if !only.is_empty() && !only.split(',').any(|c| label == c) {
                continue;
            }
            let b = Bearing {
                lambda: 1.0,
                grooves,
                cavitation,
                model: if narrow {
                    FilmModel::NarrowGroove { n_theta, n_zeta }
                } else {
                    FilmModel::Finite { n_theta, n_zeta }
                },
            };
            let st = moving_state();
            let (f, total, longest) =
                crate::cancel::gaps::longest(|| b.solver().and_then(|mut s| s.force(&st, false)));
            println!(
                "{label} {n_theta}x{n_zeta}: call {total:.3} s, longest between polls \
                 {longest:.3} s (fx {:.6})",
                f.unwrap().fx
            );
        }
    }
}
