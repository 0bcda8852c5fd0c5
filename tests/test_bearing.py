"""ballbal.bearing: film forces, equilibrium, coefficients, whirl threshold.

Each test checks against something computed here independently: textbook closed forms
(Ocvirk, Gümbel, Sommerfeld, Friswell's coefficients, Muijderman's pumping), scipy
quadrature of the short-bearing pressure, central differences of the force, symmetry.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from ballbal import bearing as bb
from ballbal.exceptions import ParameterError


def ocvirk(lam: float, eps: float) -> tuple[float, float]:
    """Ocvirk's short bearing, half-Sommerfeld: (F_r, F_t) in F_S (F0 = mu w R L^3 / c^2 =
    (2 lambda)^2 F_S)."""
    f0 = 4.0 * lam * lam
    s2 = 1.0 - eps * eps
    return f0 * eps**2 / s2**2, f0 * math.pi * eps / (4.0 * s2**1.5)


def gumbel(eps: float) -> tuple[float, float]:
    """Infinitely long bearing, half-Sommerfeld (Gümbel), per unit length, mu w R^3 / c^2."""
    s2 = 1.0 - eps * eps
    return (12.0 * eps**2 / ((2.0 + eps**2) * s2),
            6.0 * math.pi * eps / ((2.0 + eps**2) * math.sqrt(s2)))


def test_short_bearing_is_ocvirk() -> None:
    lam = 0.25
    b = bb.Bearing(length_ratio=lam, model="short")
    for eps, ang in [(0.2, 0.3), (0.5, -2.0), (0.8, 1.0)]:
        f = bb.film_force(b, (eps * math.cos(ang), eps * math.sin(ang)))
        fr, ft = ocvirk(lam, eps)
        assert f.radial == pytest.approx(fr, rel=1e-10)
        assert f.tangential == pytest.approx(ft, rel=1e-10)
        assert f.eccentricity == pytest.approx(eps)
        assert f.position_angle == pytest.approx(ang)
        # tan(attitude) = pi sqrt(1 - eps^2) / (4 eps); the journal leads the load.
        assert math.tan(f.attitude) == pytest.approx(
            math.pi * math.sqrt(1 - eps**2) / (4 * eps), rel=1e-9)
        assert f.load == pytest.approx(math.hypot(fr, ft), rel=1e-10)
        assert f.sommerfeld == pytest.approx(1.0 / (math.pi * math.hypot(fr, ft)), rel=1e-10)
        assert f.min_film == pytest.approx(1.0 - eps)


def test_finite_tends_to_gumbel_with_deficit_like_d_over_l() -> None:
    eps = 0.6
    fr, ft = gumbel(eps)
    deficit = []
    for lam in (4.0, 8.0):
        b = bb.Bearing(length_ratio=lam, model="finite", grid=(128, int(12 * lam)))
        f = bb.film_force(b, (0.0, -eps))
        deficit.append(1.0 - f.tangential / ft)
        assert 0.0 < 1.0 - f.radial / fr < 2.0 / lam
    assert 0.0 < deficit[1] < deficit[0]
    assert deficit[0] / deficit[1] == pytest.approx(2.0, abs=0.4)


def test_full_sommerfeld_has_no_radial_force() -> None:
    eps = 0.5
    ft = 12.0 * math.pi * eps / ((2.0 + eps**2) * math.sqrt(1.0 - eps**2))
    f = bb.film_force(bb.Bearing(model="long", cavitation="none"), (eps, 0.0))
    assert abs(f.radial) < 1e-10 * ft
    assert f.tangential == pytest.approx(ft, rel=1e-10)


def test_short_bearing_squeeze_matches_quadrature() -> None:
    lam = 0.3
    b = bb.Bearing(length_ratio=lam, model="short")
    x, y, vx, vy = 0.3, -0.4, -0.1, 0.25

    def pressure(z: float, th: float) -> float:
        # The short-bearing Reynolds equation d/dz(H^3 dP/dz) = 6 dH/dtheta + 12 dH/dtau
        # with P(+-lambda) = 0, clipped at 0.
        h = 1.0 - x * math.cos(th) - y * math.sin(th)
        g = 6.0 * (x * math.sin(th) - y * math.cos(th)) - 12.0 * (vx * math.cos(th)
                                                                   + vy * math.sin(th))
        return max(g / (2.0 * h**3) * (z * z - lam * lam), 0.0)

    def component(n: callable) -> float:  # type: ignore[valid-type]
        val, _ = integrate.dblquad(lambda z, th: -pressure(z, th) * n(th), 0.0, 2 * math.pi,
                                   -lam, lam, epsabs=1e-11, epsrel=1e-10)
        return val / (2.0 * lam)

    fx, fy = component(math.cos), component(math.sin)
    f = bb.film_force(b, (x, y), (vx, vy))
    assert f.fx == pytest.approx(fx, rel=1e-6)
    assert f.fy == pytest.approx(fy, rel=1e-6)


def friswell(eps: float) -> tuple[np.ndarray, np.ndarray]:
    """Friswell, Penny, Garvey & Lees, Dynamics of Rotating Machines (2010), section 5.5.1,
    short bearing: K = (f0/c) a, C = (f0/(c w)) b, load f0 along -y, spin counter-clockwise."""
    e2 = eps * eps
    p2 = math.pi**2
    s = math.sqrt(1.0 - e2)
    h0 = 1.0 / (p2 * (1.0 - e2) + 16.0 * e2) ** 1.5
    a = np.array([
        [h0 * 4 * (p2 * (2 - e2) + 16 * e2),
         h0 * math.pi * (p2 * (1 - e2) ** 2 - 16 * e2 * e2) / (eps * s)],
        [-h0 * math.pi * (p2 * (1 - e2) * (1 + 2 * e2) + 32 * e2 * (1 + e2)) / (eps * s),
         h0 * 4 * (p2 * (1 + 2 * e2) + 32 * e2 * (1 + e2) / (1 - e2))],
    ])
    buv = -h0 * 8 * (p2 * (1 + 2 * e2) - 16 * e2)
    b = np.array([
        [h0 * 2 * math.pi * s * (p2 * (1 + 2 * e2) - 16 * e2) / eps, buv],
        [buv, h0 * 2 * math.pi * (p2 * (1 - e2) ** 2 + 48 * e2) / (eps * s)],
    ])
    return a, b


@pytest.mark.parametrize("eps", [0.2, 0.5, 0.8])
def test_short_coefficients_match_friswell(eps: float) -> None:
    lam = 0.25
    b = bb.Bearing(length_ratio=lam, model="short")
    w = math.hypot(*ocvirk(lam, eps))
    eq = bb.equilibrium(b, w)  # a magnitude: along -y
    assert eq.eccentricity == pytest.approx(eps, rel=1e-8)
    assert eq.sommerfeld == pytest.approx(1.0 / (math.pi * w))
    co = bb.coefficients(b, eq.position)
    a, bd = friswell(eps)
    np.testing.assert_allclose(co.k / w, a, atol=1e-6 * abs(a).max())
    np.testing.assert_allclose(co.c / w, bd, atol=1e-6 * abs(bd).max())


def test_coefficients_are_derivatives_of_the_force() -> None:
    g = bb.Grooves(count=8, angle=30.0, depth_ratio=0.8)
    for b in (bb.Bearing(grid=(64, 16)), bb.Bearing(grooves=g, grid=(128, 16)),
              bb.Bearing(grooves=g, model="narrow_groove", grid=(64, 16))):
        q = (0.3, -0.35)
        co = bb.coefficients(b, q)
        h = 1e-5
        k = np.zeros((2, 2))
        c = np.zeros((2, 2))
        for j in range(2):
            dq = np.eye(2)[j] * h
            fp = bb.film_force(b, q + dq)
            fm = bb.film_force(b, q - dq)
            k[:, j] = -np.array([fp.fx - fm.fx, fp.fy - fm.fy]) / (2 * h)
            vp = bb.film_force(b, q, dq)
            vm = bb.film_force(b, q, -dq)
            c[:, j] = -np.array([vp.fx - vm.fx, vp.fy - vm.fy]) / (2 * h)
        scale = max(abs(k).max(), abs(c).max())
        np.testing.assert_allclose(co.k, k, atol=1e-5 * scale)
        np.testing.assert_allclose(co.c, c, atol=1e-5 * scale)


def test_depth_zero_is_the_plain_bearing() -> None:
    q, v = (0.4, -0.3), (0.1, 0.2)
    plain = bb.film_force(bb.Bearing(grid=(128, 32)), q, v)
    for model in ("finite", "narrow_groove"):
        for side in ("sleeve", "journal"):
            g = bb.Grooves(count=8, angle=30.0, depth_ratio=0.0, side=side)
            f = bb.film_force(bb.Bearing(grooves=g, model=model, grid=(128, 32)), q, v)
            assert math.hypot(f.fx - plain.fx, f.fy - plain.fy) < 1e-12 * plain.load


def test_concentric_grooved_bearing_carries_no_load() -> None:
    for model in ("finite", "narrow_groove"):
        g = bb.Grooves(count=8, angle=30.0, depth_ratio=1.0)
        f = bb.film_force(bb.Bearing(grooves=g, model=model, grid=(128, 32)), (0.0, 0.0))
        assert f.peak_pressure > 0.1  # the grooves pump
        assert f.load < 1e-12 * f.peak_pressure


def test_grooved_journal_turns_with_the_journal() -> None:
    # Grooves on the journal: turning the journal's position, velocity and angle together
    # by a grid step turns the force with them.
    g = bb.Grooves(count=8, angle=30.0, depth_ratio=1.0, side="journal")
    b = bb.Bearing(grooves=g, grid=(128, 16))
    q, v, tau = np.array([0.3, -0.4]), np.array([0.1, 0.2]), 0.2
    f0 = bb.film_force(b, q, v, tau=tau)
    for k in (5, 37):
        a = 2 * math.pi * k / 128
        r = np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])
        f = bb.film_force(b, r @ q, r @ v, tau=tau + a)
        want = r @ np.array([f0.fx, f0.fy])
        assert math.hypot(f.fx - want[0], f.fy - want[1]) < 1e-10 * f0.load


def test_muijderman_pumping_of_the_narrow_groove_film() -> None:
    # Muijderman (1966): a grooved surface sliding over a smooth one at angle alpha builds
    # dp/dz = 6 mu U g1 / h_ridge^2 across the grooves.
    lam, depth, gamma, alpha = 0.5, 1.0, 0.5, math.radians(30.0)
    h, t = 1.0 + depth, math.tan(alpha)
    g1 = gamma * (1 - gamma) * (h**3 - 1) * (h - 1) * t / (
        h**3 * (1 + t * t) + gamma * (1 - gamma) * (h**3 - 1) ** 2 * t * t)
    g = bb.Grooves(count=20, angle=30.0, depth_ratio=depth, width_ratio=gamma)
    f = bb.film_force(bb.Bearing(length_ratio=lam, grooves=g, model="narrow_groove",
                                 grid=(16, 20)), (0.0, 0.0), field=True)
    assert f.pressure is not None and f.zeta is not None
    np.testing.assert_allclose(f.pressure[3], 6 * g1 * (lam - abs(f.zeta)), rtol=1e-12)


def test_narrow_groove_gives_direct_stiffness_at_the_centre() -> None:
    g = bb.Grooves(count=20, angle=30.0, depth_ratio=1.0)
    k_plain = bb.coefficients(bb.Bearing(grid=(64, 16)), (0.0, 0.0)).k
    k = bb.coefficients(bb.Bearing(grooves=g, model="narrow_groove", grid=(64, 16)),
                        (0.0, 0.0)).k
    assert abs(k_plain[0, 0]) < 1e-5 * abs(k_plain[0, 1])
    assert k[0, 0] > 0.1 * abs(k[0, 1])
    assert k[1, 1] == pytest.approx(k[0, 0], rel=1e-6)


def test_resolved_grooves_approach_narrow_groove_theory() -> None:
    q = (0.0, -0.5)
    diffs = []
    for n in (8, 16, 32):
        g = bb.Grooves(count=n, angle=45.0, depth_ratio=1.0)
        grid = (16 * n, 32)
        f = bb.film_force(bb.Bearing(length_ratio=0.5, grooves=g, grid=grid), q)
        s = bb.film_force(bb.Bearing(length_ratio=0.5, grooves=g, model="narrow_groove",
                                     grid=grid), q)
        diffs.append(math.hypot(f.fx - s.fx, f.fy - s.fy) / s.load)
    assert diffs[2] < diffs[1] < diffs[0]
    assert diffs[2] < 0.3 * diffs[0]


def test_stability_of_a_rigid_rotor_on_short_bearings() -> None:
    lam = 0.25
    b = bb.Bearing(length_ratio=lam, model="short")
    # Stable at every speed above eps = 0.756; below, a threshold with whirl near 1/2.
    high = bb.stability(b, math.hypot(*ocvirk(lam, 0.8)))
    assert high.equilibrium.eccentricity == pytest.approx(0.8, rel=1e-8)
    assert math.isinf(high.threshold_speed)
    low = bb.stability(b, math.hypot(*ocvirk(lam, 0.1)))
    assert 0 < low.threshold_speed < math.inf
    assert low.whirl_ratio == pytest.approx(0.5, abs=0.03)
    # The rotor's eigenvalues cross the imaginary axis at the critical mass parameter.
    k, c = low.coefficients.k, low.coefficients.c

    def max_re(m: float) -> float:
        a = np.block([[np.zeros((2, 2)), np.eye(2)], [-k / m, -c / m]])
        return float(np.linalg.eigvals(a).real.max())

    assert max_re(0.99 * low.critical_mass) < 0 < max_re(1.01 * low.critical_mass)
    w = math.hypot(*low.equilibrium.load)
    assert low.threshold_speed == pytest.approx(math.sqrt(low.critical_mass / w))


def test_dimensions_scales() -> None:
    d = bb.Dimensions(radius=0.025, length=0.03, clearance=40e-6, viscosity=0.02)
    w = 300.0
    assert d.length_ratio == pytest.approx(0.6)
    assert d.force_scale(w) == pytest.approx(0.02 * w * 0.03 * 0.025**3 / 40e-6**2)
    assert d.pressure_scale(w) == pytest.approx(0.02 * w * 0.025**2 / 40e-6**2)
    b = bb.Bearing(length_ratio=d.length_ratio, model="short")
    load_n = 200.0
    eq = bb.equilibrium(b, load_n, dimensions=d, speed=w)
    # The same equilibrium from the nondimensional load; S from its definition.
    eq2 = bb.equilibrium(b, load_n / d.force_scale(w))
    assert eq.position == pytest.approx(eq2.position, rel=1e-12)
    s_def = 0.02 * (w / (2 * math.pi)) * 0.03 * 0.05 * (0.025 / 40e-6) ** 2 / load_n
    assert eq.sommerfeld == pytest.approx(s_def, rel=1e-12)
    assert d.sommerfeld(w, load_n) == pytest.approx(s_def, rel=1e-12)
    f = bb.film_force(b, eq.position, field=True)
    fx, fy = d.force(f, w)
    assert (fx, fy) == pytest.approx((0.0, load_n), rel=1e-8, abs=1e-8 * load_n)
    assert d.pressure(f, w).max() == pytest.approx(f.peak_pressure * d.pressure_scale(w),
                                                   rel=0.05)
    co = bb.coefficients(b, eq.position, dimensions=d, speed=w)
    assert co.k_si is not None and co.c_si is not None
    np.testing.assert_allclose(co.k_si, co.k * d.force_scale(w) / 40e-6)
    np.testing.assert_allclose(co.c_si, co.c * d.force_scale(w) / (40e-6 * w))


def test_field_axes_and_plot() -> None:
    import matplotlib

    matplotlib.use("Agg")
    g = bb.Grooves(count=8, angle=30.0, depth_ratio=1.0)
    b = bb.Bearing(length_ratio=0.5, grooves=g, grid=(128, 16))
    f = bb.film_force(b, (0.5, 0.2), field=True)
    assert f.pressure is not None and f.theta is not None and f.zeta is not None
    assert f.pressure.shape == (128, 16) == (len(f.theta), len(f.zeta))
    assert f.zeta.min() > -0.5 and f.zeta.max() < 0.5
    assert f.pressure.max() == pytest.approx(f.peak_pressure)
    fig = bb.plot_pressure(f)
    assert fig.axes
    assert bb.plot_pressure(b, (0.5, 0.2)).axes
    assert bb.film_force(b, (0.5, 0.2)).pressure is None


@pytest.mark.parametrize(("make", "parameter"), [
    (lambda: bb.Dimensions(0.025, 0.03, -40e-6, 0.02), "clearance"),
    (lambda: bb.Grooves(count=8, angle=30.0, depth_ratio=-0.1), "grooves.depth_ratio"),
    (lambda: bb.Grooves(count=8, angle=30.0, depth_ratio=1.0, width_ratio=0.0),
     "grooves.width_ratio"),
    (lambda: bb.Grooves(count=8, angle=30.0, depth_ratio=1.0, width_ratio=1.0),
     "grooves.width_ratio"),
    (lambda: bb.Grooves(count=8, angle=0.0, depth_ratio=1.0), "grooves.angle"),
    (lambda: bb.Grooves(count=8, angle=90.0, depth_ratio=1.0), "grooves.angle"),
    (lambda: bb.Bearing(grooves=bb.Grooves(count=8, angle=30.0, depth_ratio=1.0),
                        grid=(32, 16)), "grid.n_theta"),
    (lambda: bb.Bearing(model="narrow_groove", grid=(64, 15)), "grid.n_zeta"),
    (lambda: bb.film_force(bb.Bearing(model="short"), (0.8, 0.7)), "position"),
    (lambda: bb.film_force(bb.Bearing(model="short"), (math.nan, 0.0)), "position[0]"),
    (lambda: bb.film_force(bb.Bearing(model="short"), (0.1, 0.0, 0.0)), "position"),
    (lambda: bb.film_force(bb.Bearing(model="short"), (0.1, 0.0), (0.0, math.inf)),
     "velocity[1]"),
    (lambda: bb.coefficients(bb.Bearing(model="short"), (1.0, 0.0)), "position"),
    (lambda: bb.equilibrium(bb.Bearing(model="short"), 0.0), "load"),
    (lambda: bb.equilibrium(bb.Bearing(model="short"), 1.0,
                            dimensions=bb.Dimensions(0.025, 0.03, 4e-5, 0.02)), "speed"),
])
def test_bad_input_names_the_parameter(make, parameter: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ParameterError) as e:
        make()
    assert e.value.parameter == parameter
