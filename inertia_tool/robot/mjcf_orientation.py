"""MJCF orientations: ``quat``, ``axisangle``, ``euler`` (any ``eulerseq``), ``xyaxes``, ``zaxis`` as rotation
matrices, with MuJoCo's rules (checked against ``mujoco`` 4.0); the first stage of reading an MJCF pose, used
by the model reader (:mod:`inertia_tool.robot.mjcf_model`), the body walk (:mod:`inertia_tool.robot.mjcf_bodies`)
and the geoms (:mod:`inertia_tool.robot.mjcf`)."""

from __future__ import annotations

import math

import numpy as np

from ..errors import RobotDescriptionError
from .description import _numbers

__all__ = ["orientation_matrix"]

#: The orientation attributes of MJCF: one orientation, whichever of them is given.
_ORIENTATION = ("quat", "axisangle", "euler", "xyaxes", "zaxis")

#: Shortest x axis, and part of the y axis across it, that ``xyaxes`` may give: MuJoCo's compiler refuses
#: shorter ones ("xaxis too small", "yaxis too small"; checked against ``mujoco`` 4.0).
_AXIS_TOO_SHORT = 1e-6


def _fail(source: str, problem: str) -> RobotDescriptionError:
    return RobotDescriptionError(f"{source}: {problem}")


def _unit(vector) -> np.ndarray | None:
    """``vector`` scaled to length 1, or None when it is zero.

    Divided by its largest component first, so that components near the float64 limits (``1e308``, ``1e-320``)
    neither overflow nor underflow the norm: a direction is refused only when it is zero, never turned into a
    wrong one (an overflowed norm would make every component 0 and the rotation the identity)."""
    v = np.asarray(vector, dtype=np.float64)
    largest = float(np.max(np.abs(v)))
    if not largest > 0:
        return None
    v = v / largest
    return v / np.linalg.norm(v)


def _quaternion_matrix(q) -> np.ndarray:
    """Rotation of the quaternion ``q`` (w x y z, any non-zero length)."""
    unit = _unit(q)
    if unit is None:
        raise ValueError("a quaternion of zero length has no rotation")
    w, x, y, z = unit
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def _axis_angle(axis, angle: float) -> np.ndarray:
    n = _unit(axis)
    if n is None:
        raise ValueError("a zero axis has no rotation")
    k = np.array([[0, -n[2], n[1]], [n[2], 0, -n[0]], [-n[1], n[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def _z_to(direction) -> np.ndarray:
    """The minimal rotation taking +z onto ``direction`` (MuJoCo's ``zaxis`` and ``fromto`` frames)."""
    d = _unit(direction)
    if d is None:
        raise ValueError("a zero direction has no rotation")
    axis = np.cross([0.0, 0.0, 1.0], d)
    s, c = np.linalg.norm(axis), float(d[2])
    if s < 1e-14:
        return np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    return _axis_angle(axis, math.atan2(s, c))


_ELEMENTARY_AXES = {"x": 0, "y": 1, "z": 2}


def _euler_matrix(sequence: str, angles) -> np.ndarray:
    """Active rotation of the Euler angles ``angles`` (rad) about the axes of ``sequence`` (three of ``xyzXYZ``,
    checked by :func:`_compiler`), composed as MuJoCo does: a lower-case axis rotates with the frame
    (``R ← R R_k``, intrinsic), an upper-case one stays fixed (``R ← R_k R``, extrinsic); cases may mix."""
    rotation = np.eye(3)
    for letter, angle in zip(sequence, angles):
        axis = np.zeros(3)
        axis[_ELEMENTARY_AXES[letter.lower()]] = 1.0
        step = _axis_angle(axis, float(angle))
        rotation = rotation @ step if letter.islower() else step @ rotation
    return rotation


def orientation_matrix(attrs: dict, *, degrees: bool, eulerseq: str, what: str, source: str) -> np.ndarray:
    """Active rotation (frame axes as columns, in parent axes) from MJCF orientation attributes.

    Parameters
    ----------
    attrs : dict
        Attribute values (strings) after defaults: ``quat`` (w x y z), ``axisangle``, ``euler``, ``xyaxes``,
        ``zaxis``; at most one of them.
    degrees : bool
        ``<compiler angle="degree">`` (MuJoCo's default) or radians.
    eulerseq : str
        ``<compiler eulerseq>``, three of ``xyzXYZ``: lower case rotate with the frame (intrinsic).
    """
    given = [k for k in ("quat", "axisangle", "euler", "xyaxes", "zaxis") if attrs.get(k) is not None]
    if len(given) > 1:
        raise _fail(source, f"{what}: more than one orientation ({', '.join(given)})")
    if not given:
        return np.eye(3)
    key = given[0]
    unit = math.pi / 180.0 if degrees else 1.0
    if key == "quat":
        q = _numbers(attrs[key], 4, f"{what} quat", source)
        if _unit(q) is None:
            raise _fail(source, f"{what}: quat of zero length")
        return _quaternion_matrix(q)
    if key == "axisangle":
        a = _numbers(attrs[key], 4, f"{what} axisangle", source)
        if _unit(a[:3]) is None:
            raise _fail(source, f"{what}: axisangle with a zero axis")
        return _axis_angle(a[:3], a[3] * unit)
    if key == "euler":
        angles = _numbers(attrs[key], 3, f"{what} euler", source) * unit
        return _euler_matrix(eulerseq, angles)
    if key == "xyaxes":
        a = _numbers(attrs[key], 6, f"{what} xyaxes", source)
        # MuJoCo refuses an x axis, or the part of y across x, shorter than 1e-6 ("xaxis/yaxis too small");
        # both lengths are computed on the numbers scaled by their largest, so no length overflows to inf
        x, y = _unit(a[:3]), a[3:]
        y_scale = float(np.max(np.abs(y)))
        across = None
        if x is not None and y_scale > 0:
            across = y / y_scale - ((y / y_scale) @ x) * x
        x_scale = float(np.max(np.abs(a[:3])))
        if (x is None or across is None or x_scale * float(np.linalg.norm(a[:3] / x_scale)) < _AXIS_TOO_SHORT
                or y_scale * float(np.linalg.norm(across)) < _AXIS_TOO_SHORT):
            raise _fail(source, f"{what}: xyaxes are zero or parallel (expected an x axis and a y axis across it "
                                f"at least {_AXIS_TOO_SHORT:g} long, got {attrs[key]!r})")
        y_axis = across / np.linalg.norm(across)
        return np.column_stack([x, y_axis, np.cross(x, y_axis)])
    z = _numbers(attrs[key], 3, f"{what} zaxis", source)
    if _unit(z) is None:
        raise _fail(source, f"{what}: zaxis of zero length")
    return _z_to(z)
