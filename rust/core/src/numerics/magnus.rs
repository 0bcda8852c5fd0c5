//! Monodromy of a linear periodic system `xi' = A(t) xi` by Magnus integrators on a
//! fixed grid.
//!
//! Along a harmonic-balance orbit `A(t)` is known in closed form (the series and the
//! model's Jacobians), so the fundamental matrix over one step is `exp(Omega)`, with
//! `Omega` the truncated Magnus expansion built from `A` at the Gauss–Legendre nodes of
//! the step; the monodromy is the product of the `K` step exponentials. A constant `A`
//! is integrated exactly whatever the step, so the error depends on how fast `A`
//! varies along the orbit (the frequency `omega` times the harmonics that matter),
//! not on the fast oscillations of the linearisation itself: the slow, long-period
//! orbits that cost the adaptive RK45 thousands of steps need no more steps than fast
//! ones. Sixth order, three nodes per step (Blanes, Casas & Ros, BIT 40 (2000) 434,
//! eq. (3.27)); the step count is doubled until two successive monodromies give the
//! same multipliers to the requested tolerance.

/// `c = a b` for row-major `n x n` matrices. The sizes of the planar balancer and the
/// scenes (state dimensions 4 to 12) get loops of fixed length, which the compiler
/// unrolls and vectorises: the products are most of a Magnus step's cost.
#[inline]
pub fn matmul(a: &[f64], b: &[f64], c: &mut [f64], n: usize) {
    match n {
        4 => matmul_fixed::<4>(a, b, c),
        6 => matmul_fixed::<6>(a, b, c),
        8 => matmul_fixed::<8>(a, b, c),
        10 => matmul_fixed::<10>(a, b, c),
        12 => matmul_fixed::<12>(a, b, c),
        _ => matmul_any(a, b, c, n),
    }
}

#[inline(always)]
fn matmul_fixed<const N: usize>(a: &[f64], b: &[f64], c: &mut [f64]) {
    let (a, b, c) = (&a[..N * N], &b[..N * N], &mut c[..N * N]);
    for i in 0..N {
        let mut row = [0.0f64; N];
        for k in 0..N {
            let aik = a[i * N + k];
            let bk: &[f64; N] = b[k * N..(k + 1) * N].try_into().unwrap();
            for j in 0..N {
                row[j] += aik * bk[j];
            }
        }
        c[i * N..(i + 1) * N].copy_from_slice(&row);
    }
}

fn matmul_any(a: &[f64], b: &[f64], c: &mut [f64], n: usize) {
    c[..n * n].fill(0.0);
    for i in 0..n {
        let ci = &mut c[i * n..(i + 1) * n];
        for k in 0..n {
            let aik = a[i * n + k];
            let bk = &b[k * n..(k + 1) * n];
            for (cv, bv) in ci.iter_mut().zip(bk) {
                *cv += aik * bv;
            }
        }
    }
}

/// `c = a b - b a`.
fn commutator(a: &[f64], b: &[f64], c: &mut [f64], tmp: &mut [f64], n: usize) {
    matmul(a, b, c, n);
    matmul(b, a, tmp, n);
    for (x, y) in c.iter_mut().zip(tmp.iter()) {
        *x -= y;
    }
}

fn norm1(a: &[f64], n: usize) -> f64 {
    (0..n)
        .map(|j| (0..n).map(|i| a[i * n + j].abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// Scratch of [`expm`] for `n x n` matrices.
pub struct ExpmWork {
    n: usize,
    x: Vec<f64>,
    x2: Vec<f64>,
    x3: Vec<f64>,
    x4: Vec<f64>,
    acc: Vec<f64>,
    tmp: Vec<f64>,
}

impl ExpmWork {
    pub fn new(n: usize) -> Self {
        let z = || vec![0.0; n * n];
        ExpmWork {
            n,
            x: z(),
            x2: z(),
            x3: z(),
            x4: z(),
            acc: z(),
            tmp: z(),
        }
    }
}

/// Taylor coefficients `1/k!`, k = 0..=12.
const INV_FACT: [f64; 13] = [
    1.0,
    1.0,
    0.5,
    1.0 / 6.0,
    1.0 / 24.0,
    1.0 / 120.0,
    1.0 / 720.0,
    1.0 / 5040.0,
    1.0 / 40320.0,
    1.0 / 362880.0,
    1.0 / 3628800.0,
    1.0 / 39916800.0,
    1.0 / 479001600.0,
];

/// `out = exp(a)` by scaling and squaring with the degree-12 Taylor polynomial
/// (Paterson–Stockmeyer: six products). The scaled matrix has 1-norm at most 1/2, where
/// the truncated remainder is below `0.5^13 / 13! < 2e-14` relative.
pub fn expm(a: &[f64], out: &mut [f64], w: &mut ExpmWork) {
    let n = w.n;
    let nrm = norm1(a, n);
    let s = if nrm > 0.5 {
        (nrm / 0.5).log2().ceil().max(0.0) as i32
    } else {
        0
    };
    let scale = 0.5f64.powi(s);
    for (x, y) in w.x.iter_mut().zip(a) {
        *x = y * scale;
    }
    matmul(&w.x, &w.x, &mut w.x2, n);
    matmul(&w.x2, &w.x, &mut w.x3, n);
    matmul(&w.x2, &w.x2, &mut w.x4, n);
    // p(X) = B0 + X4 (B1 + X4 (B2 + c12 X4)), B_j = sum_{i<4} c_{4j+i} X^i.
    let block = |j: usize, w: &ExpmWork, dst: &mut [f64]| {
        let c = &INV_FACT[4 * j..4 * j + 4];
        for (idx, o) in dst.iter_mut().enumerate().take(n * n) {
            *o = c[1] * w.x[idx] + c[2] * w.x2[idx] + c[3] * w.x3[idx];
        }
        for i in 0..n {
            dst[i * n + i] += c[0];
        }
    };
    // acc = B2 + c12 X4
    let mut acc = std::mem::take(&mut w.acc);
    let mut tmp = std::mem::take(&mut w.tmp);
    block(2, w, &mut acc);
    for (x, y) in acc.iter_mut().zip(&w.x4) {
        *x += INV_FACT[12] * y;
    }
    for j in [1usize, 0] {
        matmul(&w.x4, &acc, &mut tmp, n);
        block(j, w, &mut acc);
        for (x, y) in acc.iter_mut().zip(&tmp) {
            *x += y;
        }
    }
    for _ in 0..s {
        matmul(&acc, &acc, &mut tmp, n);
        std::mem::swap(&mut acc, &mut tmp);
    }
    out[..n * n].copy_from_slice(&acc);
    w.acc = acc;
    w.tmp = tmp;
}

/// Gauss–Legendre nodes of the sixth-order method on `[0, 1]`.
pub const NODES: [f64; 3] = [
    0.5 - 0.387_298_334_620_741_7, // sqrt(15) / 10
    0.5,
    0.5 + 0.387_298_334_620_741_7,
];

/// Scratch of one sixth-order Magnus step.
pub struct MagnusWork {
    n: usize,
    a1: Vec<f64>,
    a2: Vec<f64>,
    a3: Vec<f64>,
    c1: Vec<f64>,
    c2: Vec<f64>,
    u: Vec<f64>,
    v: Vec<f64>,
    tmp: Vec<f64>,
    omega: Vec<f64>,
    step: Vec<f64>,
    expm: ExpmWork,
}

impl MagnusWork {
    pub fn new(n: usize) -> Self {
        let z = || vec![0.0; n * n];
        MagnusWork {
            n,
            a1: z(),
            a2: z(),
            a3: z(),
            c1: z(),
            c2: z(),
            u: z(),
            v: z(),
            tmp: z(),
            omega: z(),
            step: z(),
            expm: ExpmWork::new(n),
        }
    }

    /// The step's propagator `exp(Omega_6)` from `A` at the three nodes of a step `h`.
    pub fn step(&mut self, at: [&[f64]; 3], h: f64) -> &[f64] {
        let n = self.n;
        let r15 = 15f64.sqrt();
        // alpha_1 = h A2, alpha_2 = sqrt(15) h / 3 (A3 - A1),
        // alpha_3 = 10 h / 3 (A3 - 2 A2 + A1).
        #[allow(clippy::needless_range_loop)]
        for i in 0..n * n {
            let (x1, x2, x3) = (at[0][i], at[1][i], at[2][i]);
            self.a1[i] = h * x2;
            self.a2[i] = r15 * h / 3.0 * (x3 - x1);
            self.a3[i] = 10.0 * h / 3.0 * (x3 - 2.0 * x2 + x1);
        }
        // C1 = [a1, a2]; C2 = -1/60 [a1, 2 a3 + C1];
        // Omega = a1 + a3 / 12 + 1/240 [-20 a1 - a3 + C1, a2 + C2].
        commutator(&self.a1, &self.a2, &mut self.c1, &mut self.tmp, n);
        for i in 0..n * n {
            self.u[i] = 2.0 * self.a3[i] + self.c1[i];
        }
        commutator(&self.a1, &self.u, &mut self.c2, &mut self.tmp, n);
        for i in 0..n * n {
            self.c2[i] *= -1.0 / 60.0;
            self.u[i] = -20.0 * self.a1[i] - self.a3[i] + self.c1[i];
            self.v[i] = self.a2[i] + self.c2[i];
        }
        commutator(&self.u, &self.v, &mut self.omega, &mut self.tmp, n);
        for i in 0..n * n {
            self.omega[i] = self.a1[i] + self.a3[i] / 12.0 + self.omega[i] / 240.0;
        }
        expm(&self.omega, &mut self.step, &mut self.expm);
        &self.step
    }
}

/// Monodromy `Phi(T)` (row-major `n x n`) of `xi' = A(t) xi` over `[0, period]` with
/// `steps` sixth-order Magnus steps; `a_at(t, out)` fills `A(t)`.
pub fn monodromy_fixed(
    mut a_at: impl FnMut(f64, &mut [f64]),
    n: usize,
    period: f64,
    steps: usize,
) -> Vec<f64> {
    let mut w = MagnusWork::new(n);
    let mut phi = vec![0.0; n * n];
    for i in 0..n {
        phi[i * n + i] = 1.0;
    }
    let mut next = vec![0.0; n * n];
    let h = period / steps as f64;
    let mut at = [vec![0.0; n * n], vec![0.0; n * n], vec![0.0; n * n]];
    for k in 0..steps {
        let t0 = k as f64 * h;
        for (node, a) in NODES.iter().zip(at.iter_mut()) {
            a_at(t0 + node * h, a);
        }
        let e = w.step([&at[0], &at[1], &at[2]], h);
        matmul(e, &phi, &mut next, n);
        std::mem::swap(&mut phi, &mut next);
    }
    phi
}

#[cfg(test)]
mod tests {
    use super::*;

    fn expm_series(a: &[f64], n: usize) -> Vec<f64> {
        // Reference: many squarings of a tiny Taylor step, all in f64.
        let s = 20;
        let scale = 0.5f64.powi(s);
        let x: Vec<f64> = a.iter().map(|v| v * scale).collect();
        let mut out = vec![0.0; n * n];
        let mut term = vec![0.0; n * n];
        for i in 0..n {
            out[i * n + i] = 1.0;
            term[i * n + i] = 1.0;
        }
        let mut tmp = vec![0.0; n * n];
        for k in 1..8 {
            matmul(&term, &x, &mut tmp, n);
            for (t, v) in term.iter_mut().zip(&tmp) {
                *t = v / k as f64;
            }
            for (o, t) in out.iter_mut().zip(&term) {
                *o += t;
            }
        }
        for _ in 0..s {
            matmul(&out, &out, &mut tmp, n);
            std::mem::swap(&mut out, &mut tmp);
        }
        out
    }

    #[test]
    fn expm_of_a_rotation_and_a_general_matrix() {
        // exp([[0, w], [-w, 0]]) = rotation by w.
        let w = 7.3;
        let mut out = vec![0.0; 4];
        let mut work = ExpmWork::new(2);
        expm(&[0.0, w, -w, 0.0], &mut out, &mut work);
        let (s, c) = w.sin_cos();
        for (x, y) in out.iter().zip([c, s, -s, c]) {
            assert!((x - y).abs() < 1e-13, "{out:?}");
        }
        let a: Vec<f64> = (0..9).map(|i| ((i * 7 % 5) as f64 - 2.0) * 0.9).collect();
        let mut out = vec![0.0; 9];
        expm(&a, &mut out, &mut ExpmWork::new(3));
        let r = expm_series(&a, 3);
        for (x, y) in out.iter().zip(&r) {
            assert!((x - y).abs() < 1e-10 * (1.0 + y.abs()), "{out:?} {r:?}");
        }
    }

    #[test]
    fn sixth_order_on_a_scalar_and_a_mathieu_equation() {
        // Scalar a(t) = cos t: Phi(T) = exp(sin T) exactly, at any step count.
        let phi = monodromy_fixed(|t, a| a[0] = t.cos(), 1, 1.3, 4);
        assert!((phi[0] - 1.3f64.sin().exp()).abs() < 1e-6);
        // Mathieu x'' + (1 + 0.4 cos 2t) x = 0 over one period pi: a converged
        // reference from many steps, and sixth-order convergence (error ratio ~ 64).
        let a = |t: f64, m: &mut [f64]| {
            m.copy_from_slice(&[0.0, 1.0, -(1.0 + 0.4 * (2.0 * t).cos()), 0.0]);
        };
        let p = std::f64::consts::PI;
        let r = monodromy_fixed(a, 2, p, 400);
        let err = |k| {
            let m = monodromy_fixed(a, 2, p, k);
            m.iter()
                .zip(&r)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
        };
        let (e1, e2) = (err(8), err(16));
        assert!(e1 / e2 > 40.0 && e1 / e2 < 100.0, "{e1} {e2}");
        // Liouville: det Phi = exp(int tr A) = 1.
        assert!((r[0] * r[3] - r[1] * r[2] - 1.0).abs() < 1e-12);
    }
}
