//! Equilibria of scenes: the balanced state that continues the planar perfect balance
//! (followed from zero spring stiffness), and the dispatch to the equilibrium searches
//! by what the scene switches on. Analysis of a model, kept out of the model.

use crate::equilibria::{
    analyse_all, analyse_model, equal_balls, equilibria, equilibria_in_track_order, equilibria_of,
    newton_static, Equilibrium, EquilibriumKind,
};
use crate::model::assembly::Assembly;
use crate::model::{Dynamics, Scene};
use std::f64::consts::PI;

/// The balanced state and its stability (Rezaee et al.'s (2017) "stable balanced region"): the
/// equilibrium that continues the planar balancer's perfect balance (`x = y = 0`,
/// balls cancelling the unbalance) to this scene. Springs whose rest spacing differs
/// from the balancing positions shift it to a nearly balanced state with a residual
/// whirl `hypot(x, y)`; it is followed from zero spring stiffness in steps. `None`
/// when the balls cannot balance the disk or the continuation fails.
pub fn balanced_state(sc: &Scene) -> Option<Equilibrium> {
    let q = balanced_q(sc)?;
    let kind = if sc.springs > 0.0 {
        EquilibriumKind::Balanced
    } else {
        EquilibriumKind::PerfectBalance
    };
    Some(analyse_model(sc, &q, kind, sc.springs == 0.0))
}

/// The balanced state's coordinates, unanalysed (see [`balanced_state`]).
fn balanced_q(sc: &Scene) -> Option<Vec<f64>> {
    if sc.time_dependence().is_some() {
        return None;
    }
    let p = &sc.planar;
    let (n, o) = (p.n_balls(), sc.first_ball());
    // Planar perfect balance: equal pairs have a closed form, otherwise Newton from
    // balls fanned out opposite the unbalance.
    let mut q = vec![0.0; n + 2];
    if n == 2 && p.eta[0] == p.eta[1] {
        if p.eta[0] < 0.5 {
            return None;
        }
        let b = (-1.0 / (2.0 * p.eta[0])).acos();
        // balls in track order, b_1 < b_2 < b_1 + 2 pi: springs unwound
        q[2] = b;
        q[3] = 2.0 * PI - b;
    } else {
        for i in 0..n {
            q[2 + i] = PI + 1.6 * (i as f64 - (n as f64 - 1.0) / 2.0) / n as f64;
        }
        q = newton_static(p, &q)?;
        if q[0].hypot(q[1]) > 1e-8 {
            return None;
        }
    }
    let mut start = vec![0.0; sc.ndof()];
    start[o..].copy_from_slice(&q[2..]);
    if sc.springs > 0.0 {
        spring_homotopy(sc, start)
    } else {
        newton_static(sc, &start)
    }
}

/// All equilibria found, each analysed, for an autonomous scene (empty otherwise).
/// Without springs as for the planar balancer; with springs those with the balls in
/// track order (see [`equilibria_in_track_order`]), the one that continues the
/// perfect balance (see [`balanced_state`]) of kind `"balanced"`.
pub fn scene_equilibria(sc: &Scene) -> Vec<Equilibrium> {
    if sc.time_dependence().is_some() {
        return vec![];
    }
    let p = &sc.planar;
    let equal = equal_balls(p);
    if sc.springs == 0.0 {
        // The closed forms and lattice of `equilibria` are the planar disk's on the
        // isotropic support: any other assembly gets the general search.
        return match sc.model() {
            Assembly::Planar(_) => equilibria(p),
            _ => equilibria_of(sc, equal, true),
        };
    }
    let balanced = balanced_q(sc);
    let extra: Vec<Vec<f64>> = balanced.iter().cloned().collect();
    let mut found = equilibria_in_track_order(sc, equal, &extra);
    if let Some(b) = &balanced {
        if let Some(f) = found
            .iter_mut()
            .find(|(q, _)| q.iter().zip(b).all(|(u, v)| (u - v).abs() < 1e-6))
        {
            f.1 = EquilibriumKind::Balanced;
        }
    }
    analyse_all(sc, found, false)
}

/// Newton along spring stiffness `0 -> sc.springs`, halving steps that fail.
fn spring_homotopy(sc: &Scene, mut q: Vec<f64>) -> Option<Vec<f64>> {
    let mut at: f64 = 0.0;
    let mut step: f64 = 0.125;
    while at < 1.0 {
        let next = (at + step).min(1.0);
        let mut partial = sc.clone();
        partial.springs = sc.springs * next;
        partial.reassemble();
        match newton_static(&partial, &q) {
            // a continuation step must not jump to another winding of the springs
            Some(qn) if qn.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1.0) => {
                q = qn;
                at = next;
                step = (step * 2.0).min(0.25);
            }
            _ => {
                step /= 2.0;
                if step < 1e-6 {
                    return None;
                }
            }
        }
    }
    Some(q)
}
