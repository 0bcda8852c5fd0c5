//! Timings, instruction counts and force dumps of the film solvers: measuring aids,
//! not checks (results in docs/measurements.md). Compiled only with the `studies`
//! feature, and `#[ignore]`d: run one by name with `--ignored --nocapture`.

use super::tests::{finite, grooved, herringbone, kind, solver, SolverKindRef};
use super::*;

/// Time per force evaluation: `cargo test --release -p ballbal-core --features studies
/// bearing_bench -- --ignored --nocapture`.
#[test]
#[ignore]
fn bearing_bench() {
    use std::time::Instant;
    let st = |k: usize| JournalState {
        x: 0.4 + 1e-3 * (k % 7) as f64,
        y: -0.3,
        vx: 0.01,
        vy: 0.02,
        tau: 0.01 * k as f64,
    };
    let run = |label: &str, s: &mut FilmSolver, n: usize| {
        let mut acc = 0.0;
        s.force(&st(0), false).unwrap();
        let t0 = Instant::now();
        for k in 0..n {
            acc += s.force(&st(k), false).unwrap().fx;
        }
        let dt = t0.elapsed().as_secs_f64() / n as f64;
        println!(
            "{label}: {:.3} us per force evaluation ({acc:.3})",
            dt * 1e6
        );
    };
    run(
        "short",
        &mut solver(&Bearing::plain(0.5, FilmModel::Short)),
        1_000_000,
    );
    run(
        "long (half-Sommerfeld)",
        &mut solver(&Bearing::plain(0.5, FilmModel::Long)),
        20_000,
    );
    run(
        "plain finite 128 x 32",
        &mut finite(1.0, 128, 32, Cavitation::HalfSommerfeld),
        5_000,
    );
    run(
        "grooved sleeve 256 x 32",
        &mut grooved(1.0, 256, 32, herringbone(1.0, GrooveSide::Sleeve)),
        300,
    );
    let mut reuse = grooved(1.0, 256, 32, herringbone(1.0, GrooveSide::Sleeve));
    reuse.set_factor_reuse(Some(1e-10));
    run("grooved sleeve 256 x 32, old factor + CG", &mut reuse, 300);
    run(
        "grooved journal 256 x 32",
        &mut grooved(1.0, 256, 32, herringbone(1.0, GrooveSide::Journal)),
        300,
    );
    run(
        "plain finite 128 x 32 Reynolds",
        &mut finite(1.0, 128, 32, Cavitation::Reynolds),
        100,
    );
}

/// Instruction counts per force evaluation under callgrind, e.g.
/// `valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*profile_force*'
/// target/release/deps/ballbal_core-* bearing_profile --ignored` (built with `--features
/// studies`) with `BEARING_PROFILE`
/// one of `plain`, `grooved`, `reuse`, `journal`, `linearise`.
#[test]
#[ignore]
fn bearing_profile() {
    #[inline(never)]
    fn profile_force(s: &mut FilmSolver, st: &JournalState) -> f64 {
        s.force(st, false).unwrap().fx
    }
    #[inline(never)]
    fn profile_force_linearise(s: &mut FilmSolver, st: &JournalState) -> f64 {
        s.force_derivatives(st).unwrap().unwrap().1[0][0]
    }
    let which = std::env::var("BEARING_PROFILE").unwrap_or_else(|_| "plain".into());
    let (mut s, n) = match which.as_str() {
        "plain" => (finite(1.0, 128, 32, Cavitation::HalfSommerfeld), 200),
        "grooved" | "linearise" => (
            grooved(1.0, 256, 32, herringbone(1.0, GrooveSide::Sleeve)),
            10,
        ),
        "reuse" => {
            let mut s = grooved(1.0, 256, 32, herringbone(1.0, GrooveSide::Sleeve));
            s.set_factor_reuse(Some(1e-10));
            (s, 50)
        }
        "journal" => (
            grooved(1.0, 256, 32, herringbone(1.0, GrooveSide::Journal)),
            10,
        ),
        other => panic!("unknown profile {other}"),
    };
    // A stretch of a whirl orbit, 0.01 rad of the journal per step.
    let st = |k: usize| {
        let t = 0.01 * k as f64;
        JournalState {
            x: 0.4 * t.cos(),
            y: 0.4 * t.sin() - 0.1,
            vx: -0.2 * t.sin(),
            vy: 0.2 * t.cos(),
            tau: t,
        }
    };
    let mut acc = 0.0;
    for k in 0..n {
        acc += if which == "linearise" {
            profile_force_linearise(&mut s, &st(k))
        } else {
            profile_force(&mut s, &st(k))
        };
    }
    let SolverKindRef::Finite(fs) = kind(&mut s) else {
        unreachable!()
    };
    println!(
        "{which}: {n} evaluations ({acc}), {} factorisations, {} CG iterations",
        fs.factorisations, fs.cg_iterations
    );
}

/// Forces and derivatives on a fixed set of bearings and states, written to
/// `$BEARING_DUMP` (for comparing two builds of the solver to round-off).
#[test]
#[ignore]
fn bearing_dump_forces() {
    use std::fmt::Write;
    let path = std::env::var("BEARING_DUMP").expect("BEARING_DUMP names the output file");
    let mut out = String::new();
    let mut g = herringbone(1.3, GrooveSide::Sleeve);
    g.length_fraction = 0.6;
    g.width = 0.3;
    let mut bearings = vec![
        finite(1.0, 128, 32, Cavitation::HalfSommerfeld),
        finite(0.5, 64, 16, Cavitation::None),
        finite(1.0, 64, 16, Cavitation::Reynolds),
        grooved(1.0, 128, 16, herringbone(1.0, GrooveSide::Sleeve)),
        grooved(0.8, 128, 16, herringbone(0.7, GrooveSide::Journal)),
        grooved(1.5, 96, 20, g),
    ];
    let mut gr = Bearing {
        lambda: 1.0,
        grooves: Some(herringbone(1.0, GrooveSide::Sleeve)),
        cavitation: Cavitation::Reynolds,
        model: FilmModel::Finite {
            n_theta: 64,
            n_zeta: 16,
        },
    };
    bearings.push(solver(&gr));
    gr.cavitation = Cavitation::None;
    bearings.push(solver(&gr));
    let states = [
        JournalState::at(0.0, 0.0),
        JournalState {
            x: 0.4,
            y: -0.3,
            vx: 0.1,
            vy: 0.2,
            tau: 0.7,
        },
        JournalState {
            x: -0.7,
            y: 0.2,
            vx: -0.3,
            vy: 0.05,
            tau: 2.1,
        },
        JournalState::at(0.05, 0.9),
    ];
    for (b, s) in bearings.iter_mut().enumerate() {
        for (k, st) in states.iter().enumerate() {
            let f = s.force(st, false).unwrap();
            write!(
                out,
                "{b} {k} F {:.17e} {:.17e} {:.17e}",
                f.fx, f.fy, f.p_max
            )
            .unwrap();
            if let Some((_, d)) = s.force_derivatives(st).unwrap() {
                for row in d {
                    for v in row {
                        write!(out, " {v:.17e}").unwrap();
                    }
                }
            }
            out.push('\n');
        }
    }
    std::fs::write(path, out).unwrap();
}
