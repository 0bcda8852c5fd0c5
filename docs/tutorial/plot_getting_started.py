"""
First steps: a periodic motion, a map, a branch
===============================================

This tutorial takes the two-ball balancer of [Tien2011]_ from one periodic motion to
a map over two parameters and a branch followed through its bifurcations. Every block
below ran when this page was built; what it printed is shown under it.

Install
-------

ballbal is built from source: a Rust toolchain (``cargo``) and Python 3.10 or newer
are needed, and the first build compiles the Rust core for several minutes. From the
repository::

    pip install ".[plot,progress]"

``plot`` brings matplotlib (every ``.plot()``), ``progress`` brings tqdm (progress
bars). Without one of them, the call that needs it stops with a one-line error naming
the extra.

.. [Tien2011] Tien, M.-H., *Numerical and Experimental Study of Periodic Solutions of
   Ball-Type Automatic Balancer Systems*, Master's thesis, National Taiwan University,
   2011. See :doc:`/references`.
"""

# %%
# A balancer
# ----------
#
# :class:`ballbal.Balancer` holds the nondimensional parameters of :doc:`/model`:
# the disk's mass share ``mu``, the support's and the track's damping ratios ``zeta``
# and ``zeta_b``, the track radius over the eccentricity ``delta``, the spin ratio
# ``Omega`` and the balls' balancing capacities ``eta`` (one per ball). A bad value is
# refused when the object is made, with the parameter's name and range.
import os

import matplotlib.pyplot as plt
import numpy as np

import ballbal
from ballbal import continuation as cont

SMALL = os.environ.get("BALLBAL_EXAMPLE_SMALL") == "1"

b = ballbal.Balancer(mu=0.2, zeta=0.05, zeta_b=0.05, delta=50, Omega=1.2, eta=(1.0, 1.0))
print(b)

try:
    ballbal.Balancer(mu=1.5, zeta=0.05, zeta_b=0.05, delta=50, Omega=1.2, eta=1.0)
except ballbal.exceptions.ParameterError as err:
    print("refused:", err)

# %%
# The perfect balance
# -------------------
#
# Two equal balls cancel the imbalance at :math:`b_{1,2} = \pm\arccos(-1/(2\eta))`
# (:doc:`/model`). :func:`ballbal.equilibria` finds every equilibrium; the first is the
# perfect balance. Here it is unstable: at this speed the balls do not settle.
eqs = ballbal.equilibria(b)
pb = eqs[0]
print(pb)
expected = np.arccos(-1 / (2 * 1.0))
print(f"ball angles {np.degrees(pb.q[2:]).round(3)} deg, closed form +-{np.degrees(expected):.3f}")

# %%
# A first periodic motion
# -----------------------
#
# With both balls rotating relative to the disk (pattern ``"R-R"``),
# :func:`ballbal.periodic` solves for the Fourier coefficients of the orbit and its
# frequency ``omega`` and judges it by its Floquet multipliers. [Tien2011]_'s table 3-1
# gives, for this case, a largest non-trivial modulus of 0.8641 at ``N = 3`` (an
# independent shooting computation: omega 0.25141, modulus 0.8637).
sol = ballbal.periodic(b, "R-R", N=8)
print(sol)
print(f"omega {sol.omega:.5f} (shooting 0.25141), "
      f"largest modulus {sol.max_modulus:.4f} (shooting 0.8637)")
print("orbit closes after one simulated period:", sol.verify())

# %%
# Every result draws itself: the orbit in time, in the ground frame, and the balls.
sol.plot()
plt.show()

# %%
# A first map
# -----------
#
# :func:`ballbal.scan` finds every motion of the asked patterns over a grid and returns
# one polars row per solution. A range is ``(start, stop, step)`` with ``stop``
# included. This grid is coarse so that the page builds fast.
step = 0.2 if SMALL else 0.1
table = ballbal.scan(b, Omega=(1.0, 2.0, step), eta=(0.4, 1.4, step), patterns=["R-R"])
stable = table.filter(table["stability"] == "stable")
print(table.height, "rows,", stable.height, "stable R-R")
print(stable.select("Omega", "eta", "omega", "max_modulus").head(6))

# %%
# Stable R-R motions need :math:`\eta \ge 1/2` and live just above the support's
# resonance, as [Tien2011]_'s maps show; :func:`ballbal.plot.scan_map` draws the table.
from ballbal import plot as bplot  # noqa: E402

bplot.scan_map(table, type="R-R")
plt.show()

# %%
# A first branch
# --------------
#
# :func:`ballbal.continuation.periodic_branch` follows the R-R orbit as ``Omega``
# changes, through folds and branch points, and locates them as events.
rr = cont.periodic_branch(sol, "Omega", range=(1.0, 2.0),
                          options=cont.Continuation(max_points=130))
print(rr)
print(rr.events.select("type", "Omega"))
rr.plot()
plt.show()

# %%
# Where to go next: :doc:`/model` for what the parameters mean,
# :doc:`/howto/index` for one page per task, and :doc:`/auto_gallery/index` for the
# published figures reproduced.
