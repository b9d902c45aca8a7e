"""Getters that answer a tuple for any number of keys (core/framework/tuple_getter.py)."""

from __future__ import annotations

from operator import attrgetter, itemgetter
from types import SimpleNamespace

import pytest

from wire_fmu.core.framework.tuple_getter import tuple_getter


@pytest.mark.parametrize("keys", [[], ["b"], ["c", "a"], ["a", "b", "c"]])
def test_a_getter_answers_a_tuple_in_the_keys_order(keys):
    values = {"a": 1.0, "b": 2, "c": "three"}
    assert tuple_getter(itemgetter, keys)(values) == tuple(values[k] for k in keys)
    record = SimpleNamespace(**values)
    assert tuple_getter(attrgetter, keys)(record) == tuple(values[k] for k in keys)


def test_a_missing_key_raises_as_the_operator_does():
    with pytest.raises(KeyError):
        tuple_getter(itemgetter, ["x"])({"a": 1})
    with pytest.raises(AttributeError):
        tuple_getter(attrgetter, ["x", "a"])(SimpleNamespace(a=1))
