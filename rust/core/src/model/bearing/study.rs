//! Groove study: a parallel scan over herringbone groove parameters (bearing.md section 3).
//!
//! Every point is the base bearing with one groove geometry and `L / D`, solved on its own
//! (its own solver, nothing carried between points), so the table does not depend on the
//! thread count. Per point, with the journal held at eccentricity `eps` along `+x` (the
//! load then is the film force reversed; **load capacity at a given eccentricity** is the
//! choice here, not the equilibrium at a given load, because it needs no Newton solve and
//! cannot fail to converge):
//!
//! * `load = |F| / F_S`, the Sommerfeld number `S = 1 / (pi load)`, the attitude angle;
//! * the linearised stiffness `K` (units `F_S / c`) and damping `C` (`F_S / (c w)`) there;
//! * the rigid-rotor whirl threshold from [`rigid_rotor_stability`] with that load
//!   (critical mass parameter, whirl ratio, threshold speed in `sqrt(W / (M c))`);
//! * the concentric direct stiffness `K_xx(0)` (what grooves are for: a plain bearing has
//!   none) and cross stiffness `K_xy(0)`.
//!
//! The finite model's `n_theta` is rounded up to a multiple of the point's groove count
//! (with at least [`super::MIN_CELLS_PER_PITCH`] cells per pitch); `n_zeta` is the base's.

use super::linear::{linear_coefficients, rigid_rotor_stability};
use super::{Bearing, FilmModel, GrooveSide, Grooves, JournalState, MIN_CELLS_PER_PITCH};
use crate::cancel;
use crate::error::{check_range, Error, Result};
use crate::model::ParamId;

/// The axes of a groove study (their cartesian product is scanned, `angle` slowest).
#[derive(Debug, Clone, PartialEq)]
pub struct GrooveAxes {
    /// Groove angles in degrees from the circumferential direction, in (0, 90].
    pub angle: Vec<f64>,
    /// Depth ratios `c_g / c`, >= 0.
    pub depth: Vec<f64>,
    /// Width ratios groove / pitch, in (0, 1).
    pub width: Vec<f64>,
    /// `L / D`, > 0.
    pub length_ratio: Vec<f64>,
    /// Groove counts, >= 1.
    pub count: Vec<usize>,
}

/// What one point of the study found.
#[derive(Debug, Clone, PartialEq)]
pub struct GroovePoint {
    pub angle: f64,
    pub depth: f64,
    pub width: f64,
    pub length_ratio: f64,
    pub count: usize,
    /// `Ok` or why this point has no values (the values are then NaN).
    pub status: std::result::Result<(), String>,
    pub load: f64,
    pub sommerfeld: f64,
    /// Attitude angle, degrees.
    pub attitude: f64,
    /// `[[K_xx, K_xy], [K_yx, K_yy]]`.
    pub k: [[f64; 2]; 2],
    pub c: [[f64; 2]; 2],
    pub critical_mass: f64,
    pub whirl_ratio: f64,
    pub threshold_speed: f64,
    /// `K_xx` and `K_xy` of the concentric journal.
    pub k_centre: f64,
    pub k_centre_cross: f64,
}

impl GrooveAxes {
    /// Checks every axis; errors name the axis.
    pub fn validate(&self) -> Result<()> {
        let nonempty = |name: &str, len: usize| {
            if len == 0 {
                Err(Error::param_range(
                    name,
                    "the axis has no values",
                    "at least one value",
                ))
            } else {
                Ok(())
            }
        };
        nonempty("angle", self.angle.len())?;
        nonempty("depth_ratio", self.depth.len())?;
        nonempty("width_ratio", self.width.len())?;
        nonempty("length_ratio", self.length_ratio.len())?;
        nonempty("count", self.count.len())?;
        for &a in &self.angle {
            check_range("angle", a, 0.0, true, 90.0, false)?;
        }
        for &d in &self.depth {
            ParamId::GrooveDepth.check_named("depth_ratio", d)?;
        }
        for &w in &self.width {
            check_range("width_ratio", w, 0.0, true, 1.0, true)?;
        }
        for &l in &self.length_ratio {
            check_range("length_ratio", l, 0.0, true, f64::INFINITY, true)?;
        }
        for &n in &self.count {
            if n == 0 {
                return Err(Error::param_range(
                    "count",
                    "must be at least 1",
                    "integer >= 1",
                ));
            }
        }
        Ok(())
    }

    /// The points in scan order.
    pub fn points(&self) -> Vec<(f64, f64, f64, f64, usize)> {
        let mut out = Vec::new();
        for &a in &self.angle {
            for &d in &self.depth {
                for &w in &self.width {
                    for &l in &self.length_ratio {
                        for &n in &self.count {
                            out.push((a, d, w, l, n));
                        }
                    }
                }
            }
        }
        out
    }
}

/// The bearing of one point: the base with these grooves (side and grooved length from
/// the base's grooves, else the sleeve over the whole length) and `L / D`.
pub fn point_bearing(base: &Bearing, pt: (f64, f64, f64, f64, usize)) -> Bearing {
    let (angle, depth, width, lambda, count) = pt;
    let (side, length_fraction) = base
        .grooves
        .map_or((GrooveSide::Sleeve, 1.0), |g| (g.side, g.length_fraction));
    let model = match base.model {
        FilmModel::Finite { n_theta, n_zeta } => {
            let per = n_theta.div_ceil(count).max(MIN_CELLS_PER_PITCH);
            FilmModel::Finite {
                n_theta: per * count,
                n_zeta,
            }
        }
        m => m,
    };
    Bearing {
        lambda,
        grooves: Some(Grooves {
            count,
            angle: angle.to_radians(),
            depth,
            width,
            length_fraction,
            side,
        }),
        cavitation: base.cavitation,
        model,
    }
}

fn solve_point(base: &Bearing, pt: (f64, f64, f64, f64, usize), eps: f64) -> GroovePoint {
    let nan = f64::NAN;
    let mut out = GroovePoint {
        angle: pt.0,
        depth: pt.1,
        width: pt.2,
        length_ratio: pt.3,
        count: pt.4,
        status: Ok(()),
        load: nan,
        sommerfeld: nan,
        attitude: nan,
        k: [[nan; 2]; 2],
        c: [[nan; 2]; 2],
        critical_mass: nan,
        whirl_ratio: nan,
        threshold_speed: nan,
        k_centre: nan,
        k_centre_cross: nan,
    };
    let run = |out: &mut GroovePoint| -> Result<()> {
        let mut solver = point_bearing(base, pt).solver()?;
        let f = solver.force(&JournalState::at(eps, 0.0), false)?;
        let lc = linear_coefficients(&mut solver, eps, 0.0)?;
        let lc0 = linear_coefficients(&mut solver, 0.0, 0.0)?;
        let load = f.fx.hypot(f.fy);
        let w = rigid_rotor_stability(&lc, load);
        out.load = load;
        out.sommerfeld = f.sommerfeld;
        out.attitude = f.attitude.to_degrees();
        for i in 0..2 {
            for j in 0..2 {
                out.k[i][j] = lc.k[(i, j)];
                out.c[i][j] = lc.c[(i, j)];
            }
        }
        out.critical_mass = w.critical_mass;
        out.whirl_ratio = w.whirl_ratio;
        out.threshold_speed = w.threshold_speed;
        out.k_centre = lc0.k[(0, 0)];
        out.k_centre_cross = lc0.k[(0, 1)];
        Ok(())
    };
    if let Err(e) = run(&mut out) {
        out.status = Err(e.to_string());
    }
    out
}

/// Scans the cartesian product of `axes` on `threads` threads (`None`: rayon's global
/// pool), at eccentricity `eps` in (0, 1). A point that fails (a groove width the grid
/// cannot resolve, a singular film) carries its error in `status`; a cancellation
/// ([`crate::cancel`]) stops the scan with `Error::Cancelled`.
pub fn groove_study(
    base: &Bearing,
    axes: &GrooveAxes,
    eps: f64,
    threads: Option<usize>,
) -> Result<Vec<GroovePoint>> {
    use rayon::prelude::*;
    base.validate()?;
    axes.validate()?;
    check_range("eccentricity", eps, 0.0, true, 1.0, true)?;
    if threads == Some(0) {
        return Err(Error::param_range(
            "threads",
            "must be at least 1",
            "integer >= 1 or None",
        ));
    }
    let points = axes.points();
    // rayon's threads do not inherit the cancellation token: hand it on.
    let tok = cancel::current();
    let work = || -> Vec<Option<GroovePoint>> {
        points
            .par_iter()
            .map(|&pt| {
                cancel::with(tok.clone(), || {
                    let found = (!cancel::cancelled()).then(|| solve_point(base, pt, eps));
                    cancel::advance();
                    found
                })
            })
            .collect()
    };
    let found = match threads {
        None => work(),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| Error::param("threads", format!("cannot start the threads: {e}")))?
            .install(work),
    };
    cancel::check()?;
    found
        .into_iter()
        .map(|p| p.ok_or(Error::Cancelled))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::bearing::{Cavitation, FilmModel};

    fn base() -> Bearing {
        Bearing::plain(
            1.0,
            FilmModel::Finite {
                n_theta: 64,
                n_zeta: 16,
            },
        )
    }

    fn axes() -> GrooveAxes {
        GrooveAxes {
            angle: vec![30.0, 60.0],
            depth: vec![0.0, 1.0],
            width: vec![0.5],
            length_ratio: vec![1.0],
            count: vec![8],
        }
    }

    #[test]
    fn groove_study_stiffness_matches_central_differences_of_the_force() {
        // The study's K and C against central differences of the film force, written here.
        let eps = 0.5;
        let rows = groove_study(&base(), &axes(), eps, Some(1)).unwrap();
        for r in &rows {
            assert!(r.status.is_ok(), "{:?}", r.status);
            let b = point_bearing(
                &base(),
                (r.angle, r.depth, r.width, r.length_ratio, r.count),
            );
            let mut s = b.solver().unwrap();
            let h = 1e-6;
            let mut f = |st: JournalState| s.force_xy(&st).unwrap();
            let at = |x: f64, y: f64, vx: f64, vy: f64| JournalState {
                x,
                y,
                vx,
                vy,
                tau: 0.0,
            };
            let cols = [
                (f(at(eps + h, 0.0, 0.0, 0.0)), f(at(eps - h, 0.0, 0.0, 0.0))),
                (f(at(eps, h, 0.0, 0.0)), f(at(eps, -h, 0.0, 0.0))),
                (f(at(eps, 0.0, h, 0.0)), f(at(eps, 0.0, -h, 0.0))),
                (f(at(eps, 0.0, 0.0, h)), f(at(eps, 0.0, 0.0, -h))),
            ];
            let scale = r.k.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs()));
            for (j, (fp, fm)) in cols.iter().enumerate() {
                for i in 0..2 {
                    let d = -(fp[i] - fm[i]) / (2.0 * h);
                    let got = if j < 2 { r.k[i][j] } else { r.c[i][j - 2] };
                    assert!((got - d).abs() < 1e-6 * scale, "({i}, {j}): {got} vs {d}");
                }
            }
            let f0 = f(at(eps, 0.0, 0.0, 0.0));
            assert!((r.load - f0[0].hypot(f0[1])).abs() < 1e-12 * r.load);
        }
        // Grooves give the concentric journal direct stiffness; depth 0 has none.
        for r in &rows {
            if r.depth == 0.0 {
                assert!(r.k_centre.abs() < 1e-9 * r.k_centre_cross.abs());
            } else {
                assert!(r.k_centre > 0.05 * r.k_centre_cross.abs());
            }
        }
    }

    #[test]
    fn groove_study_is_independent_of_the_thread_count() {
        let a = groove_study(&base(), &axes(), 0.4, Some(1)).unwrap();
        let b = groove_study(&base(), &axes(), 0.4, Some(2)).unwrap();
        assert_eq!(a, b);
    }

    #[test]
    fn groove_study_depth_zero_is_the_plain_film() {
        // Depth 0 runs the grooved (sparse, half-domain) path; the plain bearing the
        // sine-transform path.
        let mut b = base();
        b.cavitation = Cavitation::HalfSommerfeld;
        let rows = groove_study(&b, &axes(), 0.6, Some(1)).unwrap();
        let mut plain = b.solver().unwrap();
        let f = plain.force(&JournalState::at(0.6, 0.0), false).unwrap();
        for r in rows.iter().filter(|r| r.depth == 0.0) {
            assert!((r.load - f.fx.hypot(f.fy)).abs() < 1e-12 * r.load);
            assert!((r.attitude - f.attitude.to_degrees()).abs() < 1e-10);
        }
    }

    #[test]
    fn groove_study_bad_axes_name_the_axis() {
        type Spoil = fn(&mut GrooveAxes);
        let cases: [(&str, Spoil); 6] = [
            ("angle", |a| a.angle = vec![95.0]),
            ("depth_ratio", |a| a.depth = vec![-0.1]),
            ("width_ratio", |a| a.width = vec![1.0]),
            ("length_ratio", |a| a.length_ratio = vec![0.0]),
            ("count", |a| a.count = vec![0]),
            ("angle", |a| a.angle.clear()),
        ];
        for (name, bad) in cases {
            let mut a = axes();
            bad(&mut a);
            match groove_study(&base(), &a, 0.5, Some(1)) {
                Err(Error::InvalidParameter { name: got, .. }) => assert_eq!(got, name),
                other => panic!("{name}: {other:?}"),
            }
        }
    }
}
