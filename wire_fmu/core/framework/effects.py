"""Physical effects a scene may ask a unit to include (SPEC section 12).

Everything a scene does not name is the simplest model; an effect that is
absent adds no state and no work per step. Each unit has an
:class:`EffectCatalogue`; :meth:`EffectCatalogue.parse` turns the text a
scene or an FMU parameter carries (``"rope_damping, sheave_inertia"``) into
a frozen set, or lists every problem with it at once.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from dataclasses import dataclass

__all__ = ["Effect", "EffectCatalogue"]


@dataclass(frozen=True)
class Effect:
    """One optional piece of physics.

    Parameters
    ----------
    name : str
        Identifier used in scenes and FMU parameters.
    absent, present : str
        What the model does without and with it.
    requires : tuple of str
        Effects that must be on for this one to make sense.
    """

    name: str
    absent: str
    present: str
    requires: tuple[str, ...] = ()


@dataclass(frozen=True)
class EffectCatalogue:
    """The effects one unit knows."""

    unit: str
    effects: tuple[Effect, ...]

    @property
    def names(self) -> tuple[str, ...]:
        """Known effect names, in declaration order."""
        return tuple(e.name for e in self.effects)

    def problems(self, requested: Iterable[str]) -> list[str]:
        """Every problem with a requested set of effects.

        Parameters
        ----------
        requested : iterable of str
            Effect names.
        """
        requested = list(requested)
        by_name = {e.name: e for e in self.effects}
        out = []
        for name in requested:
            if name not in by_name:
                close = difflib.get_close_matches(name, self.names, n=1)
                hint = f" (did you mean {close[0]!r}?)" if close else ""
                out.append(
                    f"{self.unit}: unknown effect {name!r}{hint}; known effects: "
                    + ", ".join(self.names)
                )
                continue
            for needed in by_name[name].requires:
                if needed not in requested:
                    out.append(
                        f"{self.unit}: effect {name!r} needs effect {needed!r} as well "
                        f"({by_name[name].present} has no meaning with {by_name[needed].absent})"
                    )
        return out

    def parse(self, text: str | Iterable[str]) -> tuple[frozenset[str], list[str]]:
        """Parse a comma- or space-separated list; return (effects, problems).

        Parameters
        ----------
        text : str or iterable of str
            Effect names, comma or space separated in a string.
        """
        if isinstance(text, str):
            names = [n.strip() for n in text.replace(",", " ").split()]
        else:
            names = [str(n).strip() for n in text]
        names = [n for n in names if n]
        return frozenset(names), self.problems(names)

    def describe(self) -> str:
        """A table of the effects, one per line, for help texts."""
        width = max(len(n) for n in self.names)
        return "\n".join(
            f"{e.name:<{width}}  absent: {e.absent}; present: {e.present}" for e in self.effects
        )
