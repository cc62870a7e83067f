"""Kinematics in a rotating, accelerating coordinate system (Chapter 4, "Rigid Body Motion", §4.2).

A point of mass ``m`` seen from a frame whose origin accelerates as ``R̈`` and whose axes turn with angular
velocity ``ω`` (angular acceleration ``ω̇``) obeys, in that frame (end of §4.2),

    m a′ = F − m R̈ − 2 m ω × v′ − m ω̇ × r − m ω × (ω × r),

with ``r``, ``v′ = (dr/dt)_b``, ``a′ = (d²r/dt²)_b`` the position, velocity and acceleration measured in the
frame.  The four additions are the pseudoforce of the accelerating origin, the Coriolis force, the force of the
angular acceleration (the chapter leaves it unnamed; often "Euler force") and the centrifugal force.

All vectors are components in the moving frame (m, m/s, m/s², rad/s, rad/s²); SI throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import UsageError

__all__ = ["Pseudoforces", "pseudoforces", "integrate_in_rotating_frame", "eastward_drop_deflection",
           "foucault_precession_rate", "EARTH_SIDEREAL_RATE"]

#: rad/s, Earth's rotation rate, 2π per sidereal day of 86164.0905 s.
EARTH_SIDEREAL_RATE = 2.0 * math.pi / 86164.0905


def _vector(value, name: str) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64)
    if a.shape[-1:] != (3,):
        raise UsageError(f"Expected `{name}` to have shape (..., 3), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise UsageError(f"Expected `{name}` to be finite")
    return a


@dataclass(frozen=True)
class Pseudoforces:
    """The fictitious forces on a point seen from a moving frame (§4.2), N, components in that frame.

    Attributes
    ----------
    translation : (..., 3) float
        ``−m R̈``, from the acceleration of the frame's origin.
    coriolis : (..., 3) float
        ``−2 m ω × v′``.
    angular_acceleration : (..., 3) float
        ``−m ω̇ × r`` (the "Euler force").
    centrifugal : (..., 3) float
        ``−m ω × (ω × r)``; points away from the rotation axis.
    """

    translation: np.ndarray
    coriolis: np.ndarray
    angular_acceleration: np.ndarray
    centrifugal: np.ndarray

    @property
    def total(self) -> np.ndarray:
        """Sum of the four terms, N, (..., 3): what must be added to the real force to get ``m a′``."""
        return self.translation + self.coriolis + self.angular_acceleration + self.centrifugal


def pseudoforces(mass: float, position, velocity, angular_velocity, *, angular_acceleration=(0.0, 0.0, 0.0),
                 frame_acceleration=(0.0, 0.0, 0.0)) -> Pseudoforces:
    """The four pseudoforces on a point of ``mass`` at ``position`` moving with ``velocity`` in the frame.

    Parameters
    ----------
    mass : float
        kg, > 0.
    position, velocity : (..., 3) array_like
        ``r`` (m) and ``v′ = (dr/dt)_b`` (m/s), components in the moving frame, ``r`` from the frame's origin.
    angular_velocity : (..., 3) array_like
        ``ω`` of the frame, rad/s, its components in the frame.
    angular_acceleration : (..., 3) array_like
        ``ω̇``, rad/s² (the same in both frames, Eq. 4.8).
    frame_acceleration : (..., 3) array_like
        ``R̈``, the inertial acceleration of the frame's origin, m/s², components in the frame.

    Returns
    -------
    Pseudoforces
    """
    if not (math.isfinite(mass) and mass > 0):
        raise UsageError(f"Expected a positive finite `mass`, got {mass!r}")
    r = _vector(position, "position")
    v = _vector(velocity, "velocity")
    w = _vector(angular_velocity, "angular_velocity")
    wdot = _vector(angular_acceleration, "angular_acceleration")
    acc = _vector(frame_acceleration, "frame_acceleration")
    return Pseudoforces(translation=-mass * np.broadcast_to(acc, np.broadcast_shapes(acc.shape, r.shape)).copy(),
                        coriolis=-2.0 * mass * np.cross(w, v),
                        angular_acceleration=-mass * np.cross(wdot, r),
                        centrifugal=-mass * np.cross(w, np.cross(w, r)))


#: Most output samples of :func:`integrate_in_rotating_frame`.
MAX_FRAME_SAMPLES = 200_001


def integrate_in_rotating_frame(force, position, velocity, t, *, mass: float = 1.0, angular_velocity=(0, 0, 0),
                                rtol: float = 1e-11, atol: float = 1e-13):
    """Integrate ``m a′ = F + pseudoforces`` for a frame turning at a constant ``angular_velocity``.

    Parameters
    ----------
    force : callable
        ``force(t, r, v′) -> (3,)`` real force, N, components in the frame.
    position, velocity : (3,) array_like
        ``r`` and ``v′`` at ``t[0]``, m and m/s, in the frame.
    t : (N,) array_like
        Increasing output times, s; 2 to ``MAX_FRAME_SAMPLES`` of them.
    mass : float
        kg.
    angular_velocity : (3,) array_like
        Constant ``ω`` of the frame, rad/s (``ω̇ = 0``, ``R̈ = 0``: e.g. the rotating Earth about its centre, the
        frame origin's own centripetal acceleration folded into the measured gravity).
    rtol, atol : float
        Tolerances of ``scipy.integrate.solve_ivp`` (DOP853).

    Returns
    -------
    position, velocity : (N, 3) ndarray
        In the frame at the times ``t``.
    """
    from scipy.integrate import solve_ivp

    times = np.asarray(t, dtype=np.float64)
    if times.ndim != 1 or not 2 <= len(times) <= MAX_FRAME_SAMPLES or np.any(np.diff(times) <= 0):
        raise UsageError(f"Expected `t` to be 2 to {MAX_FRAME_SAMPLES} increasing times, got shape {times.shape}")
    w = _vector(angular_velocity, "angular_velocity")

    def rhs(time, y):
        r, v = y[:3], y[3:]
        fict = pseudoforces(mass, r, v, w).total
        return np.concatenate([v, (np.asarray(force(time, r, v), dtype=float) + fict) / mass])

    y0 = np.concatenate([_vector(position, "position"), _vector(velocity, "velocity")])
    sol = solve_ivp(rhs, (times[0], times[-1]), y0, method="DOP853", t_eval=times, rtol=rtol, atol=atol)
    if not sol.success:
        raise UsageError(f"integration in the rotating frame failed: {sol.message}")
    return sol.y[:3].T, sol.y[3:].T


def eastward_drop_deflection(fall_time: float, latitude: float, *, gravity: float = 9.80665,
                             rotation_rate: float = EARTH_SIDEREAL_RATE) -> float:
    """Eastward deflection of a body dropped from rest, to first order in the rotation: ``ω g t³ cos λ / 3``, m.

    From the Coriolis term of §4.2: with ``x`` east, ``z`` up, ``v′ ≈ −g t ẑ`` and ``ω = Ω (0, cos λ, sin λ)``,
    ``ẍ = −2 (ω × v′)_x = 2 Ω g t cos λ``, integrated twice.  ``latitude`` in rad.
    """
    return rotation_rate * gravity * fall_time ** 3 * math.cos(latitude) / 3.0


def foucault_precession_rate(latitude: float, *, rotation_rate: float = EARTH_SIDEREAL_RATE) -> float:
    """Rate at which a Foucault pendulum's plane of swing turns, ``Ω sin λ`` rad/s (clockwise seen from above in
    the northern hemisphere): the vertical component of ``ω`` in the Coriolis force of §4.2.  ``latitude`` rad."""
    return rotation_rate * math.sin(latitude)
