//! Research studies of the bifurcation wing: measurement runs that print what a branch or
//! curve does at settings given through the environment, not tests of behaviour. They
//! are built only with the `studies` feature and run by hand, e.g.
//! `cargo test --release -p ballbal-core --features studies explore_branch -- --ignored
//! --nocapture`.

use super::po_branch::tests::opts;
use super::po_branch::{periodic_branch, PoEventKind};
use super::po_curves::tests::{curve_at_event, curve_opts, whirl_branch};
use super::po_curves::PoCurveKind;
use crate::periodic::periodic;
use crate::Planar;

/// Measurement: `cargo test --release -p ballbal-core --features studies explore_branch -- --ignored
/// --nocapture`.
#[test]
#[ignore]
fn explore_branch() {
    let zb: f64 = std::env::var("ZB")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.05);
    let eta: f64 = std::env::var("ETA")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1.0);
    let om: f64 = std::env::var("OM")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1.2);
    let fwd = std::env::var("FWD").as_deref() != Ok("0");
    let n: usize = std::env::var("N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(8);
    let p = Planar::new(0.2, 0.05, &[zb], 50.0, om, &[eta, eta]).unwrap();
    let mut o = opts(n, 0.5, 3.0, fwd);
    o.arc.max_points = 400;
    let start = periodic(&p, &[true, true], None, &o.periodic);
    println!("start {:?} omega {}", start.sol.status, start.sol.omega);
    let t = std::time::Instant::now();
    let b = periodic_branch(&p, "Omega", &start.sol, &o).unwrap();
    println!(
        "{} points in {:?}, stop {}",
        b.points.len(),
        t.elapsed(),
        b.stop
    );
    for pt in &b.points {
        let m = pt.multipliers().map(|m| {
            m.iter()
                .map(|z| format!("{:.3}{:+.3}i", z.0, z.1))
                .collect::<Vec<_>>()
                .join(" ")
        });
        println!(
            "p={:.6} w={:.5} {} {} lp={:+.2e} bp={:+.2e} pd={:?} ns={:?} ev={:?} | {}",
            pt.p,
            pt.omega(),
            pt.result.sol.status.as_str(),
            pt.stability().as_str(),
            pt.tests.lp,
            pt.tests.bp,
            pt.tests.pd.map(|v| (v * 1e3).round() / 1e3),
            pt.tests.ns.map(|v| (v * 1e3).round() / 1e3),
            pt.events,
            m.unwrap_or_default()
        );
    }
    for e in &b.events {
        println!(
            "EVENT {} p={:.9} test={:.3e} idx={} w={}",
            e.kind.as_str(),
            e.p,
            e.test,
            e.index,
            e.point.omega()
        );
    }
}

/// Measurement: `cargo test --release -p ballbal-core --features studies explore_ns -- --ignored
/// --nocapture`.
#[test]
#[ignore]
fn explore_ns() {
    let n: usize = std::env::var("N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(6);
    let t = std::time::Instant::now();
    let (sc, b) = whirl_branch(n, 0.05);
    println!(
        "{} points {:?} stop {}",
        b.points.len(),
        t.elapsed(),
        b.stop
    );
    for e in &b.events {
        println!(
            "EVENT {} p={:.9} w={}",
            e.kind.as_str(),
            e.p,
            e.point.omega()
        );
    }
    let mut co = curve_opts(n, (0.0, 1.0), (0.3, 1.0), 40);
    (co.arc.ds, co.arc.ds_max) = (0.01, 0.05);
    let c = curve_at_event(
        &sc,
        &b,
        PoEventKind::NeimarkSacker,
        ["zeta", "rho"],
        PoCurveKind::NeimarkSacker,
        &co,
    );
    println!("curve {:?} {:?}", c.stop, t.elapsed());
    for pt in &c.points {
        let m = &pt.result.floquet.as_ref().expect("multipliers").multipliers;
        let ns = m
            .iter()
            .filter(|z| z.1 > 1e-9)
            .map(|z| format!("{:.6}@{:.4}", z.0.hypot(z.1), z.1.atan2(z.0)))
            .collect::<Vec<_>>()
            .join(" ");
        println!(
            "zeta={:.6} rho={:.6} theta={:.5} g={:.1e} w={:.5} {:?} | {}",
            pt.p[0],
            pt.p[1],
            pt.theta.unwrap(),
            pt.g,
            pt.result.sol.omega,
            pt.tests,
            ns
        );
    }
    for s in &c.special {
        println!("SPECIAL {} {:?} row {}", s.kind, s.p, s.row);
    }
}
