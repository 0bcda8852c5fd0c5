//! The infinitely long bearing (circumferential flow only): closed-form pressure, force by
//! quadrature.
//!
//! With `t = theta - phi`, `H = 1 - eps cos t` and `g = A sin t + B cos t` as in [`super::short`],
//! `d/dt (H^3 dP/dt) = g` integrates to `H^3 P' = -A cos t + B sin t + C`; periodicity of `P`
//! (`int cos t / H^3 = 3 pi eps / s^5`, `int 1/H^3 = pi (2 + eps^2) / s^5`, `s^2 = 1 - eps^2`)
//! fixes `C = 3 A eps / (2 + eps^2)`. With the gauge `P = 0` at the widest film (`t = pi`,
//! Sommerfeld's convention):
//!
//! ```text
//! P = -A sin t (2 - eps cos t) / ((2 + eps^2) H^2)  -  B (1 + cos t)(1 + eps + H) / (2 H^2 (1 + eps)^2)
//! ```
//!
//! (the first term is Sommerfeld's `6 eps sin a (2 + eps cos a)/((2 + eps^2)(1 + eps cos a)^2)`
//! with `a = t - pi` for the steady journal, `A = 6 eps`). Static forces per unit length are
//! Sommerfeld's `F_t = 12 pi eps / ((2 + eps^2) s)`, `F_r = 0`, and with the half-Sommerfeld clip
//! Gümbel's `F_r = 12 eps^2 / ((2 + eps^2)(1 - eps^2))`, `F_t = 6 pi eps / ((2 + eps^2) s)`.
//! Full film: periodic trapezoid (geometric convergence). Clipped film: the sign changes of
//! `P` are bracketed on 256 samples, refined by bisection, and each positive arc integrated by
//! 8 panels of 16-point Gauss–Legendre.

use super::short::gauss_legendre16;
use super::{Cavitation, FilmForce, JournalState, LineOfCentres, PressureField};
use std::f64::consts::PI;

/// Long-bearing film force (per unit length, i.e. in units `F_S`).
pub fn force(lambda: f64, cav: Cavitation, s: &JournalState, want_field: bool) -> FilmForce {
    let frame = LineOfCentres::of(s);
    let (eps, phi, big_a, big_b) = (frame.eps, frame.phi, frame.big_a, frame.big_b);
    let p = |t: f64| pressure(eps, big_a, big_b, t);
    let n = 256;
    let dt = 2.0 * PI / n as f64;
    let (mut fr_out, mut ft, mut p_max) = (0.0, 0.0, 0.0_f64);
    let samples: Vec<f64> = (0..=n).map(|i| p(i as f64 * dt)).collect();
    for v in &samples {
        p_max = p_max.max(*v);
    }
    if cav == Cavitation::None {
        for (i, v) in samples.iter().take(n).enumerate() {
            let (st, ct) = (i as f64 * dt).sin_cos();
            fr_out -= v * ct * dt;
            ft -= v * st * dt;
        }
    } else {
        let (nodes, weights) = gauss_legendre16();
        let mut arc = |t1: f64, t2: f64| {
            let panels = 8;
            let hp = (t2 - t1) / panels as f64;
            for k in 0..panels {
                let c = t1 + (k as f64 + 0.5) * hp;
                for (x, w) in nodes.iter().zip(weights) {
                    let t = c + 0.5 * hp * x;
                    let v = p(t).max(0.0) * w * 0.5 * hp;
                    let (st, ct) = t.sin_cos();
                    fr_out -= v * ct;
                    ft -= v * st;
                }
            }
        };
        // Break points: 0, 2 pi and every sign change, each refined by bisection.
        let mut breaks = vec![0.0];
        for i in 0..n {
            let (u, v) = (samples[i], samples[i + 1]);
            if (u > 0.0) != (v > 0.0) {
                let (mut lo, mut hi) = (i as f64 * dt, (i + 1) as f64 * dt);
                let up = u > 0.0;
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    if (p(mid) > 0.0) == up {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                breaks.push(0.5 * (lo + hi));
            }
        }
        breaks.push(2.0 * PI);
        for w in breaks.windows(2) {
            if p(0.5 * (w[0] + w[1])) > 0.0 {
                arc(w[0], w[1]);
            }
        }
    }
    let (fx, fy) = frame.to_fixed(fr_out, ft);
    let mut f = FilmForce::from_xy(s, fx, fy, p_max);
    if want_field {
        let (nt, nz) = (128, 32);
        let theta: Vec<f64> = (0..nt)
            .map(|i| (i as f64 + 0.5) * 2.0 * PI / nt as f64)
            .collect();
        let zeta: Vec<f64> = (0..nz)
            .map(|j| -lambda + (j as f64 + 0.5) * 2.0 * lambda / nz as f64)
            .collect();
        let mut values = Vec::with_capacity(nt * nz);
        for th in &theta {
            let v = p(th - phi);
            let v = if cav == Cavitation::None {
                v
            } else {
                v.max(0.0)
            };
            values.extend(std::iter::repeat_n(v, nz));
        }
        f.pressure = Some(PressureField {
            n_theta: nt,
            n_zeta: nz,
            theta,
            zeta,
            values,
        });
    }
    f
}

/// The long-bearing pressure at line-of-centres angle `t` (see the module documentation).
pub fn pressure(eps: f64, big_a: f64, big_b: f64, t: f64) -> f64 {
    let (st, ct) = t.sin_cos();
    let h = 1.0 - eps * ct;
    let h2 = h * h;
    -big_a * st * (2.0 - eps * ct) / ((2.0 + eps * eps) * h2)
        - big_b * (1.0 + ct) * (1.0 + eps + h) / (2.0 * h2 * (1.0 + eps) * (1.0 + eps))
}
