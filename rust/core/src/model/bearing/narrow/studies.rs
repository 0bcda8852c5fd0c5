//! Timing of the narrow-groove film against the resolved one (docs/guide.md quotes it).
//! Compiled only with the `studies` feature, and `#[ignore]`d: run by name with
//! `--ignored --nocapture`.

use super::super::{FilmModel, GrooveSide};
use super::*;

/// `cargo test --release -p ballbal-core --features studies narrow_bench -- --ignored
/// --nocapture`.
#[test]
#[ignore]
fn narrow_bench() {
    use std::time::Instant;
    let g = Grooves {
        count: 16,
        angle: 30f64.to_radians(),
        depth: 1.0,
        width: 0.5,
        length_fraction: 1.0,
        side: GrooveSide::Sleeve,
    };
    for (label, model, n) in [
        (
            "narrow groove 128 x 32",
            FilmModel::NarrowGroove {
                n_theta: 128,
                n_zeta: 32,
            },
            300,
        ),
        (
            "narrow groove 64 x 16",
            FilmModel::NarrowGroove {
                n_theta: 64,
                n_zeta: 16,
            },
            1000,
        ),
        (
            "resolved 16 grooves 256 x 32",
            FilmModel::Finite {
                n_theta: 256,
                n_zeta: 32,
            },
            300,
        ),
    ] {
        let mut s = Bearing {
            lambda: 1.0,
            grooves: Some(g),
            cavitation: Cavitation::HalfSommerfeld,
            model,
        }
        .solver()
        .unwrap();
        let mut acc = 0.0;
        let t0 = Instant::now();
        for k in 0..n {
            let st = JournalState::at(0.4 + 1e-3 * (k % 7) as f64, -0.3);
            acc += s.force(&st, false).unwrap().fx;
        }
        let dt = t0.elapsed().as_secs_f64() / n as f64;
        println!("{label}: {:.1} us per force ({acc:.3})", dt * 1e6);
    }
}
