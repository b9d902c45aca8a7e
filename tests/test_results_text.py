"""The results' numbers as text: every float reads back to the same bits."""

from __future__ import annotations

import csv
import io
import math
import random
import struct
from fractions import Fraction

import numpy as np

from wire_fmu.master.results_text import number_lines


def _bits(value: float) -> int:
    return struct.unpack("<Q", struct.pack("<d", value))[0]


def _cells(text: str) -> list[list[str]]:
    return list(csv.reader(io.StringIO(text, newline="")))


def _random_doubles(count: int, seed: int) -> list[float]:
    """Doubles from random bit patterns (every exponent, subnormals) and everyday values."""
    rng = random.Random(seed)
    values = []
    while len(values) < count:
        value = struct.unpack("<d", struct.pack("<Q", rng.getrandbits(64)))[0]
        if math.isfinite(value):
            values.append(value)
        values.append(rng.uniform(-1e4, 1e4))
        values.append(round(rng.uniform(-10.0, 10.0), rng.randint(0, 6)))
    return values[:count]


def test_every_float_reads_back_to_the_same_bits():
    values = _random_doubles(60_000, seed=16)
    values += [0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, 1.7976931348623157e308]
    values += [1e16, 1e15, 0.1, 0.30000000000000004, 1e-5, 1e-4, 2.5e-7, 123456789.0]
    rows = [values[i : i + 25] for i in range(0, len(values), 25)]
    cells = _cells(number_lines(rows))
    assert len(cells) == len(rows)
    for row, line in zip(rows, cells, strict=True):
        assert len(line) == len(row)
        for value, text in zip(row, line, strict=True):
            assert _bits(float(text)) == _bits(value), (value, text)


def test_no_rows_are_no_text():
    assert number_lines([]) == ""


def test_integers_are_written_as_their_digits_and_lines_end_in_crlf():
    text = number_lines([[0.5, 8247, -3], [1.0, 0, 2_147_483_647]])
    assert text == "0.5,8247,-3\r\n1.0,0,2147483647\r\n"


def test_non_finite_numbers_are_spelt_as_float_reads_them():
    rows = [[0.0, 1.5], [1.0, math.nan], [2.0, math.inf], [3.0, -math.inf], [4.0, 2.5]]
    cells = _cells(number_lines(rows))
    assert [line[1] for line in cells] == ["1.5", "nan", "inf", "-inf", "2.5"]
    assert [float(line[0]) for line in cells] == [0.0, 1.0, 2.0, 3.0, 4.0]


def test_numpy_scalars_are_written_as_their_values():
    rows = [[np.float64(0.1), np.float32(0.25), np.int64(7), np.float64(np.nan)]]
    assert _cells(number_lines(rows)) == [["0.1", "0.25", "7", "nan"]]


def test_other_numbers_are_written_as_their_floats():
    rows = [[Fraction(1, 4), np.array(2.5)], [Fraction(1, 2), np.array(math.inf)]]
    assert _cells(number_lines(rows)) == [["0.25", "2.5"], ["0.5", "inf"]]


def test_an_array_is_written_as_its_rows_as_lists_are():
    values = _random_doubles(5_000, seed=17)
    block = np.array(values).reshape(200, 25)
    assert number_lines(block) == number_lines(block.tolist())
    every_other_column = block[:, ::2]  # not C-ordered: orjson reads only C-ordered arrays
    assert number_lines(every_other_column) == number_lines(every_other_column.tolist())
    assert number_lines(np.empty((0, 3))) == ""


def test_an_array_with_non_finite_numbers_is_written_as_its_rows_as_lists_are():
    block = np.array([[0.0, 1.5], [1.0, math.nan], [2.0, math.inf], [3.0, -math.inf]])
    assert number_lines(block) == number_lines(block.tolist())
    assert [line[1] for line in _cells(number_lines(block))] == ["1.5", "nan", "inf", "-inf"]
