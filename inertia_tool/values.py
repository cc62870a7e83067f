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


def _setstate(self: Any, state: Any) -> None:
    """Unpickling: the instance dictionary filled directly (the refusing ``__setattr__`` is not called), and
    its arrays made read-only again (pickle does not keep the flag; the unpickled arrays are this value's own,
    so no copy is needed)."""
    if isinstance(state, tuple):                   # (dict, slots): what object.__reduce_ex__ gives with slots
        state, slots = state
        for name, value in (slots or {}).items():
            object.__setattr__(self, name, value)
    stored = self.__dict__
    stored.update(state or {})
    for value in stored.values():
        if isinstance(value, np.ndarray) and value.flags.writeable:
            value.setflags(write=False)


def _refuse_assignment(self: Any, name: str, value: Any) -> None:
    raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")


def _refuse_deletion(self: Any, name: str) -> None:
    raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")


class _Factory:
    """Default of an ``__init__`` parameter whose field has a ``default_factory`` (as in dataclasses)."""

    def __repr__(self) -> str:
        return "<factory>"


_HAS_FACTORY = _Factory()


def _frozen_init(cls: type, fields: tuple[dataclasses.Field[Any], ...]) -> Any:
    """The ``__init__`` a frozen dataclass writes for ``fields`` (each an ``init`` field, neither keyword-only
    nor an ``InitVar``): one parameter per field in order, defaults and default factories as declared, each
    value stored in the instance dictionary (bypassing the refusal), then ``self.__post_init__()``."""
    scope: dict[str, Any] = {"__has_factory": _HAS_FACTORY}
    # the values go straight into the instance dictionary (what object.__setattr__ does for a class without
    # slots or descriptors of its own, at a third of the cost of a call per field: MeshReport has 24)
    params, body = [], ["    __stored = __self.__dict__"]
    for f in fields:
        name = f.name
        if f.default is not dataclasses.MISSING:
            scope[f"__default_{name}"] = f.default
            params.append(f"{name}=__default_{name}")
        elif f.default_factory is not dataclasses.MISSING:
            scope[f"__factory_{name}"] = f.default_factory
            params.append(f"{name}=__has_factory")
            body.append(f"    if {name} is __has_factory: {name} = __factory_{name}()")
        else:
            params.append(name)
        body.append(f"    __stored[{name!r}] = {name}")
    body.append("    __self.__post_init__()")
    source = f"def __init__(__self, {', '.join(params)}) -> None:\n" + "\n".join(body) + "\n"
    exec(source, scope)                            # noqa: S102 - source built above from the field names only
    init = scope["__init__"]
    init.__qualname__ = f"{cls.__qualname__}.__init__"
    init.__module__ = cls.__module__
    init.__annotations__ = {**{f.name: f.type for f in fields}, "return": None}
    return init


def _is_simple(cls: type) -> bool:
    """Whether :func:`_frozen_init` can write the ``__init__`` of ``cls`` before it is a dataclass: it defines
    no ``__init__``, ``__setattr__`` or ``__delattr__`` of its own, has no dataclass base, and no field is
    keyword-only, ``init=False``, an ``InitVar`` or a ``ClassVar`` (all of which dataclasses handles itself)."""
    own = cls.__dict__
    if "__init__" in own or "__setattr__" in own or "__delattr__" in own:
        return False
    if any("__dataclass_fields__" in base.__dict__ for base in cls.__mro__[1:]):
        return False
    for name, annotation in own.get("__annotations__", {}).items():
        text = annotation if isinstance(annotation, str) else repr(annotation)
        if "InitVar" in text or "ClassVar" in text or "KW_ONLY" in text:
            return False
        default = own.get(name)
        if isinstance(default, dataclasses.Field) and (not default.init or default.kw_only is True):
            return False
    return True


@dataclass_transform(frozen_default=True, eq_default=False)
def frozen_value(cls: type[_T]) -> type[_T]:
    """Class decorator: a frozen dataclass whose arrays are read-only, with equality and hash by value.

    It behaves as ``dataclasses.dataclass(frozen=True, eq=False)`` plus the equality, hash and repr above,
    but is cheaper to make: a frozen dataclass compiles three methods per class (``__init__``,
    ``__setattr__``, ``__delattr__``), and every command-line run makes some twenty of these classes at
    import.  Here the class is made a dataclass without an ``__init__`` (its fields, ``fields()``,
    ``replace()`` and ``asdict()`` as usual), then given the ``__init__`` a frozen dataclass would have
    (:func:`_frozen_init`, the one method compiled) and one shared ``__setattr__``/``__delattr__`` that
    refuse with :class:`dataclasses.FrozenInstanceError`.  A class with keyword-only, ``init=False`` or
    ``InitVar`` fields, or a dataclass base, is made by ``dataclasses.dataclass(frozen=True)`` itself.
    """
    own_post_init = cls.__dict__.get("__post_init__")
    ndarray = np.ndarray               # a closure variable, not a module attribute looked up per field (24 on a report)

    def __post_init__(self: Any) -> None:
        if own_post_init is not None:
            own_post_init(self)
        # the instance dictionary holds exactly the fields here (a frozen dataclass without slots; derived
        # values cached later are not set yet; an init=False field with a plain default stays on the class):
        # one pass over it, no lookup per field name
        stored = self.__dict__
        writable = [name for name, value in stored.items() if isinstance(value, ndarray) and value.flags.writeable]
        for name in writable:
            value = stored[name]
            if type(value) is ndarray:             # readonly() inlined: ~14 values of a small part, ~30 arrays
                value = value.copy() if value.size <= COPY_LIMIT else value.view()
                value.setflags(write=False)
                stored[name] = value
            else:                                  # a subclass: readonly() makes it a plain ndarray
                stored[name] = readonly(value)

    # the class is being built: methods are added to it dynamically, which a type checker cannot follow
    built: Any = cls
    # set before the dataclass is made: its generated __init__ calls __post_init__ only if it exists then
    built.__post_init__ = __post_init__
    # one __repr__ for every class instead of one compiled per class (dataclass compiles each method it writes:
    # a fifth of the time of making the class, and every command line run makes some twenty at import)
    own_repr = "__repr__" in cls.__dict__
    undocumented = cls.__doc__ is None
    if not _is_simple(built):                      # the general case, left to dataclasses
        built = dataclasses.dataclass(frozen=True, eq=False, repr=False)(built)
    else:
        built = dataclasses.dataclass(init=False, repr=False, eq=False)(built)
        fields = dataclasses.fields(built)
        built.__init__ = _frozen_init(built, fields)
        built.__setattr__ = _refuse_assignment
        built.__delattr__ = _refuse_deletion
        built.__dataclass_params__.frozen = True   # what dataclasses.dataclass(frozen=True) records
        if undocumented:                           # dataclass's default docstring, from the real __init__
            built.__doc__ = f"{built.__name__}({', '.join(f.name for f in fields)})"
    if not own_repr:
        built.__repr__ = _repr
    if not any(k in cls.__dict__ for k in ("__setstate__", "__getstate__", "__reduce__", "__reduce_ex__")):
        built.__setstate__ = _setstate
    built.__eq__ = _eq
    built.__hash__ = _hash
    result: type[_T] = built
    return result
