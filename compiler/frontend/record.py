"""`Record`, the base of the front end's small value classes (in place of dataclasses).

`rl1c check` is meant to start in at most twice the time of `python -c pass`
(bench/cold_start.py), and importing `dataclasses` alone would spend a third of that
budget, mostly in `inspect`. So a record class lists its fields in `__slots__` and assigns
each in `__init__`, taking them in that order (a base class's fields first), as
pycparser's AST nodes do. This base gives it the rest of what a dataclass has:
equality and hashing by the fields' values, and a readable `repr`.

Most records are values, never changed after `__init__` (the AST, diagnostics); the
checker's graph fills in its blocks as it builds them. A record used as a dict key or
a set member must not change afterwards.
"""

from __future__ import annotations

from operator import attrgetter

TYPE_CHECKING = False  # `typing` itself costs 4 ms of every start
if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import ClassVar


class Record:
    __slots__ = ()
    fields: ClassVar[tuple[str, ...]] = ()
    """The names of the fields, in the order `__init__` takes them."""

    _get_values: ClassVar[Callable[[Record], tuple[object, ...]]]

    def __init_subclass__(cls) -> None:
        super().__init_subclass__()
        cls.fields = tuple(name for klass in reversed(cls.__mro__)
                           for name in klass.__dict__.get("__slots__", ()))
        # attrgetter reads the fields in C: the language server copies every node below
        # an inserted line (ast.relocate) through `values`.
        if len(cls.fields) > 1:
            cls._get_values = attrgetter(*cls.fields)
        elif cls.fields:  # attrgetter of one name returns the value, not a tuple
            get_only = attrgetter(cls.fields[0])
            cls._get_values = lambda record: (get_only(record),)
        else:
            cls._get_values = lambda record: ()

    def values(self) -> tuple[object, ...]:
        """The fields' values, in the order of `fields`."""
        return type(self)._get_values(self)

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Record) and type(other) is type(self)
                and self.values() == other.values())

    def __hash__(self) -> int:
        return hash((type(self), *self.values()))

    def __repr__(self) -> str:
        shown = ", ".join(f"{name}={getattr(self, name)!r}" for name in self.fields)
        return f"{type(self).__name__}({shown})"
