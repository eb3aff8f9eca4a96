"""The schema of rl1.toml, the project file (project.py reads it): msgspec Structs that
validate it through rl1.vm.config, the configuration files' one validation layer, and
give editors its JSON Schema (spec/schemas/rl1.schema.json). Imported only when a
project has the file, so that `rl1c check` without one loads no msgspec."""

from __future__ import annotations

from typing import Annotated

import msgspec
from msgspec import UNSET, Meta, Struct, UnsetType

Codes = Annotated[list[str], Meta(extra={"expected": 'a list of codes, such as ["W0601", "W06"]'},
                                  description="codes or prefixes of codes (rl1c explain)")]


class CheckTable(Struct, forbid_unknown_fields=True, rename="kebab"):
    """The options of `rl1c check` that a team shares."""

    select: Codes | UnsetType = UNSET
    ignore: Codes | UnsetType = UNSET
    warnings_as_errors: Annotated[bool, Meta(
        description="a warning fails the check (for CI)")] | UnsetType = UNSET


class ProjectFile(Struct, forbid_unknown_fields=True):
    """rl1.toml: read from the checked file's folder or the nearest folder above it."""

    check: CheckTable = msgspec.field(default_factory=CheckTable)
