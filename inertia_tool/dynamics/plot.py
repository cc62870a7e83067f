"""``plot_trajectory``: a diagnostic figure of a :class:`~.trajectory.Trajectory` (needs matplotlib).

Install the optional extra: ``pip install inertia-tool[plots]``.
"""

from __future__ import annotations

import numpy as np

from ..errors import UsageError
from ..output import atomic_target

__all__ = ["plot_trajectory"]


def _relative_drift(values: np.ndarray) -> np.ndarray:
    ref = values[0]
    return (values - ref) / ref if ref != 0 else values - ref


def plot_trajectory(trajectory, path, *, dpi: int = 120):
    """Write a figure with ω(t), the polhode on the inertia ellipsoid, and the energy and |L| drift.

    Parameters
    ----------
    trajectory : Trajectory
        Result of :func:`~inertia_tool.dynamics.simulation.simulate`.
    path : str or path-like
        Output image file (format from the suffix: .png, .pdf, .svg).
    dpi : int
        Raster resolution.

    Raises
    ------
    UsageError
        When matplotlib is not installed.
    """
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:
        raise UsageError("plot_trajectory needs matplotlib: pip install 'inertia-tool[plots]' "
                         "(or pip install matplotlib)") from exc
    t = trajectory.t
    omega_p = trajectory.angular_velocity_principal
    fig = plt.figure(figsize=(11, 8))
    ax1 = fig.add_subplot(2, 2, 1)
    for k, label in enumerate(("ω1", "ω2", "ω3")):
        ax1.plot(t, omega_p[:, k], label=label)
    ax1.set_xlabel("t [s]")
    ax1.set_ylabel("ω, principal axes [rad/s]")
    ax1.legend()
    ax2 = fig.add_subplot(2, 2, 2, projection="3d")
    two_t = 2.0 * trajectory.energy[0]
    radii = np.sqrt(two_t / trajectory.moments) if two_t > 0 else np.ones(3)
    uu, vv = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.linspace(0, np.pi, 20))
    ax2.plot_wireframe(radii[0] * np.cos(uu) * np.sin(vv), radii[1] * np.sin(uu) * np.sin(vv),
                       radii[2] * np.cos(vv), color="0.8", linewidth=0.5)
    ax2.plot(omega_p[:, 0], omega_p[:, 1], omega_p[:, 2], color="C3")
    # equal scaling on the three axes: the ellipsoid's true shape (a box aspect of its semi-axes and equal
    # limits), not stretched to a cube
    reach = 1.05 * float(np.max(radii))
    for set_lim in (ax2.set_xlim, ax2.set_ylim, ax2.set_zlim):
        set_lim(-reach, reach)
    ax2.set_box_aspect((1.0, 1.0, 1.0))
    ax2.set_xlabel("ω1")
    ax2.set_ylabel("ω2")
    ax2.set_zlabel("ω3")
    ax2.set_title("polhode on the inertia ellipsoid ω·I·ω = 2T\n(principal axes, equal scales)")
    ax3 = fig.add_subplot(2, 2, 3)
    ax3.plot(t, _relative_drift(trajectory.energy))
    ax3.set_xlabel("t [s]")
    ax3.set_ylabel("(E − E0)/E0")
    ax4 = fig.add_subplot(2, 2, 4)
    ax4.plot(t, _relative_drift(np.linalg.norm(trajectory.angular_momentum, axis=1)))
    ax4.set_xlabel("t [s]")
    ax4.set_ylabel("(|L| − |L0|)/|L0|")
    fig.suptitle(f"inertia_tool trajectory ({trajectory.method})")
    fig.tight_layout()
    try:
        with atomic_target(path) as tmp:
            fig.savefig(tmp, dpi=dpi)
    finally:
        plt.close(fig)
