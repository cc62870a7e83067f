"""The check of a COLLADA document's ``<float_array>`` text (``read_collada._check_collada_floats``) against
its first definition (issue 23, import17): the arrays found by two searches (an opening tag, then the first closing
tag after it) are those of the one lazy pattern ``<float_array ...>(.*?)</float_array>`` it replaced, and a
document is refused, with the same message, exactly when the pattern searches of that definition refuse it.

Independent code: the old definition, restated here; hypothesis documents are made of the fragments that decide
the outcome (tags with and without a namespace prefix, self-closing and unclosed tags, closing tags with spaces,
arrays nested or adjacent, numbers with big exponents, NaN, bytes outside the decimal alphabet, every white-space
byte), and every COLLADA file of the repository's test data is compared too.
"""

from __future__ import annotations

import glob
import os
import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from inertia_tool.errors import MeshReadError
from inertia_tool.mesh.read_collada import _check_collada_floats, _float_arrays

HERE = os.path.dirname(os.path.abspath(__file__))

# the definition before issue 23's import17 round, as it stood in read_collada
_OLD_FLOAT_ARRAY = re.compile(rb"<(?:\w+:)?float_array\b[^>]*(?<!/)>(.*?)</(?:\w+:)?float_array\s*>", re.DOTALL)
_OLD_NOT_DECIMAL = re.compile(rb"[^0-9eE+\-.\s]")
_OLD_BIG_EXPONENT = re.compile(rb"[eE]\+?0*([1-9][0-9]+)")


def _old_check(name: str, data: bytes) -> None:
    for match in _OLD_FLOAT_ARRAY.finditer(data):
        big = _OLD_BIG_EXPONENT.search(match.group(1))
        if big is not None and int(big.group(1)) >= 38:
            raise MeshReadError(f"{name}: a <float_array> holds a number with exponent {int(big.group(1))}, "
                                "beyond float32 (the COLLADA reader would make it infinite)")
        bad = _OLD_NOT_DECIMAL.search(match.group(1))
        if bad is not None:
            start = match.group(1).rfind(b" ", 0, bad.start()) + 1
            token = match.group(1)[start:start + 24].split()[0].decode("utf-8", "replace")
            raise MeshReadError(f"{name}: a <float_array> holds {token!r}, not a finite decimal number "
                                "(NaN and infinity are refused: the COLLADA reader would turn NaN into 0)")


def _outcome(check, data: bytes) -> str | None:
    try:
        check("doc.dae", data)
    except MeshReadError as exc:
        return str(exc)
    return None


_FRAGMENTS = st.sampled_from([
    b"<float_array>", b'<float_array id="a" count="3">', b"<c:float_array>", b"<float_array/>",
    b'<float_array id="x"/>', b"<float_arrays>", b"<float_array\n>", b"</float_array>", b"</float_array  >",
    b"</c:float_array>", b"</float_array", b"</float_arrayx>", b"<source>", b"</source>", b">", b"<", b"/",
    b"1.5 ", b"-2e-05 ", b"3E+01 ", b"4e38 ", b"5e+038 ", b"6e0038 ", b"7e37 ", b"1e999 ", b"nan ", b"inf ",
    b"NaN", b"x", b"\x00", b"\xff", b"\t", b"\n", b"\x0b", b"\x0c", b"\r", b" ", b"+", b"-", b".", b"e", b"E",
    b"0", b"9", b"12345678901234567890123456789 ",
])


@settings(max_examples=400, deadline=None)
@given(st.lists(_FRAGMENTS, max_size=40), st.binary(max_size=12))
def test_arrays_and_refusals_are_those_of_the_lazy_pattern(fragments, noise):
    data = b"".join(fragments) + noise
    assert list(_float_arrays(data)) == [m.group(1) for m in _OLD_FLOAT_ARRAY.finditer(data)]
    assert _outcome(_check_collada_floats, data) == _outcome(_old_check, data)


@settings(max_examples=200, deadline=None)
@given(st.binary(max_size=64))
def test_any_bytes_in_one_array_are_judged_as_before(text):
    data = b'<float_array id="p" count="9">' + text + b"</float_array>"
    assert _outcome(_check_collada_floats, data) == _outcome(_old_check, data)


def test_a_nan_and_a_big_exponent_are_still_refused():
    with pytest.raises(MeshReadError, match="holds 'nan'"):
        _check_collada_floats("d.dae", b"<float_array>1 2 nan 4</float_array>")
    with pytest.raises(MeshReadError, match="exponent 39"):
        _check_collada_floats("d.dae", b"<float_array>1 2e+039 4</float_array>")
    _check_collada_floats("d.dae", b"<float_array>1 -2.5e-05\t3E+37\r\n4</float_array>")


@pytest.mark.parametrize("path", sorted(glob.glob(os.path.join(HERE, "**", "*.dae"), recursive=True)),
                         ids=os.path.basename)
def test_repository_collada_files_give_the_same_arrays(path):
    with open(path, "rb") as fh:
        data = fh.read()
    assert list(_float_arrays(data)) == [m.group(1) for m in _OLD_FLOAT_ARRAY.finditer(data)]
    assert _outcome(_check_collada_floats, data) == _outcome(_old_check, data)
