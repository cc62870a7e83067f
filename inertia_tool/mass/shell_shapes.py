"""Closed-form mass properties of primitive thin shells: mass spread evenly over a sphere, box, cylinder or capsule.

A simulator's "shell inertia" (MuJoCo's ``shellinertia`` geoms and ``<mesh inertia="shell">``) treats a part
as its skin.  Everything here is at unit areal density, so ``mass`` is the area in m², ``volume`` is 0, the
centre of mass is the area centroid and the tensor is ``I = tr(Σ) 1 − Σ`` (Eq. 4.13 of Chapter 4, "Rigid Body
Motion") from the central second moments of area ``Σ = ∫ x xᵀ dA``.

Closed forms (centred, element axes; ``A`` is the area):

* sphere of radius r: ``A = 4πr²``, ``Σ = (A r²/3) 1`` (each ``∫x² dA`` is a third of ``∫|x|² dA = A r²``);
* box of full edges ``2h``: each face pair normal to axis k has area ``8 h_i h_j`` and contributes
  ``A_k h_k²`` to ``Σ_kk`` and ``A_k h_i²/3`` to ``Σ_ii`` (a uniform segment of half-length h has ``h²/3``);
* cylinder (r, length L) along z, with its two end disks: the side (``2πrL``) has ``Σ_xx = πr³L``,
  ``Σ_zz = 2πr L³/12``; each disk (``πr²``) has ``Σ_xx = πr⁴/4`` and ``Σ_zz = πr² (L/2)²``;
* capsule (r, cylinder length L): the open side plus two hemispherical caps centred at ``±L/2``; a cap of
  area ``2πr²`` has ``Σ_xx = 2πr⁴/3`` and, with ``z = L/2 + r cos φ``, ``Σ_zz = 2πr²(L/2)² + 2(L/2)πr³ +
  2πr⁴/3`` (using ``∫cos φ dA = πr²`` and ``∫cos² φ dA = 2πr²/3`` over the cap);
Triangle meshes are :func:`inertia_tool.mass.surface.surface_moments`.  The closed forms are tested against
fine triangulations through it and against MuJoCo's ``shellinertia``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ..errors import UsageError
from .properties import MassProperties

__all__ = ["sphere_shell", "box_shell", "cylinder_shell", "capsule_shell"]


def _from_moments(area: float, sigma: np.ndarray, name: str) -> MassProperties:
    if not area > 0:
        raise UsageError(f"Expected a surface with positive area, got {area:g} m²")
    return MassProperties(mass=area, volume=0.0, center_of_mass=np.zeros(3),
                          inertia=np.trace(sigma) * np.eye(3) - sigma, surface_area=area, density=float("nan"),
                          name=name)


def sphere_shell(radius: float) -> MassProperties:
    """Spherical shell of ``radius`` m at unit areal density (mass = area, m²)."""
    area = 4.0 * math.pi * radius ** 2
    return _from_moments(area, np.eye(3) * area * radius ** 2 / 3.0, "sphere shell")


def box_shell(size: ArrayLike) -> MassProperties:
    """Closed box surface of full edge lengths ``size`` (3,) m at unit areal density."""
    h = 0.5 * np.asarray(size, dtype=np.float64)
    sigma = np.zeros(3)
    area = 0.0
    for k in range(3):
        i, j = (k + 1) % 3, (k + 2) % 3
        pair = 2.0 * 4.0 * h[i] * h[j]
        area += pair
        sigma[k] += pair * h[k] ** 2
        sigma[i] += pair * h[i] ** 2 / 3.0
        sigma[j] += pair * h[j] ** 2 / 3.0
    return _from_moments(area, np.diag(sigma), "box shell")


def cylinder_shell(radius: float, length: float) -> MassProperties:
    """Closed cylinder surface (side and both end disks), axis z, at unit areal density."""
    r, half = radius, 0.5 * length
    side = 2.0 * math.pi * r * length
    disk = math.pi * r * r
    sxx = math.pi * r ** 3 * length + 2.0 * math.pi * r ** 4 / 4.0
    szz = 2.0 * math.pi * r * length ** 3 / 12.0 + 2.0 * disk * half * half
    return _from_moments(side + 2.0 * disk, np.diag([sxx, sxx, szz]), "cylinder shell")


def capsule_shell(radius: float, length: float) -> MassProperties:
    """Capsule surface (open cylinder side of ``length`` and two hemispherical caps), axis z, unit areal density."""
    r, half = radius, 0.5 * length
    side = 2.0 * math.pi * r * length
    cap = 2.0 * math.pi * r * r
    sxx = math.pi * r ** 3 * length + 2.0 * (2.0 * math.pi * r ** 4 / 3.0)
    szz = (2.0 * math.pi * r * length ** 3 / 12.0
           + 2.0 * (cap * half * half + 2.0 * half * math.pi * r ** 3 + 2.0 * math.pi * r ** 4 / 3.0))
    return _from_moments(side + 2.0 * cap, np.diag([sxx, sxx, szz]), "capsule shell")
