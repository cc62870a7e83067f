"""``<inertial>`` blocks for URDF, SDFormat and MuJoCo MJCF.  Formatting only.

Every number comes from :class:`inertia_tool.robot.inertial.InertialFrame` (already checked for what the
simulators check).  SI units; products of inertia in the tensor convention (``ixy = −∫xy dm``), which is
what the three formats define.  The mesh axes are the link (body) frame.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..errors import UsageError
from ..reports.escape import escape_terminal
from ..reports.numbers import number

if TYPE_CHECKING:     # numpy loads when a block is formatted, not when a parser lists the formats
    import numpy as np

    from .inertial import InertialFrame

__all__ = ["format_urdf", "format_sdf", "format_mjcf", "ROBOT_FORMATS", "format_inertial"]

#: Format names accepted by :func:`format_inertial`.
ROBOT_FORMATS = ("urdf", "sdf", "mjcf")

#: Inertial frame orientations (:func:`inertia_tool.robot.inertial.inertial_frame`): the principal frame
#: (diagonal tensor) or the link/mesh axes (full tensor).
FRAMES = ("principal", "mesh")

_FRAME_TEXT = {
    "principal": "principal axes at the centre of mass, the rotation nearest the link frame (diagonal tensor)",
    "mesh": "centre of mass, axes parallel to the mesh (link) axes (full tensor)",
}


def _num(x: float, digits: int) -> str:
    return number(x, digits)


def _nums(xs, digits: int) -> str:
    return " ".join(_num(x, digits) for x in xs)


def _products(frame: InertialFrame) -> np.ndarray:
    """Display only: products below 1e-12 of the largest moment print as 0 (round-off, not data)."""
    import numpy as np

    t = np.array(frame.inertia, dtype=float)
    scale = float(np.max(np.abs(np.diag(t))))
    off = ~np.eye(3, dtype=bool)
    t[off & (np.abs(t) <= 1e-12 * scale)] = 0.0
    return t


def _position(frame: InertialFrame) -> np.ndarray:
    """Display only: coordinates below 1e-12 of the body's size (|COM| + largest radius of gyration) print as 0."""
    import numpy as np

    p = np.array(frame.position, dtype=float)
    size = float(np.max(np.abs(p))) + float(np.sqrt(max(frame.check.moments[-1], 0.0) / frame.mass))
    p[np.abs(p) <= 1e-12 * size] = 0.0
    return p


def _unitless(x) -> np.ndarray:
    """Display only: angles and quaternion components below 1e-14 (round-off) print as 0."""
    import numpy as np

    a = np.array(x, dtype=float)
    a[np.abs(a) < 1e-14] = 0.0
    return a


def _comment(frame: InertialFrame, fmt: str, source: str | None, angle_note: str) -> str:
    # a name in an XML comment: control characters (not allowed in XML) escaped, "--" broken below
    parts = [f"inertia-tool: {fmt} <inertial> of {escape_terminal(source)}" if source
             else f"inertia-tool: {fmt} <inertial>"]
    parts.append("SI units (m, kg, kg*m^2); the link frame is the mesh frame")
    parts.append(f"inertial frame: {_FRAME_TEXT[frame.frame]}")
    if angle_note:
        parts.append(angle_note)
    parts.append("products of inertia in tensor convention: ixy = -(integral of x*y dm)")
    parts.append(f"checked: principal moments positive; I1 + I2 - I3 = {frame.check.triangle_margin:.3g} kg*m^2 "
                 f">= -{frame.check.epsilon:.3g} (Gazebo's tolerance)")
    text = "\n     ".join(p.replace("--", "- -") for p in parts)
    return f"<!-- {text} -->"


def format_urdf(frame: InertialFrame, *, source: str | None = None, digits: int = 12) -> str:
    """URDF ``<inertial>``: ``<origin xyz rpy>`` (fixed-axis roll-pitch-yaw), ``<mass value>``, ``<inertia>``.

    Parameters
    ----------
    frame : InertialFrame
    source : str, optional
        Description for the leading XML comment (file, material).
    digits : int
        Significant digits of every number.
    """
    t = _products(frame)
    lines = [
        _comment(frame, "URDF", source, "rpy: R = Rz(yaw) Ry(pitch) Rx(roll), fixed axes"),
        "<inertial>",
        f'  <origin xyz="{_nums(_position(frame), digits)}" rpy="{_nums(_unitless(frame.rpy), digits)}"/>',
        f'  <mass value="{_num(frame.mass, digits)}"/>',
        f'  <inertia ixx="{_num(t[0, 0], digits)}" ixy="{_num(t[0, 1], digits)}" ixz="{_num(t[0, 2], digits)}" '
        f'iyy="{_num(t[1, 1], digits)}" iyz="{_num(t[1, 2], digits)}" izz="{_num(t[2, 2], digits)}"/>',
        "</inertial>",
    ]
    return "\n".join(lines)


def format_sdf(frame: InertialFrame, *, source: str | None = None, digits: int = 12) -> str:
    """SDFormat (1.6+) ``<inertial>``: ``<pose>x y z roll pitch yaw</pose>`` relative to the link, ``<mass>``,
    ``<inertia>`` with ``ixx ixy ixz iyy iyz izz``."""
    t = _products(frame)
    names = (("ixx", 0, 0), ("ixy", 0, 1), ("ixz", 0, 2), ("iyy", 1, 1), ("iyz", 1, 2), ("izz", 2, 2))
    lines = [
        _comment(frame, "SDFormat", source, "pose: x y z roll pitch yaw, R = Rz(yaw) Ry(pitch) Rx(roll)"),
        "<inertial>",
        f"  <pose>{_nums(_position(frame), digits)} {_nums(_unitless(frame.rpy), digits)}</pose>",
        f"  <mass>{_num(frame.mass, digits)}</mass>",
        "  <inertia>",
        *[f"    <{n}>{_num(t[i, j], digits)}</{n}>" for n, i, j in names],
        "  </inertia>",
        "</inertial>",
    ]
    return "\n".join(lines)


def format_mjcf(frame: InertialFrame, *, source: str | None = None, digits: int = 12) -> str:
    """MuJoCo ``<inertial>``: ``pos``, ``mass`` and, in the principal frame, ``quat`` (w x y z) with
    ``diaginertia``; in the mesh frame ``fullinertia`` in MuJoCo's order M11 M22 M33 M12 M13 M23 (MuJoCo
    forbids ``quat`` together with ``fullinertia``)."""
    import numpy as np

    t = _products(frame)
    attrs = [f'pos="{_nums(_position(frame), digits)}"']
    if frame.frame == "principal":
        attrs.append(f'quat="{_nums(_unitless(frame.quaternion), digits)}"')
        attrs.append(f'mass="{_num(frame.mass, digits)}"')
        attrs.append(f'diaginertia="{_nums(np.diag(t), digits)}"')
        note = "quat: w x y z (scalar first) of the principal axes"
    else:
        attrs.append(f'mass="{_num(frame.mass, digits)}"')
        attrs.append(f'fullinertia="{_nums([t[0, 0], t[1, 1], t[2, 2], t[0, 1], t[0, 2], t[1, 2]], digits)}"')
        note = "fullinertia order: M11 M22 M33 M12 M13 M23"
    return "\n".join([_comment(frame, "MuJoCo", source, note), f"<inertial {' '.join(attrs)}/>"])


def format_inertial(frame: InertialFrame, fmt: str, *, source: str | None = None, digits: int = 12) -> str:
    """The ``<inertial>`` block of ``frame`` in the simulator format ``fmt``.

    Parameters
    ----------
    frame : InertialFrame
        The checked inertial (:func:`~inertia_tool.robot.inertial.inertial_frame`).
    fmt : str
        One of :data:`ROBOT_FORMATS` (``"urdf"``, ``"sdf"``, ``"mjcf"``).
    source : str, optional
        Description for the leading XML comment (file, material).
    digits : int
        Significant digits of every number.
    """
    writers = {"urdf": format_urdf, "sdf": format_sdf, "mjcf": format_mjcf}
    if fmt not in writers:
        raise UsageError(f"Expected a format among {', '.join(ROBOT_FORMATS)}, got {fmt!r}")
    writer = writers[fmt]
    return writer(frame, source=source, digits=digits)
