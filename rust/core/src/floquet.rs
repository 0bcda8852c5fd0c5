//! Floquet stability of a harmonic-balance solution.
//!
//! The linearisation `M xi'' + C xi' + K xi = 0` is taken about the Fourier series
//! itself (values and derivatives from the series, no re-integration of the nonlinear
//! system); the `2d x 2d` fundamental matrix is integrated from the identity over one
//! period with the core's Dormand–Prince RK45, and faer gives the monodromy matrix's
//! eigenvalues.

use crate::error::Result;
use crate::hb::HbSolution;
use crate::linalg::eigenvalues;
use crate::model::Dynamics;
use crate::ode::{Dopri5, Options};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stability {
    Stable,
    Unstable,
    /// The largest non-trivial modulus is within the accuracy margin of 1.
    Undetermined,
}

impl Stability {
    pub fn as_str(&self) -> &'static str {
        match self {
            Stability::Stable => "stable",
            Stability::Unstable => "unstable",
            Stability::Undetermined => "undetermined",
        }
    }
}

#[derive(Debug, Clone)]
pub struct FloquetOptions {
    pub rtol: f64,
    pub atol: f64,
    /// Least margin around modulus 1 for a definite verdict; the trivial multiplier's
    /// error widens it, since it measures how accurate the whole computation is.
    pub margin: f64,
    /// Step budget of the monodromy integration: a very long period (omega near 0, where
    /// a rotating branch ends) would otherwise run for minutes; past it the analysis
    /// fails with a message and the verdict is undetermined.
    pub max_steps: usize,
}

impl Default for FloquetOptions {
    fn default() -> Self {
        FloquetOptions {
            rtol: 1e-8,
            atol: 1e-10,
            margin: 1e-6,
            max_steps: 200_000,
        }
    }
}

#[derive(Debug, Clone)]
pub struct Floquet {
    /// All multipliers `(re, im)`, largest modulus first.
    pub multipliers: Vec<(f64, f64)>,
    /// Index in `multipliers` of the trivial one (closest to 1).
    pub trivial: usize,
    /// `|lambda_trivial - 1|`.
    pub trivial_error: f64,
    /// Largest modulus among the non-trivial multipliers.
    pub max_modulus: f64,
    pub stability: Stability,
    pub steps: usize,
    pub rhs_evals: usize,
}

/// Monodromy matrix (row-major `2d x 2d`) of the linearisation about `sol`.
pub fn monodromy<D: Dynamics + ?Sized>(
    model: &D,
    sol: &HbSolution,
    opts: &FloquetOptions,
) -> Result<(Vec<f64>, usize, usize)> {
    let d = model.ndof();
    let n2 = 2 * d;
    let om = sol.omega;
    let period = sol.period();
    let mut y0 = vec![0.0; n2 * n2];
    for i in 0..n2 {
        y0[i * n2 + i] = 1.0;
    }
    let (mut q, mut qt, mut qtt) = (vec![0.0; d], vec![0.0; d], vec![0.0; d]);
    let (mut v, mut a) = (vec![0.0; d], vec![0.0; d]);
    let (mut k, mut c, mut m) = (vec![0.0; d * d], vec![0.0; d * d], vec![0.0; d * d]);
    let mut cols = vec![0.0; 2 * d * d];
    let rhs = |t: f64, y: &[f64], dy: &mut [f64]| {
        sol.eval(om * t, &mut q, &mut qt, &mut qtt);
        for j in 0..d {
            v[j] = om * qt[j];
            a[j] = om * om * qtt[j];
        }
        model.jacobians(t, &q, &v, &a, &mut k, &mut c, &mut m);
        // Bottom half of A = [-M^-1 K, -M^-1 C], as 2d columns of length d.
        for j in 0..d {
            for i in 0..d {
                cols[j * d + i] = -k[i * d + j];
                cols[(d + j) * d + i] = -c[i * d + j];
            }
        }
        model.solve_mass_columns(t, &q, &mut cols);
        // dPhi = A Phi; the top half of A is [0 I], so those rows just copy.
        dy[..d * n2].copy_from_slice(&y[d * n2..]);
        for i in 0..d {
            let out = &mut dy[(d + i) * n2..(d + i + 1) * n2];
            out.fill(0.0);
            for kk in 0..n2 {
                let aik = cols[kk * d + i];
                let yrow = &y[kk * n2..(kk + 1) * n2];
                for (o, yv) in out.iter_mut().zip(yrow) {
                    *o += aik * yv;
                }
            }
        }
    };
    let ode_opts = Options {
        max_steps: opts.max_steps,
        ..Options::new(opts.rtol, opts.atol)
    };
    let mut solver = Dopri5::new(n2 * n2);
    let (_, phi, stats) = solver.integrate(rhs, 0.0, &y0, period, &ode_opts, |_, _, _| true)?;
    Ok((phi, stats.accepted, stats.rhs_evals))
}

/// Floquet multipliers and the stability verdict of a harmonic-balance solution.
pub fn floquet<D: Dynamics + ?Sized>(
    model: &D,
    sol: &HbSolution,
    opts: &FloquetOptions,
) -> Result<Floquet> {
    let (phi, steps, evals) = monodromy(model, sol, opts)?;
    let n2 = 2 * model.ndof();
    let mut ev = eigenvalues(&phi, n2).ok_or_else(|| {
        crate::Error::Integration("eigenvalues of the monodromy matrix did not converge".into())
    })?;
    ev.sort_by(|a, b| b.0.hypot(b.1).total_cmp(&a.0.hypot(a.1)));
    let (trivial, trivial_error) = ev
        .iter()
        .enumerate()
        .map(|(i, z)| (i, (z.0 - 1.0).hypot(z.1)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    let max_modulus = ev
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != trivial)
        .map(|(_, z)| z.0.hypot(z.1))
        .fold(0.0, f64::max);
    let margin = opts.margin.max(trivial_error);
    let stability = if max_modulus < 1.0 - margin {
        Stability::Stable
    } else if max_modulus > 1.0 + margin {
        Stability::Unstable
    } else {
        Stability::Undetermined
    };
    Ok(Floquet {
        multipliers: ev,
        trivial,
        trivial_error,
        max_modulus,
        stability,
        steps,
        rhs_evals: evals,
    })
}
