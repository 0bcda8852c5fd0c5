//! Ocvirk's short bearing with squeeze, in closed form (no solve).
//!
//! Derivation. Dropping the circumferential flow, `d/dzeta (H^3 dP/dzeta) = g(theta)` with
//! `g = 6 dH/dtheta + 12 dH/dtau`, and `H` independent of `zeta`, so with `P(+-lambda) = 0`
//!
//! ```text
//! P(theta, zeta) = g / (2 H^3) (zeta^2 - lambda^2),   integral over zeta = -(2 lambda^3 / 3) g / H^3.
//! ```
//!
//! It is positive where `g < 0`. With `H = 1 - x cos theta - y sin theta`,
//! `dH/dtau = -(x' cos theta + y' sin theta)`:
//! `g = a sin theta + b cos theta`, `a = 6 x - 12 y'`, `b = -6 y - 12 x'`.
//! In the line-of-centres angle `t = theta - phi` (`x + i y = eps e^{i phi}`), `H = 1 - eps cos t`
//! and `g = A sin t + B cos t` with `A = a cos phi - b sin phi`, `B = a sin phi + b cos phi`
//! (no division by `eps`, so the centred journal with a velocity is fine). Writing
//! `g = R sin(t + chi)`, `chi = atan2(B, A)`, the half-Sommerfeld film is the interval
//! `t in (pi - chi, 2 pi - chi)` of length `pi`. The force `F = -(1/2 lambda) int int P n`, in
//! units `F_S`, with `n . e_r = cos t`, `n . e_t = sin t`:
//!
//! ```text
//! F . e_r = (lambda^2/3) (A S_sc + B S_cc),   F . e_t = (lambda^2/3) (A S_ss + B S_sc),
//! S_cc = int cos^2 t / H^3,  S_ss = int sin^2 t / H^3,  S_sc = int sin t cos t / H^3.
//! ```
//!
//! With `I_n = int dt / H^n`, `cos t = (1 - H)/eps` gives `S_cc = (I_3 - 2 I_2 + I_1)/eps^2`,
//! `S_ss = I_3 - S_cc`, `S_sc = [(1/H - 1/(2 H^2)) / eps^2]`, and differentiating
//! `sin t / H^m` gives the recurrence
//! `m (1 - eps^2) I_{m+1} = eps sin t / H^m + (2m - 1) I_m - (m - 1) I_{m-1}`, `I_1 = (2/sqrt(1-eps^2)) atan(sqrt((1+eps)/(1-eps)) tan(t/2))` (unwrapped).
//! Those cancel like `1/eps^2` for small `eps`; below `eps = 0.1` the three integrals are
//! taken by 16-point Gauss–Legendre instead, exact to round-off there (the integrand's poles
//! are at `Im t = acosh(1/eps) > 2.99`, the error is below `4^-32`).
//!
//! For `x' = y' = 0` this reduces to Ocvirk's `F_r = F0 eps^2/(1-eps^2)^2`,
//! `F_t = F0 pi eps/(4 (1-eps^2)^(3/2))`, `F0 = (2 lambda)^2 F_S`; the tests check both that
//! and a direct quadrature of the pressure above.

use super::{Cavitation, FilmForce, JournalState, LineOfCentres, PressureField};
use std::f64::consts::PI;
use std::sync::OnceLock;

const SMALL_EPS: f64 = 0.1;

/// Short-bearing film force.
pub fn force(lambda: f64, cav: Cavitation, s: &JournalState, want_field: bool) -> FilmForce {
    let frame = LineOfCentres::of(s);
    let (eps, big_a, big_b) = (frame.eps, frame.big_a, frame.big_b);
    let (s_cc, s_ss, s_sc) = if cav == Cavitation::None {
        full_period(eps)
    } else if big_a == 0.0 && big_b == 0.0 {
        (0.0, 0.0, 0.0)
    } else {
        let chi = big_b.atan2(big_a);
        interval(eps, PI - chi, 2.0 * PI - chi)
    };
    let k = lambda * lambda / 3.0;
    let fr_out = k * (big_a * s_sc + big_b * s_cc);
    let ft = k * (big_a * s_ss + big_b * s_sc);
    let (fx, fy) = frame.to_fixed(fr_out, ft);
    let clip = cav != Cavitation::None;
    let p_mid = |t: f64| {
        let h = 1.0 - eps * t.cos();
        let p = -lambda * lambda * (big_a * t.sin() + big_b * t.cos()) / (2.0 * h * h * h);
        if clip {
            p.max(0.0)
        } else {
            p
        }
    };
    // The peak is on the mid-plane: 64 samples (sin and cos by rotation, no libm calls), then
    // one parabola through the best sample and its neighbours.
    let n = 64;
    let dt = 2.0 * PI / n as f64;
    let (sd, cd) = dt.sin_cos();
    let (mut st, mut ct) = (0.0_f64, 1.0_f64);
    let (mut best, mut ib) = (f64::NEG_INFINITY, 0);
    for i in 0..n {
        let h = 1.0 - eps * ct;
        let v = -(big_a * st + big_b * ct) / (h * h * h);
        if v > best {
            best = v;
            ib = i;
        }
        (st, ct) = (st * cd + ct * sd, ct * cd - st * sd);
    }
    let t0 = ib as f64 * dt;
    let (pm, p0, pp) = (p_mid(t0 - dt), p_mid(t0), p_mid(t0 + dt));
    let den = pm - 2.0 * p0 + pp;
    let p_max = if den < 0.0 {
        let d = 0.5 * (pm - pp) / den;
        p_mid(t0 + d * dt).max(p0)
    } else {
        p0
    };
    let mut f = FilmForce::from_xy(s, fx, fy, p_max.max(0.0));
    if want_field {
        f.pressure = Some(field(lambda, clip, s, 128, 32));
    }
    f
}

/// The short-bearing pressure on cell centres (used for plotting and by the tests).
pub fn field(
    lambda: f64,
    clip: bool,
    s: &JournalState,
    n_theta: usize,
    n_zeta: usize,
) -> PressureField {
    let theta: Vec<f64> = (0..n_theta)
        .map(|i| (i as f64 + 0.5) * 2.0 * PI / n_theta as f64)
        .collect();
    let zeta: Vec<f64> = (0..n_zeta)
        .map(|j| -lambda + (j as f64 + 0.5) * 2.0 * lambda / n_zeta as f64)
        .collect();
    let mut values = Vec::with_capacity(n_theta * n_zeta);
    for &th in &theta {
        let (st, ct) = th.sin_cos();
        let h = 1.0 - s.x * ct - s.y * st;
        let g = (6.0 * s.x - 12.0 * s.vy) * st + (-6.0 * s.y - 12.0 * s.vx) * ct;
        for &z in &zeta {
            let p = g / (2.0 * h * h * h) * (z * z - lambda * lambda);
            values.push(if clip { p.max(0.0) } else { p });
        }
    }
    PressureField {
        n_theta,
        n_zeta,
        theta,
        zeta,
        values,
    }
}

/// `(S_cc, S_ss, S_sc)` over `[t1, t2]`.
fn interval(eps: f64, t1: f64, t2: f64) -> (f64, f64, f64) {
    if eps < SMALL_EPS {
        let (nodes, weights) = gauss_legendre16();
        let (c, r) = (0.5 * (t1 + t2), 0.5 * (t2 - t1));
        let (mut cc, mut ss, mut sc) = (0.0, 0.0, 0.0);
        for (x, w) in nodes.iter().zip(weights) {
            let t = c + r * x;
            let (st, ct) = t.sin_cos();
            let h = 1.0 - eps * ct;
            let wi = w * r / (h * h * h);
            cc += wi * ct * ct;
            ss += wi * st * st;
            sc += wi * st * ct;
        }
        return (cc, ss, sc);
    }
    let (i1a, i2a, i3a) = antiderivatives(eps, t1);
    let (i1b, i2b, i3b) = antiderivatives(eps, t2);
    let (i1, i2, i3) = (i1b - i1a, i2b - i2a, i3b - i3a);
    let e2 = eps * eps;
    let cc = (i3 - 2.0 * i2 + i1) / e2;
    let ss = i3 - cc;
    let j = |t: f64| {
        let h = 1.0 - eps * t.cos();
        (1.0 / h - 0.5 / (h * h)) / e2
    };
    (cc, ss, j(t2) - j(t1))
}

/// Full-period integrals (no cavitation).
fn full_period(eps: f64) -> (f64, f64, f64) {
    if eps < SMALL_EPS {
        // The periodic trapezoid rule converges geometrically; 32 points are exact to round-off here.
        let n = 32;
        let dt = 2.0 * PI / n as f64;
        let (mut cc, mut ss) = (0.0, 0.0);
        for i in 0..n {
            let (st, ct) = (i as f64 * dt).sin_cos();
            let h = 1.0 - eps * ct;
            let w = dt / (h * h * h);
            cc += w * ct * ct;
            ss += w * st * st;
        }
        return (cc, ss, 0.0);
    }
    let s2 = 1.0 - eps * eps;
    let s = s2.sqrt();
    let j1 = 2.0 * PI / s;
    let j2 = j1 / s2;
    let j3 = PI * (2.0 + eps * eps) / (s2 * s2 * s);
    let cc = (j3 - 2.0 * j2 + j1) / (eps * eps);
    (cc, j3 - cc, 0.0)
}

/// Continuous antiderivatives `(I_1, I_2, I_3)` of `1 / (1 - eps cos t)^n`.
fn antiderivatives(eps: f64, t: f64) -> (f64, f64, f64) {
    let s2 = 1.0 - eps * eps;
    let s = s2.sqrt();
    let k = ((1.0 + eps) / (1.0 - eps)).sqrt();
    // t/2 = m pi + r with r in [-pi/2, pi/2): atan(k tan r) + m pi is continuous in t.
    let m = (t / (2.0 * PI)).round();
    let r = 0.5 * t - m * PI;
    let i1 = 2.0 / s * ((k * r.tan()).atan() + m * PI);
    let (st, ct) = t.sin_cos();
    let h = 1.0 - eps * ct;
    let i2 = (eps * st / h + i1) / s2;
    let i3 = (eps * st / (h * h) + 3.0 * i2 - i1) / (2.0 * s2);
    (i1, i2, i3)
}

/// 16-point Gauss–Legendre nodes and weights on [-1, 1] (Newton on `P_16`).
pub(crate) fn gauss_legendre16() -> &'static ([f64; 16], [f64; 16]) {
    static GL: OnceLock<([f64; 16], [f64; 16])> = OnceLock::new();
    GL.get_or_init(gauss_legendre::<16>)
}

pub(crate) fn gauss_legendre<const N: usize>() -> ([f64; N], [f64; N]) {
    let mut x = [0.0; N];
    let mut w = [0.0; N];
    for i in 0..N {
        let mut z = (PI * (i as f64 + 0.75) / (N as f64 + 0.5)).cos();
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=N {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let dp = N as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                let (mut q0, mut q1) = (1.0, z);
                for k in 2..=N {
                    let q2 = ((2 * k - 1) as f64 * z * q1 - (k - 1) as f64 * q0) / k as f64;
                    q0 = q1;
                    q1 = q2;
                }
                let dq = N as f64 * (z * q1 - q0) / (z * z - 1.0);
                w[i] = 2.0 / ((1.0 - z * z) * dq * dq);
                break;
            }
        }
        x[i] = z;
    }
    (x, w)
}
