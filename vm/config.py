"""The one validation layer of the configuration files: sensor scripts (JSON or TOML),
world files and rl1.toml.

Each file's schema is a set of msgspec Structs whose fields carry their ranges
(`msgspec.Meta`), so that the same types validate a file and give editors its JSON
Schema (spec/schemas/). This module reads a file's bytes into data (`read_document`, the
one bounded reader of numbers: UTF-8 with or without a byte order mark, integers of at
most `MAX_DIGITS` digits) and converts the data to a schema (`convert`). Every failure is
a ConfigError naming the file, the line, the key path and what to write:
`w.toml:27: vehicle.tread: 5e-324 is outside 10..1000; write one within it`.

msgspec's errors give a key path but no line, and neither tomllib nor json gives
positions: `config_lines.py` finds the line from the key path in one linear pass.
"""

from __future__ import annotations

import difflib
import json
import math
import re
import sys
import tomllib
import types
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Annotated, Any, Literal, TypeVar, Union, get_args, get_origin

import msgspec
import msgspec.inspect as mi
from msgspec import Meta

from .config_lines import BARE_KEY, KeyPath, first_long_number, line_of
from .language import BUILTINS

T = TypeVar("T")
Syntax = Literal["toml", "json"]

MAX_DIGITS = sys.int_info.default_max_str_digits
"""The most digits of an integer in any configuration file (4,300): Python's own limit on
converting decimal text, which tomllib meets past it, and the JSON reader's hook
enforces. No value of these files is near that long; the range checks refuse the long
ones that remain, quoting only a few digits."""

_EXCERPT = 40  # characters of a key or string quoted in a message

# The types that more than one file's schema uses.
Int16 = Annotated[int, Meta(ge=-32768, le=32767)]
Byte = Annotated[int, Meta(ge=0, le=255)]
INPUT_PORTS = BUILTINS["INP"].forms[0].params[0]
"""The ports (INP p) reads: what a port's name (PortName) may number."""
PortName = Annotated[str, Meta(pattern=r"^[0-9]{1,6}$", extra={
    "expected": f'a port number {INPUT_PORTS.low}..{INPUT_PORTS.high} in quotes, such as "3"'})]


class ConfigError(Exception):
    """A configuration file that cannot be used: `file:line: where: what`, the line
    (1-based) when it is known and `where` the key path; `problem` is what follows the
    place, `where: what`."""

    def __init__(self, file: str, line: int | None, where: str, detail: str) -> None:
        at = f"{file}:{line}" if line is not None else file
        self.problem = f"{where}: {detail}" if where else detail
        super().__init__(f"{at}: {self.problem}")
        self.file = file
        self.line = line
        self.where = where
        self.detail = detail


def error_at(name: str, text: str, path: KeyPath, detail: str,
             syntax: Syntax = "toml") -> ConfigError:
    """The ConfigError of a check that spans keys (a loader's own), at `path` in the
    file `name` whose text is `text`."""
    return ConfigError(name, line_of(text, path, syntax), describe_path(path), detail)


def excerpt(text: str) -> str:
    """`text`, cut to a short excerpt for a message."""
    return text if len(text) <= _EXCERPT else text[:_EXCERPT] + "..."


def written_key(key: str, syntax: Syntax) -> str:
    """`key` as a file of `syntax` writes it: in quotes, unless TOML takes it bare."""
    return key if syntax == "toml" and BARE_KEY.fullmatch(key) else json.dumps(key)


def unknown_key(key: str, known: Sequence[str], quote: Callable[[str], str] = str) -> str:
    """What a table of the keys `known` says of the key `key` it does not have."""
    return "unknown key; " + one_of(key, known, quote)


def one_of(word: str, choices: Sequence[str], quote: Callable[[str], str] = str) -> str:
    """What to write instead of `word`, which is none of `choices`: the choices, each
    written by `quote`, and the one `word` is likely a misspelling of (its case aside),
    when one is closer than any other."""
    listed = ", ".join(quote(choice) for choice in choices)
    likely = _closest(word.lower(), {choice.lower(): choice for choice in reversed(choices)})
    if likely is None:
        return f"expected one of {listed}"
    # The guess first: a long message is cut at its end when shown.
    return f"did you mean {quote(likely)}? (expected one of {listed})"


def _closest(word: str, choices: Mapping[str, str]) -> str | None:
    """The value of the key of `choices` closest to `word`; None when none is close, or
    two are as close (`CAM X` is as near to `CAM A` as to `CAM Z`: a guess would mislead)."""
    if len(word) > _EXCERPT:  # a long word is no misspelling, and costly to compare
        return None
    close = difflib.get_close_matches(word, choices, n=2)
    # Rated as get_close_matches rates them: the choice first.
    ratios = [difflib.SequenceMatcher(None, choice, word).ratio() for choice in close]
    if not close or (len(close) == 2 and ratios[0] == ratios[1]):
        return None
    return choices[close[0]]


def describe_path(path: KeyPath) -> str:
    """`stands[0].x`, `ports.3`, `CAM R[2]`: a key path as messages write it."""
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{excerpt(part)}" if text
                                                            else excerpt(part))
    return text


# Reading ------------------------------------------------------------------------------


def decode_text(data: bytes, name: str) -> str:
    """The text of a configuration file: UTF-8, a byte order mark allowed (as in
    sources)."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise ConfigError(name, None, "", f"not UTF-8 text (byte {error.start}); save "
                          "the file as UTF-8") from None
    return text.removeprefix("\ufeff")


def read_document(data: bytes, name: str, syntax: Syntax) -> tuple[Any, str]:
    """The data of a TOML or JSON file and its text; ConfigError when it is not valid,
    at the line of a number longer than MAX_DIGITS digits."""
    text = decode_text(data, name)
    what = "TOML" if syntax == "toml" else "JSON"
    try:
        if syntax == "toml":
            document = tomllib.loads(text)
            if _holds_a_huge_int(document):  # 0x, 0o and 0b integers are read unbounded
                raise ValueError("an integer too long")
            return document, text
        return json.loads(text, parse_int=_bounded_int, parse_constant=_refuse_constant), text
    except tomllib.TOMLDecodeError as error:
        # tomllib (before Python 3.14) gives the place only in its message.
        place = _TOML_PLACE.search(str(error))
        if place is None:
            raise ConfigError(name, None, "", f"invalid TOML: {error}") from None
        raise ConfigError(name, int(place["line"]), "", f"invalid TOML: "
                          f"{str(error)[:place.start()]}(column {place['column']})") from None
    except json.JSONDecodeError as error:
        raise ConfigError(name, error.lineno, "", f"invalid JSON: {error.msg} (column "
                          f"{error.colno})") from None
    except RecursionError:
        raise ConfigError(name, None, "", f"invalid {what}: arrays or tables nested too "
                          "deeply to read") from None
    except ValueError as error:  # an integer longer than MAX_DIGITS digits
        found = first_long_number(text, syntax, MAX_DIGITS)
        if found is None:
            raise ConfigError(name, None, "", f"invalid {what}: {error}") from None
        line, path = found
        raise ConfigError(name, line, describe_path(path), "a number of more than "
                          f"{MAX_DIGITS} digits; no value here is near that "
                          "long") from None


_TOML_PLACE = re.compile(r"\(at line (?P<line>\d+), column (?P<column>\d+)\)$")


# The bits of the largest integer of MAX_DIGITS decimal digits: any longer one, however it
# is written, could not even be shown in a message.
MAX_BITS: int = (10**MAX_DIGITS - 1).bit_length()


def _holds_a_huge_int(value: object) -> bool:
    match value:
        case bool():
            return False
        case int():
            return value.bit_length() > MAX_BITS
        case dict():
            return any(_holds_a_huge_int(item) for item in value.values())
        case list():
            return any(_holds_a_huge_int(item) for item in value)
    return False


def _bounded_int(digits: str) -> int:
    if len(digits.lstrip("-")) > MAX_DIGITS:
        raise ValueError(digits[:20])
    return int(digits)


def _refuse_constant(constant: str) -> float:
    """JSON has no NaN or Infinity; Python's reader takes them unless told."""
    raise json.JSONDecodeError(f"{constant} is not a JSON number", constant, 0)


# Files given for one another ----------------------------------------------------------


@dataclass(frozen=True, slots=True)
class FileKind:
    """A kind of configuration file, so that one given where another is wanted is
    named as what it is, with the option that takes it."""

    what: str
    option: str
    page: str
    marks: tuple[str, ...]  # top-level keys that files of this kind have, and no other

    def mistaken_for(self, other: FileKind, mark: str | None = None) -> str:
        has = f" (it has `{mark}`)" if mark is not None else ""
        return (f"this looks like {other.what}{has}, not {self.what}: give it to "
                f"`{other.option}` ({other.page})")

    def refuse_other(self, document: object, name: str, other: FileKind) -> None:
        """ConfigError when `document` has keys of `other`'s kind and none of this one's."""
        if not isinstance(document, dict) or any(mark in document for mark in self.marks):
            return
        mark = next((mark for mark in other.marks if mark in document), None)
        if mark is not None:
            raise ConfigError(name, None, "", self.mistaken_for(other, mark))


WORLD = FileKind("a world file", "rl1c sim --world", "spec/simulator.md", ("floor", "start"))
"""Every world file has these tables (vm/sim/world.py's WorldFile requires them)."""

SENSOR_SCRIPT = FileKind("a sensor script", "rl1c run --sensors", "spec/sensors.md",
                         ("IMG", "KYO", "CAM R", "ULT A", "ULT B", "ULT C", "ULT D", "INP",
                          "FZI", "line_lost", "fail", "stop_fails", "after_last"))
"""The keys of a sensor script (vm/sensor_script.py's ScriptFile) but its comment."""


# Converting ---------------------------------------------------------------------------

_AT = re.compile(r" - at `(?:(key)` in `)?(\$[^`]*)`$")
_PART = re.compile(r"\.([^.\[]+)|\[(\d+|\.\.\.)\]")
_MISSING = "Object missing required field `"
_UNKNOWN = "Object contains unknown field `"


def convert(document: object, schema: type[T], name: str, text: str,
            syntax: Syntax = "toml") -> T:
    """`document` converted to `schema`; ConfigError with the file, line and key path of
    the first problem, saying what the schema expects there and what the file has."""
    try:
        return msgspec.convert(document, schema)
    except msgspec.ValidationError as error:
        message = str(error)
    except UnicodeEncodeError:  # JSON's reader takes "\ud800", half a UTF-16 pair
        raise error_at(name, text, _surrogate_at(document) or (), "a string holds half of a "
                       "UTF-16 pair (an escape \\uD800 to \\uDFFF without its other half), "
                       "which is no character; write the character itself, or both halves "
                       "of its pair", syntax) from None
    at = _AT.search(message)
    path, kind = _path(at.group(2) if at else "$", document, schema)
    what = message[:at.start()] if at else message
    value = _value_at(document, path)
    if what.startswith(_MISSING):
        detail = _missing(kind, path, value, syntax)
    elif what.startswith(_UNKNOWN):
        known = _keys(kind)
        unknown = (next((key for key in value if key not in known), None)
                   if isinstance(value, Mapping) else None)
        key = what[len(_UNKNOWN):-1] if unknown is None else unknown
        path = (*path, key)
        detail = unknown_key(key, known, lambda name: written_key(name, syntax))
    elif at is not None and at.group(1) == "key" and isinstance(value, Mapping):
        path = (*path, _first_failing(value, kind))
        key_kind = get_args(_strip(kind))[0]
        detail = f"expected {expected(mi.type_info(key_kind), syntax)}"
    else:
        detail = _mismatch(kind, value, syntax)
    raise error_at(name, text, path, detail, syntax)


def _surrogate_at(value: object, path: KeyPath = ()) -> KeyPath | None:
    """The path of the first key or string in `value` that holds a surrogate; None when
    none does."""
    match value:
        case str():
            return path if _SURROGATE.search(value) else None
        case dict():
            for key, item in value.items():
                if isinstance(key, str) and _SURROGATE.search(key):
                    return (*path, key)
                if (found := _surrogate_at(item, (*path, key))) is not None:
                    return found
        case list():
            for index, item in enumerate(value):
                if (found := _surrogate_at(item, (*path, index))) is not None:
                    return found
    return None


_SURROGATE = re.compile("[\ud800-\udfff]")


def _path(text: str, document: object, schema: Any) -> tuple[KeyPath, Any]:
    """msgspec's `$.stands[0].x` as a key path, with the schema's type there; a `[...]`
    (a table's key, which msgspec does not name) becomes the first key whose entry fails
    alone. The schemas' field names hold no `.` or `[`, so the text splits plainly."""
    path: list[str | int] = []
    kind, value = schema, document
    for match in _PART.finditer(text):
        field, index = match.groups()
        part: str | int
        if field is not None:
            part = field
        elif index == "..." and isinstance(value, Mapping):
            part = _first_failing(value, kind)
        else:
            part = int(index)
        path.append(part)
        kind, value = _child(kind, part), _step(value, part)
    return tuple(path), kind


def _first_failing(mapping: Mapping[str, object], kind: Any) -> str:
    """The first key of `mapping` whose entry alone is not a valid `kind`."""
    for key, value in mapping.items():
        try:
            msgspec.convert({key: value}, kind)
        except msgspec.ValidationError:
            return key
    return "..."  # every entry is valid alone: msgspec's own placeholder


def _strip(kind: Any) -> Any:
    """`kind` without Annotated and without None in a union; of a union of one table
    and values (a world's `noise = false` or [noise] table), the table, which a key
    path goes into."""
    while True:
        if get_origin(kind) is Annotated:
            kind = get_args(kind)[0]
            continue
        bare = _without_none(kind)
        if get_origin(bare) in (Union, types.UnionType):
            tables = [arg for arg in get_args(bare) if _is_table(arg)]
            bare = tables[0] if len(tables) == 1 else bare
        if bare is kind:
            return kind
        kind = bare


def _without_none(kind: Any) -> Any:
    """`kind` without None or UNSET (a key left out) in a union, its constraints kept."""
    if get_origin(kind) in (Union, types.UnionType):
        rest = [arg for arg in get_args(kind) if arg not in (type(None), msgspec.UnsetType)]
        if len(rest) == 1:
            return rest[0]
    return kind


def _child(kind: Any, part: str | int) -> Any:
    """The schema's type at `part` inside a value of type `kind`."""
    kind = _strip(kind)
    origin, args = get_origin(kind), get_args(kind)
    if isinstance(kind, type) and issubclass(kind, msgspec.Struct):
        return next((field.type for field in msgspec.structs.fields(kind)
                     if field.encode_name == part), Any)
    if origin is list:
        return args[0]
    if origin is tuple and isinstance(part, int):
        return args[0] if args[-1] is Ellipsis else args[min(part, len(args) - 1)]
    if origin is dict:
        return args[1]
    return Any


def _step(value: object, part: str | int) -> object:
    match value:
        case Mapping():
            return value.get(part)
        case list() if isinstance(part, int) and part < len(value):
            return value[part]
    return None


def _value_at(document: object, path: KeyPath) -> object:
    for part in path:
        document = _step(document, part)
    return document


def _is_table(kind: Any) -> bool:
    kind = _strip(kind)
    return isinstance(kind, type) and issubclass(kind, msgspec.Struct)


def _missing(kind: Any, path: KeyPath, value: object, syntax: Syntax) -> str:
    """What to add to the table `value` of schema type `kind` at `path`."""
    keys = [field.encode_name for field in msgspec.structs.fields(_strip(kind))
            if field.required and not (isinstance(value, Mapping) and field.encode_name in value)]
    if syntax == "json":
        named = [json.dumps(key) for key in keys]
        return f"missing {', '.join(named)}; write {named[0]}: ..."
    if _is_table(_child(kind, keys[0])):
        return f"missing the [{describe_path((*path, keys[0]))}] table; add one"
    return "missing " + ", ".join(f"`{key}`" for key in keys) + f"; write `{keys[0]} = ...`"


def _keys(kind: Any) -> list[str]:
    """The keys of the table type `kind`, as the file writes them."""
    return [field.encode_name for field in msgspec.structs.fields(_strip(kind))]


def _mismatch(kind: Any, value: object, syntax: Syntax) -> str:
    info = mi.type_info(_without_none(kind))
    bare = info.type if isinstance(info, mi.Metadata) else info
    number = isinstance(value, int | float) and not isinstance(value, bool)
    if number and isinstance(bare, mi.IntType | mi.FloatType) and (
            isinstance(value, int) or isinstance(bare, mi.FloatType)):
        assert isinstance(value, int | float)
        if isinstance(value, float) and not math.isfinite(value):
            return f"{value} is not a finite number; write one{_range(bare)}"
        if bare.le is not None and (bare.ge is not None or bare.gt is not None):
            return f"{found(value, syntax)} is outside{_range(bare)[3:]}; write one within it"
        return f"{found(value, syntax)} is not{_range(bare)}; write one that is"
    return f"expected {expected(info, syntax)}, found {found(value, syntax)}"


def _range(info: mi.IntType | mi.FloatType) -> str:
    """`in 0..255`, `of at least 1`, or nothing: the range a number has to be in."""
    low = (_number(info.ge) if info.ge is not None else
           f"(more than {_number(info.gt)})" if info.gt is not None else None)
    high = _number(info.le) if info.le is not None else None
    if low is not None and high is not None:
        return f" in {low}..{high}"
    if low is not None:
        return f" of at least {low}"
    return f" of at most {high}" if high is not None else ""


def _number(bound: float) -> str:
    return str(bound) if isinstance(bound, int) else f"{bound:g}"


def expected(info: mi.Type, syntax: Syntax) -> str:
    """What a value of schema type `info` is, for a message: `an integer in 0..255`."""
    match info:
        case mi.Metadata():
            extra = info.extra or {}
            return str(extra["expected"]) if "expected" in extra else expected(info.type, syntax)
        case mi.IntType():
            return "an integer" + _range(info)
        case mi.FloatType():
            return "a number" + _range(info)
        case mi.BoolType():
            return "true or false"
        case mi.StrType():
            return "a string"
        case mi.LiteralType():
            return " or ".join(json.dumps(value) for value in info.values)
        case mi.ListType():
            least = f"at least {info.min_length} " if info.min_length else ""
            return f"an array of {least}{_plural(info.item_type, syntax)}"
        case mi.TupleType():
            return f"an array of {len(info.item_types)} {_plural(info.item_types[0], syntax)}"
        case mi.StructType() | mi.DictType():
            return "a table" if syntax == "toml" else "an object"
        case mi.UnionType():
            return " or ".join(expected(t, syntax) for t in info.types
                               if not isinstance(t, mi.NoneType))
    return "a value"


def _plural(info: mi.Type, syntax: Syntax) -> str:
    match info:
        case mi.Metadata():
            extra = info.extra or {}
            return str(extra["plural"]) if "plural" in extra else _plural(info.type, syntax)
        case mi.IntType():
            return "integers"
        case mi.FloatType():
            return "numbers"
        case mi.StrType():
            return "strings"
        case mi.StructType() | mi.DictType():
            return "tables" if syntax == "toml" else "objects"
    return "arrays" if isinstance(info, mi.ListType | mi.TupleType) else "values"


def found(value: object, syntax: Syntax) -> str:
    """What a file has, for a message, never more than a short excerpt."""
    match value:
        case bool():
            return "true" if value else "false"
        case int():
            digits = len(str(abs(value)))
            return str(value) if digits <= 20 else f"a number of {digits} digits"
        case float():
            return repr(value)
        case str():
            return f'the string "{excerpt(value)}"'
        case Mapping():
            return "a table" if syntax == "toml" else "an object"
        case []:
            return "an empty array"
        case list():
            return f"an array of {len(value)} item{'' if len(value) == 1 else 's'}"
        case None:
            return "null"
    return "a date or time"
