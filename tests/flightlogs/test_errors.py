"""The error and warning hierarchy, and :func:`collected_warnings`: a result keeps its warnings, the caller sees them."""

from __future__ import annotations

import inspect
import warnings

import pytest

from flightlogs import errors
from flightlogs.errors import (
    DataError,
    DataQualityWarning,
    FitWarning,
    LogCorruptionWarning,
    SysidWarning,
    collected_warnings,
)


def _dropped_samples() -> None:
    """A helper deep in a reader: it warns, and knows nothing of results."""
    warnings.warn(DataQualityWarning("q: dropped 3 of 100 samples"), stacklevel=2)


def _build() -> tuple[str, ...]:
    """A function that builds a result: the helper's warnings become its field."""
    with collected_warnings() as caught:
        _dropped_samples()
        return caught.messages


def test_every_warning_is_a_sysid_warning_and_a_user_warning() -> None:
    for category in (DataQualityWarning, LogCorruptionWarning, FitWarning):
        assert issubclass(category, SysidWarning) and issubclass(category, UserWarning)
        assert not issubclass(category, errors.SysidError)


def test_a_helpers_warning_reaches_the_result_and_the_caller() -> None:
    with pytest.warns(DataQualityWarning, match=r"^q: dropped 3 of 100 samples$") as raised:
        notes = _build()
    assert notes == ("q: dropped 3 of 100 samples",)
    assert len(raised) == 1
    (warning,) = raised
    # raised again where the helper put it (stacklevel=2: the line in _build that called it)
    lines, first = inspect.getsourcelines(_build)
    assert warning.filename == __file__
    assert lines[warning.lineno - first].strip() == "_dropped_samples()"


def test_the_result_keeps_its_warnings_whatever_the_filters() -> None:
    with warnings.catch_warnings(record=True) as raised:
        warnings.simplefilter("ignore")
        notes = _build()
    assert notes == ("q: dropped 3 of 100 samples",) and raised == []


def test_under_warnings_as_errors_the_warning_is_raised_after_the_work() -> None:
    done = []

    def build() -> tuple[str, ...]:
        with collected_warnings() as caught:
            _dropped_samples()
            done.append("rest of the work")
            return caught.messages

    with warnings.catch_warnings():
        warnings.simplefilter("error", DataQualityWarning)
        with pytest.raises(DataQualityWarning, match="dropped 3 of 100"):
            build()
    assert done == ["rest of the work"]  # the helper was not interrupted; the result was not returned


def test_an_error_leaving_the_block_is_the_one_seen() -> None:
    def build() -> None:
        with collected_warnings():
            _dropped_samples()
            raise DataError("flight.ulg: no attitude")

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(DataError, match="no attitude"):
            build()
    with pytest.warns(DataQualityWarning, match="dropped 3"), pytest.raises(DataError):
        build()  # shown, under the default filters, before the error


def test_discarded_warnings_are_not_raised_again() -> None:
    with warnings.catch_warnings(record=True) as raised:
        warnings.simplefilter("always")
        with collected_warnings() as caught:
            _dropped_samples()
            caught.discard()  # a first pass, redone below
            warnings.warn(DataQualityWarning("q: dropped 2 of 100 samples"), stacklevel=1)
    assert caught.messages == ("q: dropped 2 of 100 samples",)
    assert [str(w.message) for w in raised] == ["q: dropped 2 of 100 samples"]


def test_nested_collectors_raise_each_warning_once() -> None:
    with pytest.warns(DataQualityWarning) as raised:
        with collected_warnings() as outer:
            inner = _build()
    assert inner == outer.messages == ("q: dropped 3 of 100 samples",)
    assert len(raised) == 1


def test_other_warnings_pass_through_untouched() -> None:
    with pytest.warns(RuntimeWarning, match="overflow"):
        with collected_warnings() as caught:
            warnings.warn("overflow in exp", RuntimeWarning, stacklevel=1)
    assert caught.messages == ()
