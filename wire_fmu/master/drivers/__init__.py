"""Drivers: time signals a scene applies to unit inputs.

A driver gives a value and its time derivative, so that a (position,
velocity) pair of inputs is driven consistently: vessel heave drives
``mover_b.position`` with :meth:`Driver.value` and ``mover_b.velocity`` with
:meth:`Driver.rate`. Values are in the unit of the input they drive (the
driver itself is unit-agnostic), times in s, rates in that unit per second.

A scene describes a driver as a plain TOML table whose ``kind`` selects one
entry of :data:`DRIVER_KINDS`; :func:`make_driver` checks the table and
builds the driver, or lists every problem with it at once.

=============  ==============================================================
kind           keys (defaults)
=============  ==============================================================
``constant``   ``value``
``ramp``       ``points = [[t0, v0], [t1, v1], ...]`` (times strictly
               increasing), or the short form ``start_time`` (0),
               ``end_time``, ``start_value``, ``end_value``
``sine``       ``amplitude``; ``period`` (s) or ``frequency`` (Hz);
               ``phase_deg`` (0), ``offset`` (0), ``start_time`` (0),
               ``ramp_time`` (0)
``sea_state``  ``significant_height`` (m), ``peak_period`` (s);
               ``spectrum`` ("jonswap" or "pierson_moskowitz"), ``gamma``
               (3.3), ``components`` (200), ``seed`` (0), ``cutoff``
               ([0.5, 4.0] times the peak frequency), ``start_time`` (0),
               ``ramp_time`` (0), ``heave_rao`` (1)
``table``      ``file`` (CSV, relative to the scene's folder),
               ``time_column`` ("time"), ``value_column`` ("value")
=============  ==============================================================

Conventions
-----------
* Piecewise linear drivers (``ramp``, ``table``) hold their first value
  before the first point and their last value after the last one (rate 0
  there). Between points the rate is the slope of the segment that starts at
  or before ``t`` (right-continuous: at a breakpoint the rate is that of the
  segment that begins there, which is what a master evaluating at the start
  of a step wants).
* ``sine``: ``offset + amplitude * sin(2 pi (t - start_time) / period +
  phase)`` for ``t >= start_time``, ``offset`` before.
* Fade-in (``ramp_time`` > 0, ``sine`` and ``sea_state``): the oscillating
  part is multiplied by ``w = (1 - cos(pi (t - start_time) / ramp_time)) / 2``
  over ``ramp_time``, so it and its rate both start at exactly zero: a scene
  that starts in static equilibrium has no start-up transient.
* ``sea_state``: see :class:`SeaStateDriver` and :func:`jonswap_spectrum`.
  The default band [0.5, 4] omega_p loses about 0.3-0.5 % of m0 (the tail
  above 4 omega_p); a constant ``heave_rao`` scales the wave elevation to
  vessel heave.
* ``table``: a comma-separated UTF-8 text file (a regular file of at most
  :data:`MAX_TABLE_BYTES`) with a header row naming the columns (names are
  stripped of spaces; a UTF-8 byte-order mark is ignored), then at least
  two data rows; blank lines and lines starting with ``#`` are skipped; the
  time column must be strictly increasing. A file that is not such a table
  is reported without quoting it (the first line of a file pointed at by
  mistake may be a secret): the column names are listed only when the rows
  under them are all numbers, and a bad cell is quoted only if it is short.
* Every number must be finite and so must what the driver computes from it
  (slopes, angular frequencies, wave amplitudes); values quoted in problems
  are shortened, so a huge array in a scene gives a short message.

Every driver's :meth:`~Driver.value` and :meth:`~Driver.rate` also accept an
array of times (s) and then return an array; a float gives a float.

Modules: :mod:`.protocol` (the :class:`Driver` protocol, fade-in),
:mod:`.simple` (constant, piecewise linear, sine), :mod:`.sea_state` (sea
state and wave spectra), :mod:`.table` (CSV tables), :mod:`.spec_reading`
(reading a scene table), :mod:`.builders` and :mod:`.registry`
(:data:`DRIVER_KINDS`, :func:`make_driver`). The package is also bundled
into the generated signals FMU (:mod:`wire_fmu.interop.signals`), each
module as a top-level module: it imports only the standard library, numpy
and its own modules, those with ``from .module import ...``.
"""

from __future__ import annotations

from .protocol import Driver
from .registry import DRIVER_KINDS, DriverKind, make_driver
from .sea_state import SPECTRA, SeaStateDriver, jonswap_spectrum, pierson_moskowitz_spectrum
from .simple import ConstantDriver, PiecewiseLinearDriver, SineDriver
from .table import MAX_TABLE_BYTES

__all__ = [
    "Driver",
    "DriverKind",
    "DRIVER_KINDS",
    "make_driver",
    "ConstantDriver",
    "PiecewiseLinearDriver",
    "SineDriver",
    "SeaStateDriver",
    "pierson_moskowitz_spectrum",
    "jonswap_spectrum",
    "SPECTRA",
    "MAX_TABLE_BYTES",
]
