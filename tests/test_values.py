"""Result values cannot be corrupted (issue: read-only arrays, equality that works, one way to principal axes)."""

import copy
import dataclasses
import inspect

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import inertia_tool as it
from inertia_tool.mass import point_mass, shapes
from inertia_tool.values import COPY_LIMIT, frozen_value, readonly


@pytest.fixture
def props():
    solid = shapes.box(0.1, 0.2, 0.3)
    return it.mass_properties((solid.vertices, solid.faces), density=7850.0)


def test_arrays_of_results_are_read_only(props):
    for array in (props.center_of_mass, props.inertia, props.principal.moments, props.principal.axes,
                  props.principal.reference_point, props.inertia_about([1, 2, 3]).tensor,
                  props.mesh.bbox_min):
        with pytest.raises(ValueError, match="read-only"):
            array[0] = 1.0


def test_caller_arrays_are_copied_so_the_value_cannot_change_later():
    com = np.array([1.0, 2.0, 3.0])
    p = it.MassProperties(mass=1.0, volume=1e-3, center_of_mass=com, inertia=np.eye(3))
    com[0] = 99.0
    assert p.center_of_mass[0] == 1.0


def test_equality_by_value_and_hash(props):
    again = it.mass_properties((shapes.box(0.1, 0.2, 0.3).vertices, shapes.box(0.1, 0.2, 0.3).faces),
                               density=7850.0)
    assert props == again and hash(props) == hash(again)
    assert props != props.with_mass(2 * props.mass)
    assert props.principal == again.principal
    assert len({props, again}) == 1
    assert point_mass(1.0, [0, 0, 0]) == point_mass(1.0, [0, 0, 0])          # NaN density compares equal
    assert it.stability(props) == it.stability(again)


def test_large_arrays_are_read_only_views_not_copies():
    @frozen_value
    class Holder:
        data: np.ndarray

    big = np.zeros(COPY_LIMIT + 1)
    held = Holder(big)
    assert np.shares_memory(held.data, big) and not held.data.flags.writeable
    assert not np.shares_memory(readonly(np.zeros(3)), np.zeros(3))


def test_one_way_to_principal_axes_on_a_body(props):
    assert not hasattr(props, "principal_axes")
    assert props.principal is props.principal                                  # computed once, read-only
    from inertia_tool.mass.principal import principal_axes
    other = principal_axes(props.inertia, reference_point=props.center_of_mass, mass=props.mass, rtol=1e-3)
    np.testing.assert_array_equal(other.moments, props.principal.moments)


@pytest.mark.parametrize("value", [float("inf"), float("-inf"), float("nan"), np.float64("inf"), [1.0, float("nan")],
                                   np.array([[0.0, np.inf]])])
def test_non_finite_check_refuses_every_non_finite_form(value):
    """The float fast path (no numpy) and the array path both refuse inf and NaN, and name the quantity."""
    from inertia_tool.errors import NonFiniteResultError

    with pytest.raises(NonFiniteResultError, match="the mass is"):
        NonFiniteResultError.check("the mass", value)


@pytest.mark.parametrize("value", [0.0, -1e308, 5e-324, np.float64(2.0), [1.0, 2.0], np.eye(3)])
def test_non_finite_check_accepts_finite_values(value):
    from inertia_tool.errors import NonFiniteResultError

    assert NonFiniteResultError.check("the mass", value) is None


def test_frozen_value_field_names_are_per_class():
    """The cached field names are per class: two value classes with different array fields each make their own
    arrays read-only, and compare by their own compared fields."""
    @frozen_value
    class A:
        x: np.ndarray

    @frozen_value
    class B:
        x: np.ndarray
        y: np.ndarray
        note: str = dataclasses.field(default="", compare=False)

    a, b = A(np.zeros(2)), B(np.zeros(2), np.ones(2), note="n")
    assert not a.x.flags.writeable and not b.x.flags.writeable and not b.y.flags.writeable
    assert b == B(np.zeros(2), np.ones(2), note="other") and hash(b) == hash(B(np.zeros(2), np.ones(2)))
    assert b != B(np.zeros(2), np.zeros(2))


# --- frozen_value writes one __init__ and shares __setattr__/__delattr__ (issue 25 item 4, start-up) --------------

_KINDS = st.sampled_from(["required", "default", "field_default", "factory"])


def _declare(decorator, kinds, flags):
    """A class with one field per kind (in order), decorated by ``decorator``; required fields first, as a
    dataclass demands."""
    kinds = sorted(kinds, key=lambda k: k != "required")
    namespace: dict = {"__annotations__": {}, "__module__": __name__, "__doc__": "a value"}
    for i, (kind, (shown, compared)) in enumerate(zip(kinds, flags)):
        name = f"f{i}"
        namespace["__annotations__"][name] = "float"
        if kind == "default":
            namespace[name] = float(i)
        elif kind == "field_default":
            namespace[name] = dataclasses.field(default=float(i), repr=shown, compare=compared)
        elif kind == "factory":
            namespace[name] = dataclasses.field(default_factory=lambda i=i: np.full(2, float(i)), repr=shown,
                                                compare=compared)
        elif not (shown and compared):
            namespace[name] = dataclasses.field(repr=shown, compare=compared)
    return decorator(type("Value", (), namespace)), kinds


def _reference(cls):
    """What frozen_value promises to behave as: a dataclass made by dataclasses itself (frozen), with the same
    equality, hash and repr."""
    from inertia_tool import values
    built = dataclasses.dataclass(frozen=True, eq=False, repr=False)(cls)
    built.__repr__, built.__eq__, built.__hash__ = values._repr, values._eq, values._hash
    return built


def _outcome(make):
    try:
        value = make()
    except TypeError as exc:
        return ("TypeError", str(exc).split(" ", 1)[1])     # the message without the class's qualified name
    return ("value", repr(value), dataclasses.astuple(value).__repr__(), hash(value))


@settings(max_examples=60, deadline=None)
@given(kinds=st.lists(_KINDS, min_size=0, max_size=5),
       flags=st.lists(st.tuples(st.booleans(), st.booleans()), min_size=5, max_size=5),
       positional=st.integers(0, 6), keywords=st.sets(st.integers(0, 6), max_size=4))
def test_frozen_value_behaves_as_a_frozen_dataclass(kinds, flags, positional, keywords):
    """Against ``dataclasses.dataclass(frozen=True)`` on the same declaration: the same signature, fields,
    repr, equality and hash for every call (too few, too many and unknown arguments raise the same TypeError),
    and assignment and deletion refused with FrozenInstanceError."""
    ours, kinds = _declare(frozen_value, kinds, flags)
    theirs, _ = _declare(_reference, kinds, flags)
    assert str(inspect.signature(ours)) == str(inspect.signature(theirs))
    assert [(f.name, f.repr, f.compare, f.default) for f in dataclasses.fields(ours)] == \
        [(f.name, f.repr, f.compare, f.default) for f in dataclasses.fields(theirs)]
    assert ours.__dataclass_params__.frozen and ours.__match_args__ == theirs.__match_args__
    args = [10.0 + i for i in range(positional)]
    kwargs = {f"f{i}": 20.0 + i for i in keywords}
    assert _outcome(lambda: ours(*args, **kwargs)) == _outcome(lambda: theirs(*args, **kwargs))
    defaults = {f"f{i}": 1.0 for i, kind in enumerate(kinds) if kind == "required"}
    value = ours(**defaults)
    assert value == ours(**defaults) and hash(value) == hash(ours(**defaults))
    assert dataclasses.replace(value) == value and copy.deepcopy(value) == value
    for name in ("f0", "other"):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(value, name, 1.0)
        with pytest.raises(dataclasses.FrozenInstanceError):
            delattr(value, name)


def test_frozen_value_leaves_the_unusual_cases_to_dataclasses():
    """Keyword-only and ``init=False`` fields, and a class with its own ``__init__``, are made by dataclasses
    (frozen): they behave as declared and still refuse assignment."""
    @frozen_value
    class KeywordOnly:
        x: float
        y: float = dataclasses.field(default=2.0, kw_only=True)
        z: float = dataclasses.field(default=3.0, init=False)

    value = KeywordOnly(1.0, y=5.0)
    assert (value.x, value.y, value.z) == (1.0, 5.0, 3.0)
    with pytest.raises(TypeError):
        KeywordOnly(1.0, 5.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        value.x = 0.0


def test_stored_arrays_plain_and_subclass():
    """The inlined path for plain arrays and readonly() for subclasses store the same thing: a read-only
    plain ndarray, copied when small, a view when large."""
    @frozen_value
    class Holder:
        data: np.ndarray

    small, big = np.arange(3.0), np.zeros(COPY_LIMIT + 1)
    class Sub(np.ndarray):
        pass

    sub = np.arange(3.0).view(Sub)
    for source, shares in ((small, False), (big, True), (sub, None)):
        held = Holder(source).data
        assert type(held) is np.ndarray and not held.flags.writeable
        if shares is not None:
            assert np.shares_memory(held, source) == shares
        np.testing.assert_array_equal(held, np.asarray(source))


def test_results_survive_pickling_and_replace(props):
    """Batch workers and Dask move results between processes: unpickling fills the instance dictionary
    without the refusing ``__setattr__`` and makes the arrays read-only again (pickle does not keep the flag:
    before, an unpickled result's centre of mass could be written to), and ``dataclasses.replace`` goes
    through ``__init__``."""
    import pickle
    again = pickle.loads(pickle.dumps(props))
    assert again == props and not again.center_of_mass.flags.writeable
    assert not again.principal.axes.flags.writeable and not again.mesh.bbox_min.flags.writeable
    with pytest.raises(ValueError, match="read-only"):
        again.inertia[0, 0] = 0.0
    renamed = dataclasses.replace(props, name="renamed")
    assert renamed.name == "renamed" and renamed.mass == props.mass
    with pytest.raises(dataclasses.FrozenInstanceError):
        again.mass = 0.0
