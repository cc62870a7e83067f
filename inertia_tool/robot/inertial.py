"""The inertial frame a simulator wants, and the checks simulators apply before accepting it.

URDF, SDFormat and MuJoCo all describe a link's mass properties as a mass, an *inertial frame* (origin at
the centre of mass, some orientation relative to the link frame) and an inertia tensor about the centre of
mass in that frame.  This module builds that frame from :class:`~inertia_tool.mass.properties.MassProperties`
(the mesh axes are taken as the link frame), converts its orientation to the angles and quaternions the
formats use, and checks the principal moments the way the simulators do.  Formatting is in
``inertia_tool.robot.formats``.

Conventions (``docs/conventions.md``):

* ``rotation`` has the inertial frame's axes as columns, in link (mesh) axes: it maps inertial-frame
  components to link components, ``I_link = R I_frame Rᵀ`` (the active rotation of Eq. 4.25).
* URDF/SDF ``rpy``: fixed-axis roll, pitch, yaw, ``R = R_z(yaw) R_y(pitch) R_x(roll)`` with *active*
  elementary rotations (note: the chapter's Eqs. 4.29–4.30 are passive; ``R_z`` here is their transpose).
* MuJoCo ``quat``: scalar-first ``(w, x, y, z)`` of the same ``R``, with ``w ≥ 0``.
* Products of inertia stay in the tensor convention (``ixy = −∫xy dm``), which is what URDF, SDFormat and
  MuJoCo's ``fullinertia`` expect; :func:`positive_tensor_notation` gives the CAD sign.

Validity (what the simulators check).  gz-math ``MassMatrix3::ValidMoments`` (used by Gazebo and
libsdformat) accepts principal moments ``I1, I2, I3`` when every ``I_k + ε ≥ 0`` and every
``I_a + I_b + ε ≥ I_c``, with ``ε = tolerance · DBL_EPSILON · ½ |I1 + I2 + I3|`` and the default
``tolerance = 10`` (``GZ_MASSMATRIX3_DEFAULT_TOLERANCE``; gz-math ``include/gz/math/MassMatrix3.hh``,
``Epsilon()`` and ``ValidMoments()``).  MuJoCo's compiler refuses moments not larger than
``mjMINVAL = 1e-15`` on moving bodies and ``A + B < C`` without tolerance ("inertia must satisfy
A + B >= C"; checked with mujoco 4.0).  :func:`check_moments` applies the union: each moment must exceed
``max(ε, min_moment)`` and the triangle inequality must hold within ``ε``.
"""

from __future__ import annotations



import numpy as np

from ..values import frozen_value
from ..errors import PhysicsError, UsageError
from ..mass.properties import MassProperties
from ..rotations import matrix_to_quaternion
from .formats import FRAMES     # the frames an <inertial> block is written in, defined beside its formats

__all__ = ["InertialFrame", "MomentCheck", "inertial_frame", "check_moments", "rpy_from_matrix",
           "quaternion_from_matrix", "positive_tensor_notation", "principal_frame_nearest", "GAZEBO_TOLERANCE",
           "MUJOCO_MINVAL", "FRAMES"]

#: gz-math's ``GZ_MASSMATRIX3_DEFAULT_TOLERANCE``: multiple of machine epsilon times ½ tr(I) accepted as round-off.
GAZEBO_TOLERANCE = 10.0

#: MuJoCo's ``mjMINVAL``: masses and principal moments of moving bodies must exceed it (kg, kg·m²).
MUJOCO_MINVAL = 1e-15



@frozen_value
class MomentCheck:
    """Principal moments judged the way Gazebo (gz-math) and MuJoCo judge them.

    Attributes
    ----------
    moments : (3,) float
        Principal moments, ascending, kg·m².
    epsilon : float
        gz-math's round-off allowance ``tolerance · DBL_EPSILON · ½ |ΣI|``, kg·m².
    min_moment : float
        Absolute floor every moment must exceed (MuJoCo's ``mjMINVAL``), kg·m².
    positive : bool
        Every moment exceeds ``max(epsilon, min_moment)``.
    triangle : bool
        ``I_a + I_b + epsilon ≥ I_c`` for all three orderings.
    triangle_margin : float
        ``I1 + I2 − I3``, kg·m² (the binding one of the three inequalities for ascending moments).
    """

    moments: np.ndarray
    epsilon: float
    min_moment: float
    positive: bool
    triangle: bool
    triangle_margin: float

    @property
    def ok(self) -> bool:
        """Both checks pass."""
        return self.positive and self.triangle

    def problem(self) -> str:
        """One sentence naming the failed check(s) with the numbers; empty when ``ok``."""
        i1, i2, i3 = self.moments
        parts = []
        if not self.positive:
            parts.append(f"principal moments must be positive (> {max(self.epsilon, self.min_moment):.3g} kg·m²)")
        if not self.triangle:
            parts.append(f"the triangle inequality I1 + I2 ≥ I3 fails: {i1:.6g} + {i2:.6g} − {i3:.6g} = "
                         f"{self.triangle_margin:.3g} kg·m² (allowed round-off {self.epsilon:.3g})")
        if not parts:
            return ""
        return (f"principal moments I1, I2, I3 = {i1:.6g}, {i2:.6g}, {i3:.6g} kg·m²: " + "; ".join(parts)
                + " — simulators (Gazebo's MassMatrix3::ValidMoments, MuJoCo's compiler) reject this inertia")


def check_moments(moments, *, tolerance: float = GAZEBO_TOLERANCE, min_moment: float = MUJOCO_MINVAL) -> MomentCheck:
    """Check principal moments for positivity and the triangle inequality (see the module docstring).

    Parameters
    ----------
    moments : (3,) array_like
        Principal moments in kg·m² (any order).
    tolerance : float
        gz-math's tolerance factor (default 10): ``ε = tolerance · DBL_EPSILON · ½ |ΣI|``.
    min_moment : float
        Absolute floor in kg·m² (default MuJoCo's ``mjMINVAL`` = 1e-15); 0 to check Gazebo only.

    Returns
    -------
    MomentCheck
    """
    m = np.sort(np.asarray(moments, dtype=np.float64).reshape(3))
    if not np.all(np.isfinite(m)):
        raise UsageError(f"Expected finite principal moments, got {m.tolist()}")
    eps = float(tolerance) * np.finfo(np.float64).eps * 0.5 * abs(float(m.sum()))
    floor = max(eps, float(min_moment))
    positive = bool(np.all(m > floor))
    i1, i2, i3 = m
    triangle = bool(i1 + i2 + eps >= i3 and i2 + i3 + eps >= i1 and i3 + i1 + eps >= i2)
    return MomentCheck(moments=m, epsilon=eps, min_moment=float(min_moment), positive=positive, triangle=triangle,
                       triangle_margin=float(i1 + i2 - i3))


def rpy_from_matrix(rotation) -> np.ndarray:
    """Fixed-axis roll, pitch, yaw (rad) with ``R = R_z(yaw) R_y(pitch) R_x(roll)`` (URDF/SDF ``rpy``).

    Parameters
    ----------
    rotation : (3, 3) array_like
        Proper rotation, active (maps frame components to parent components).

    Returns
    -------
    (3,) float
        ``(roll, pitch, yaw)``; pitch in [−π/2, π/2].
    """
    from scipy.spatial.transform import Rotation   # imported on use: plain `analyze` never needs it
    return Rotation.from_matrix(_rotation(rotation)).as_euler("xyz")  # lower case: extrinsic (fixed) axes


def quaternion_from_matrix(rotation) -> np.ndarray:
    """Unit quaternion ``(w, x, y, z)`` (scalar first, ``w ≥ 0``) of an active rotation matrix (MuJoCo ``quat``)."""
    return matrix_to_quaternion(_rotation(rotation))


def positive_tensor_notation(tensor) -> np.ndarray:
    """The inertia matrix with the CAD sign of the products: diagonal unchanged, off-diagonals ``+∫xy dm``.

    SolidWorks and most CAD reports ("positive tensor notation") list ``Lxy = +∫xy dm``; the tensor
    convention used everywhere else in inertia_tool has ``I_xy = −∫xy dm``.  The result is *not* an inertia
    tensor (it does not transform as one); use it for display only.
    """
    t = np.asarray(tensor, dtype=np.float64)
    if t.shape != (3, 3):
        raise UsageError(f"Expected `tensor` to have shape (3, 3), got {t.shape}")
    return 2.0 * np.diag(np.diag(t)) - t


def _signed_permutations() -> list:
    """The 24 signed permutation matrices with det +1, in a fixed order (identity first)."""
    from itertools import permutations, product
    out = []
    for perm in permutations(range(3)):
        for signs in product((1.0, -1.0), repeat=3):
            p = np.zeros((3, 3))
            p[list(perm), range(3)] = signs
            if np.linalg.det(p) > 0:
                out.append(p)
    return out


_SIGNED_PERMUTATIONS = _signed_permutations()


def _plane_fit(columns, slots, target_det: float) -> np.ndarray:
    """2×2 orthogonal ``Q`` with det ``target_det`` maximising ``Σ_k e_slot(k) · (columns Q)_k`` (Procrustes)."""
    c = np.stack([columns.T @ np.eye(3)[:, k] for k in slots], axis=1)     # c[:, k] = columnsᵀ e_slot(k)
    u, _, vt = np.linalg.svd(c)
    d = target_det * np.linalg.det(u) * np.linalg.det(vt)
    return u @ np.diag([1.0, d]) @ vt


def principal_frame_nearest(principal) -> np.ndarray:
    """The principal frame closest to the link frame: the rotation with the largest trace among those whose
    columns are principal axes.

    Eigenvectors fix the principal frame only up to the order and signs of its axes: 24 proper rotations
    ``A P`` (``P`` a signed permutation with det +1) diagonalise the tensor.  Sorting by moment, as
    :class:`~inertia_tool.principal.PrincipalAxes` does, can turn a link that is almost aligned with its own
    frame into an inertial frame rotated by 90° (rpy near ±π/2, close to gimbal lock).  This picks the one
    with ``max trace(A P)`` (the smallest rotation angle from the link frame, since ``tr R = 1 + 2 cos θ``);
    exact ties go to the first in a fixed enumeration.  Where two moments are equal within
    ``principal.rtol``, every basis of their plane is principal: the unique axis takes the slot and sign that
    maximise the trace and the plane's two axes are the orthogonal Procrustes fit to the remaining link
    axes, so an axisymmetric link aligned with its frame keeps the link axes exactly.  Three equal moments
    give the identity.

    Parameters
    ----------
    principal : PrincipalAxes

    Returns
    -------
    (3, 3) float
        Proper rotation; columns are principal axes in link axes.
    """
    axes = np.asarray(principal.axes, dtype=np.float64)
    pairs = tuple(principal.equal_pairs)
    if len(pairs) >= 3:
        return np.eye(3)
    if not pairs:
        best = axes
        for p in _SIGNED_PERMUTATIONS[1:]:
            candidate = axes @ p
            if np.trace(candidate) > np.trace(best) + 1e-12:
                best = candidate
        return best
    pair = pairs[0]
    unique = ({0, 1, 2} - set(pair)).pop()
    u = axes[:, unique]
    plane = axes[:, list(pair)]
    best, best_trace = axes, -np.inf        # replaced by the first candidate (its trace is finite)
    for slot in range(3):
        others = [k for k in range(3) if k != slot]
        for sign in (1.0, -1.0):
            r = np.zeros((3, 3))
            r[:, slot] = sign * u
            r[:, others] = plane
            q = _plane_fit(plane, others, float(np.sign(np.linalg.det(r))))
            r[:, others] = plane @ q
            trace = float(np.trace(r))
            if trace > best_trace + 1e-12:
                best, best_trace = r, trace
    return best


def _rotation(rotation) -> np.ndarray:
    r = np.asarray(rotation, dtype=np.float64)
    if r.shape != (3, 3):
        raise UsageError(f"Expected `rotation` to have shape (3, 3), got {r.shape}")
    if not np.allclose(r @ r.T, np.eye(3), atol=1e-9) or np.linalg.det(r) < 0:
        raise UsageError("Expected `rotation` to be a proper rotation matrix (orthogonal, det +1)")
    return r


@frozen_value
class InertialFrame:
    """Mass, centre of mass and inertia in the frame a simulator's ``<inertial>`` element describes.

    Attributes
    ----------
    mass : float
        kg.
    position : (3,) float
        Origin of the inertial frame = centre of mass, m, in link (mesh) axes.
    rotation : (3, 3) float
        Proper rotation whose columns are the inertial frame's axes in link axes (identity for ``"mesh"``).
    inertia : (3, 3) float
        kg·m² about the centre of mass, in the inertial frame's axes, tensor convention (−∫xy dm);
        diagonal for ``"principal"``, with the moments in the order of the frame's axes (the frame is the
        principal frame nearest the link frame, :func:`principal_frame_nearest`, not sorted by moment).
    frame : str
        ``"principal"`` or ``"mesh"``.
    check : MomentCheck
        The validity check of the principal moments (passed, or the frame would not have been built).
    """

    mass: float
    position: np.ndarray
    rotation: np.ndarray
    inertia: np.ndarray
    frame: str
    check: MomentCheck

    @property
    def rpy(self) -> np.ndarray:
        """(3,) rad: URDF/SDF fixed-axis roll, pitch, yaw of ``rotation``."""
        return rpy_from_matrix(self.rotation)

    @property
    def quaternion(self) -> np.ndarray:
        """(4,) scalar-first ``(w, x, y, z)`` of ``rotation`` (MuJoCo ``quat``), ``w ≥ 0``."""
        return quaternion_from_matrix(self.rotation)

    @property
    def principal_moments(self) -> np.ndarray:
        """(3,) kg·m², ascending."""
        return self.check.moments


def inertial_frame(props: MassProperties, frame: str = "principal", *, tolerance: float = GAZEBO_TOLERANCE,
                   min_moment: float = MUJOCO_MINVAL) -> InertialFrame:
    """The inertial frame of ``props`` for a simulator, after checking that a simulator would accept it.

    Parameters
    ----------
    props : MassProperties
        The body; its mesh axes are taken as the link frame.
    frame : {"principal", "mesh"}
        ``"principal"``: axes along the principal axes (Eq. 4.25), ordered and signed to be nearest the link
        frame (:func:`principal_frame_nearest`), diagonal tensor.
        ``"mesh"``: axes parallel to the mesh axes, full tensor.
    tolerance, min_moment : float
        Passed to :func:`check_moments`.

    Returns
    -------
    InertialFrame

    Raises
    ------
    PhysicsError
        When the mass is not positive or the principal moments fail :func:`check_moments` (the message
        lists the moments).  The frame cannot fix that: the check is on frame-independent moments.
    UsageError
        For an unknown ``frame``.
    """
    if frame not in FRAMES:
        raise UsageError(f"Expected `frame` to be one of {', '.join(FRAMES)}, got {frame!r}")
    if not (np.isfinite(props.mass) and props.mass > max(float(min_moment), 0.0)):
        raise PhysicsError(f"{props.name or 'body'}: mass {props.mass:.6g} kg: simulators need a positive mass")
    pa = props.principal
    check = check_moments(pa.moments, tolerance=tolerance, min_moment=min_moment)
    if not check.ok:
        raise PhysicsError(f"{props.name or 'body'}: {check.problem()}")
    if frame == "principal":
        rotation = principal_frame_nearest(pa)
        inertia = np.diag(np.diag(rotation.T @ props.inertia @ rotation))
    else:
        rotation = np.eye(3)
        inertia = props.inertia
    return InertialFrame(mass=props.mass, position=props.center_of_mass.copy(), rotation=np.array(rotation),
                         inertia=np.array(inertia), frame=frame, check=check)
