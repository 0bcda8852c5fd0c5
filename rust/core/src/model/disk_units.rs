//! The planar balancer in units of the disk alone, as a parameter family
//! ([EccentricRotorABB], see docs/references.md).
//!
//! Lengths are scaled by the track radius (`e = eps / R`), masses by the disk's
//! (`m0 = m / M`, no further rotor mass) and time by `omega_n = sqrt(K / M)` of the disk
//! alone; `C0 = C / (2 sqrt(K M))`, `D0 = D / (m R^2 omega_n)`. With `S = sqrt(1 + n m0)`
//! (the total mass is `M S^2`) these parameters are the planar model's
//!
//! ```text
//!   Omega = omega0 S,  mu = 1 / S^2,  eta = m0 / e,  delta = 1 / e,
//!   zeta = C0 / S,     zeta_b = D0 S / 2,
//! ```
//!
//! so one of them moves several of the model's at once (`m0` moves all but `delta`):
//! continuation in these units builds the model through [`DiskUnits::planar`] at every
//! point. Its coordinates are the model's with `x, y` multiplied by `e` (lengths by `R`,
//! not `eps`) and its time `S` times the model's (rates and eigenvalues divided by `S`).

use crate::error::{check_range, Error, Result};
use crate::model::Planar;

/// The parameter names in the disk's units, in [`DiskUnits::values`]' order.
pub const DISK_UNITS_PARAMS: [&str; 5] = ["omega0", "m0", "e", "C0", "D0"];

/// A balancer in the disk's units (`n` equal balls).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiskUnits {
    pub omega0: f64,
    pub m0: f64,
    pub e: f64,
    pub c0: f64,
    pub d0: f64,
    pub n: usize,
}

impl DiskUnits {
    /// Validates the ranges (`omega0, C0, D0 >= 0`, `m0, e > 0`, `1 <= n <= 1024`).
    pub fn new(omega0: f64, m0: f64, e: f64, c0: f64, d0: f64, n: usize) -> Result<Self> {
        let inf = f64::INFINITY;
        check_range("omega0", omega0, 0.0, false, inf, true)?;
        check_range("m0", m0, 0.0, true, inf, true)?;
        check_range("e", e, 0.0, true, inf, true)?;
        check_range("C0", c0, 0.0, false, inf, true)?;
        check_range("D0", d0, 0.0, false, inf, true)?;
        if !(1..=1024).contains(&n) {
            return Err(Error::param_range(
                "n",
                format!("must be a ball count, got {n}"),
                "1 <= n <= 1024",
            ));
        }
        Ok(DiskUnits {
            omega0,
            m0,
            e,
            c0,
            d0,
            n,
        })
    }

    pub fn values(&self) -> [f64; 5] {
        [self.omega0, self.m0, self.e, self.c0, self.d0]
    }

    /// The value of the parameter `name` (one of [`DISK_UNITS_PARAMS`]).
    pub fn param_value(&self, name: &str) -> Result<f64> {
        match DISK_UNITS_PARAMS.iter().position(|p| *p == name) {
            Some(i) => Ok(self.values()[i]),
            None => Err(unknown(name)),
        }
    }

    /// A copy with the parameter `name` set to `value`, validated.
    pub fn with_param(&self, name: &str, value: f64) -> Result<Self> {
        let mut v = self.values();
        let i = DISK_UNITS_PARAMS
            .iter()
            .position(|p| *p == name)
            .ok_or_else(|| unknown(name))?;
        v[i] = value;
        DiskUnits::new(v[0], v[1], v[2], v[3], v[4], self.n)
    }

    /// `S = sqrt(1 + n m0)`: the disk's time unit over the model's, the model's speed
    /// over `omega0`.
    pub fn scale(&self) -> f64 {
        (1.0 + self.n as f64 * self.m0).sqrt()
    }

    /// The planar model of this balancer (see the module's notes).
    pub fn planar(&self) -> Result<Planar> {
        let s = self.scale();
        let eta = self.m0 / self.e;
        let delta = 1.0 / self.e;
        let balls = self.n as f64 * eta / delta;
        // The balls are all the mass besides the disk, so the model's mass check
        // `mu (1 + sum eta / delta) <= 1` holds with equality; keep rounding from
        // pushing it over.
        let mut mu = 1.0 / (1.0 + balls);
        while mu * (1.0 + balls) > 1.0 {
            mu = f64::from_bits(mu.to_bits() - 1);
        }
        Planar::new(
            mu,
            self.c0 / s,
            &[self.d0 * s / 2.0],
            delta,
            self.omega0 * s,
            &vec![eta; self.n],
        )
    }
}

fn unknown(name: &str) -> Error {
    Error::param_range(
        name,
        format!("is not a parameter of the disk's units (there: {name:?})"),
        DISK_UNITS_PARAMS.join(", "),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_codimension_two_point_is_the_models_double_zero() {
        // (omega0, m0) = (1/sqrt(1 + 2 m0), e/2) at e = 2 is (Omega, eta) = (1, 1/2).
        let s = DiskUnits::new(1.0 / 3f64.sqrt(), 1.0, 2.0, 0.35, 0.35, 2).unwrap();
        let p = s.planar().unwrap();
        assert!((p.omega_s - 1.0).abs() < 1e-15 && (p.eta[0] - 0.5).abs() < 1e-15);
        assert!((p.mu - 1.0 / 3.0).abs() < 1e-15 && (p.delta - 0.5).abs() < 1e-15);
        assert!((p.zeta - 0.35 / 3f64.sqrt()).abs() < 1e-15);
        assert!((p.zeta_b[0] - 0.35 * 3f64.sqrt() / 2.0).abs() < 1e-15);
        assert_eq!(s.with_param("m0", 2.5).unwrap().m0, 2.5);
        assert!(matches!(
            s.with_param("m0", 0.0),
            Err(Error::InvalidParameter { .. })
        ));
        assert!(s.param_value("Omega").is_err());
        // every m0 builds (the mass check holds with equality)
        for k in 1..2000 {
            let m0 = k as f64 * 0.00731;
            s.with_param("m0", m0).unwrap().planar().unwrap();
        }
    }
}
