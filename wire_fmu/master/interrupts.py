"""Ctrl-C and SIGTERM during a run: asked for between macro steps, never inside a unit."""

from __future__ import annotations

import logging
import signal
import threading
from typing import Any

__all__ = ["InterruptRequestedError", "Interrupts"]

logger = logging.getLogger(__name__)


class InterruptRequestedError(Exception):
    """Ctrl-C or SIGTERM was asked for between two macro steps."""


class Interrupts:
    """While a run goes: SIGINT and SIGTERM end it between macro steps.

    A signal then only sets :attr:`requested`, so it never lands inside a
    unit's own code (all our FMUs share this interpreter); the run loop ends
    the run cleanly after the step under way. A second SIGINT raises
    KeyboardInterrupt at once. Outside the main thread nothing is installed.
    """

    def __init__(self) -> None:
        self.requested = False
        self._previous: dict[int, Any] = {}

    def _handle(self, signum: int, frame: Any) -> None:
        if self.requested and signum == signal.SIGINT:
            raise KeyboardInterrupt
        self.requested = True
        logger.warning("interrupted: the run ends after this step (Ctrl-C again to stop now)")

    def __enter__(self) -> Interrupts:
        if threading.current_thread() is threading.main_thread():
            for signum in (signal.SIGINT, signal.SIGTERM):
                self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)
