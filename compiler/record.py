"""`Record`, the base of the front end's small value classes (in place of dataclasses).

`rl1c check` is meant to start in at most twice the time of `python -c pass`
(bench/cold_start.py), and importing `dataclasses` alone would spend a third of that
budget, mostly in `inspect`. So a record class lists its fields in `__slots__` and assigns
each in `__init__`, taking them in that order (a base class's fields first), as
pycparser's AST nodes do. This base gives it the rest of what a frozen dataclass has:
equality and hashing by value, and a readable `repr`.

Records are values: never assign to a field after `__init__`.
"""

from __future__ import annotations

TYPE_CHECKING = False  # `typing` itself costs 4 ms of every start
if TYPE_CHECKING:
    from typing import ClassVar


class Record:
    __slots__ = ()
    fields: ClassVar[tuple[str, ...]] = ()
    """The names of the fields, in the order `__init__` takes them."""

    def __init_subclass__(cls) -> None:
        super().__init_subclass__()
        cls.fields = tuple(name for klass in reversed(cls.__mro__)
                           for name in klass.__dict__.get("__slots__", ()))

    def values(self) -> tuple[object, ...]:
        return tuple([getattr(self, name) for name in self.fields])

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Record) and type(other) is type(self)
                and self.values() == other.values())

    def __hash__(self) -> int:
        return hash((type(self), *self.values()))

    def __repr__(self) -> str:
        shown = ", ".join(f"{name}={getattr(self, name)!r}" for name in self.fields)
        return f"{type(self).__name__}({shown})"
