"""Result values that cannot be corrupted: frozen dataclasses with read-only arrays and equality by value.

Every result object of the package (``MassProperties``, ``PrincipalAxes``, ``StabilityReport``, ...) is declared
with :func:`frozen_value` instead of ``@dataclass(frozen=True)``.  That adds what a plain frozen dataclass
lacks when it holds numpy arrays:

- every ``np.ndarray`` field is stored read-only (``flags.writeable = False``): small arrays (at most
  :data:`COPY_LIMIT` elements: vectors, tensors) as a copy, so the caller's array cannot change the value
  later; large ones (mesh vertices and faces) as a read-only view, so a 5-million-face mesh is not copied;
- ``==`` compares field by field, arrays exactly (``np.array_equal`` with NaN equal to NaN), where a plain
  dataclass raises "the truth value of an array is ambiguous"; fields declared ``compare=False`` are skipped;
- ``hash`` is consistent with ``==``.
"""

from __future__ import annotations

import dataclasses
import sys
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

if sys.version_info >= (3, 11):
    from typing import dataclass_transform
elif TYPE_CHECKING:                                # pragma: no cover
    from typing_extensions import dataclass_transform
else:                                              # Python 3.10 at run time: the marker is for type checkers only
    def dataclass_transform(**_kwargs: Any):
        return lambda decorator: decorator

_T = TypeVar("_T")

__all__ = ["frozen_value", "readonly", "COPY_LIMIT"]

#: Arrays with at most this many elements are copied when stored; larger ones are stored as read-only views.
COPY_LIMIT = 4096


def readonly(array: Any) -> np.ndarray:
    """``array`` as a read-only ndarray: a copy when small (≤ :data:`COPY_LIMIT` elements), else a view."""
    a: np.ndarray = np.asarray(array)
    a = a.copy() if a.size <= COPY_LIMIT else a.view()
    a.flags.writeable = False
    return a


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape:
            return False
        try:
            return bool(np.array_equal(a, b, equal_nan=True))
        except TypeError:                      # non-numeric dtypes have no NaN
            return bool(np.array_equal(a, b))
    if isinstance(a, (tuple, list)) and isinstance(b, (tuple, list)):
        return type(a) is type(b) and len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float) and a != a and b != b:
        return True                            # NaN fields (e.g. the density of a point mass) are equal
    return bool(a == b)


def _key(value: Any) -> object:
    if isinstance(value, np.ndarray):
        return (value.shape, str(value.dtype), value.tobytes())
    if isinstance(value, (tuple, list)):
        return tuple(_key(v) for v in value)
    if isinstance(value, float) and value != value:
        return "nan"
    return value


_FIELD_NAMES: dict[type, tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]] = {}


def _field_names(cls: type) -> tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...]]:
    """``(all field names, compared field names, shown field names)`` of a dataclass, computed once per class
    (``dataclasses.fields`` was a tenth of the engine's Python time on a small part)."""
    names = _FIELD_NAMES.get(cls)
    if names is None:
        fields = dataclasses.fields(cls)
        names = _FIELD_NAMES[cls] = (tuple(f.name for f in fields), tuple(f.name for f in fields if f.compare),
                                     tuple(f.name for f in fields if f.repr))
    return names


def _eq(self: Any, other: Any) -> bool:
    if other.__class__ is not self.__class__:
        # mypy treats NotImplemented as Any outside a method named __eq__ (its type derives from Any)
        return NotImplemented  # type: ignore[no-any-return]
    return all(_same(getattr(self, name), getattr(other, name)) for name in _field_names(self.__class__)[1])


def _hash(self: Any) -> int:
    return hash((self.__class__.__name__,) + tuple(_key(getattr(self, name))
                                                   for name in _field_names(self.__class__)[1]))


def _repr(self: Any) -> str:
    """``Name(field=value, ...)`` over the fields declared ``repr=True``, as a dataclass writes it."""
    shown = ", ".join(f"{name}={getattr(self, name)!r}" for name in _field_names(self.__class__)[2])
    return f"{self.__class__.__qualname__}({shown})"


@dataclass_transform(frozen_default=True, eq_default=False)
def frozen_value(cls: type[_T]) -> type[_T]:
    """Class decorator: a frozen dataclass whose arrays are read-only, with equality and hash by value."""
    own_post_init = cls.__dict__.get("__post_init__")

    def __post_init__(self: Any) -> None:
        if own_post_init is not None:
            own_post_init(self)
        # the instance dictionary holds exactly the fields here (a frozen dataclass without slots; derived
        # values cached later are not set yet): reading it skips a getattr per field
        stored = self.__dict__
        for name in _field_names(self.__class__)[0]:
            value = stored[name]
            if isinstance(value, np.ndarray) and value.flags.writeable:
                stored[name] = readonly(value)

    # the class is being built: methods are added to it dynamically, which a type checker cannot follow
    built: Any = cls
    # set before the dataclass is made: its generated __init__ calls __post_init__ only if it exists then
    built.__post_init__ = __post_init__
    # one __repr__ for every class instead of one compiled per class (dataclass compiles each method it writes:
    # a fifth of the time of making the class, and every command line run makes some twenty at import)
    own_repr = "__repr__" in cls.__dict__
    built = dataclasses.dataclass(frozen=True, eq=False, repr=False)(built)
    if not own_repr:
        built.__repr__ = _repr
    built.__eq__ = _eq
    built.__hash__ = _hash
    result: type[_T] = built
    return result
