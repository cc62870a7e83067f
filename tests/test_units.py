"""``inertia_tool.units``: the density spellings the tool prints read back, and messages read well."""

import pytest

from inertia_tool.errors import UnitsError
from inertia_tool.units import parse_density, parse_length, parse_mass


@pytest.mark.parametrize("text, expected", [
    ("7850", 7850.0), ("7850 kg/m³", 7850.0), ("7850kg/m³", 7850.0), ("7850 kg/m3", 7850.0),
    ("7850 kg/m^3", 7850.0), ("1.24g/cm3", 1240.0), ("1.24 g/cm³", 1240.0), ("0.1 lb/in³", 2767.99047),
    ("62.4 lb/ft³", 62.4 * 16.0184634),
])
def test_density_spellings(text, expected):
    assert parse_density(text) == pytest.approx(expected, rel=1e-12)


def test_printed_density_reads_back():
    from inertia_tool.mass.pipeline import resolve_density
    _, text = resolve_density(density=2712.5)          # "2712.5 kg/m³", as the reports print it
    assert parse_density(text) == 2712.5


@pytest.mark.parametrize("parse, text, message", [
    (parse_density, "1e999", "Expected a density that is a finite number, got '1e999'"),
    (parse_length, "1e999mm", "Expected a length that is a finite number"),
    (parse_mass, "-1e400g", "Expected a mass that is a finite number"),
])
def test_non_finite_message_wording(parse, text, message):
    with pytest.raises(UnitsError) as info:
        parse(text)
    assert str(info.value).startswith(message) and "a finite a" not in str(info.value)


@pytest.mark.parametrize("text", ["\u0663", "\u0661\u0662 kg/m3", "1_000", "inf", "nan"])
def test_one_number_grammar_refuses_what_only_float_reads(text):
    # units.DECIMAL is the grammar of robot files and environment limits too; '٣' (an Arabic-Indic 3) was
    # read here as 3 kg/m³ while robot files refused it
    with pytest.raises(UnitsError):
        parse_density(text)
