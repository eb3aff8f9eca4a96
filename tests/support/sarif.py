"""The essential parts of the SARIF 2.1.0 schema, as a small checker for the tests.

The schema itself cannot be downloaded here. This models the objects rl1c writes with
the properties the schema allows for them (every SARIF object has
`additionalProperties: false`), the required ones, the enumerations and minimums; plus
three rules of the SARIF text the schema cannot state: ruleIndex points at the rule
named by ruleId, a region does not end before it starts, and a URI is well formed.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

Check = Callable[[Any, str], list[str]]


def string(value: Any, where: str) -> list[str]:
    return [] if isinstance(value, str) else [f"{where}: not a string"]


def integer(minimum: int) -> Check:
    def check(value: Any, where: str) -> list[str]:
        if not isinstance(value, int) or isinstance(value, bool):
            return [f"{where}: not an integer"]
        return [] if value >= minimum else [f"{where}: {value} < {minimum}"]
    return check


def enum(*values: str) -> Check:
    def check(value: Any, where: str) -> list[str]:
        return [] if value in values else [f"{where}: {value!r} not one of {values}"]
    return check


_URI = re.compile(r"(?:[A-Za-z0-9\-._~:/?#\[\]@!$&'()*+,;=]|%[0-9A-Fa-f]{2})*")


def uri_reference(value: Any, where: str) -> list[str]:
    if not isinstance(value, str) or not _URI.fullmatch(value):
        return [f"{where}: {value!r} is not a URI reference"]
    return []


def array(item: Check, *, min_items: int = 0, unique: bool = False) -> Check:
    def check(value: Any, where: str) -> list[str]:
        if not isinstance(value, list):
            return [f"{where}: not an array"]
        problems = [] if len(value) >= min_items else [f"{where}: fewer than {min_items}"]
        if unique and len({repr(element) for element in value}) != len(value):
            problems.append(f"{where}: items not unique")
        for index, element in enumerate(value):
            problems += item(element, f"{where}[{index}]")
        return problems
    return check


def obj(kind: str) -> Check:
    def check(value: Any, where: str) -> list[str]:
        properties, required = SCHEMA[kind]
        if not isinstance(value, dict):
            return [f"{where}: not an object ({kind})"]
        problems = [f"{where}: missing {name!r} ({kind})"
                    for name in sorted(required - value.keys())]
        for name, element in value.items():
            if name not in properties:
                problems.append(f"{where}: {name!r} is not a property of {kind}")
            else:
                problems += properties[name](element, f"{where}.{name}")
        return problems + EXTRA_RULES.get(kind, _nothing)(value, where)
    return check


def _nothing(value: Any, where: str) -> list[str]:
    return []


_LEVEL = enum("none", "note", "warning", "error")
_MESSAGE_PROPERTIES: dict[str, Check] = {"text": string, "markdown": string, "id": string}

SCHEMA: dict[str, tuple[dict[str, Check], set[str]]] = {
    "sarifLog": ({"$schema": uri_reference, "version": enum("2.1.0"),
                  "runs": array(obj("run"))}, {"version", "runs"}),
    "run": ({"tool": obj("tool"), "results": array(obj("result")),
             "columnKind": enum("utf16CodeUnits", "unicodeCodePoints")}, {"tool"}),
    "tool": ({"driver": obj("toolComponent")}, {"driver"}),
    "toolComponent": ({"name": string, "version": string, "informationUri": uri_reference,
                       "rules": array(obj("reportingDescriptor"), unique=True)}, {"name"}),
    "reportingDescriptor": ({"id": string, "name": string,
                             "shortDescription": obj("multiformatMessageString"),
                             "fullDescription": obj("multiformatMessageString"),
                             "help": obj("multiformatMessageString"),
                             "helpUri": uri_reference,
                             "defaultConfiguration": obj("reportingConfiguration")}, {"id"}),
    "reportingConfiguration": ({"level": _LEVEL}, set()),
    "multiformatMessageString": ({"text": string, "markdown": string}, {"text"}),
    "message": (_MESSAGE_PROPERTIES, set()),
    "result": ({"ruleId": string, "ruleIndex": integer(-1), "level": _LEVEL,
                "message": obj("message"), "locations": array(obj("location")),
                "relatedLocations": array(obj("location"), unique=True),
                "fixes": array(obj("fix"), unique=True)}, {"message"}),
    "location": ({"id": integer(-1), "physicalLocation": obj("physicalLocation"),
                  "message": obj("message")}, set()),
    "physicalLocation": ({"artifactLocation": obj("artifactLocation"),
                          "region": obj("region")}, {"artifactLocation"}),
    "artifactLocation": ({"uri": uri_reference, "uriBaseId": string}, set()),
    "region": ({"startLine": integer(1), "startColumn": integer(1), "endLine": integer(1),
                "endColumn": integer(1)}, set()),
    "fix": ({"description": obj("message"),
             "artifactChanges": array(obj("artifactChange"), min_items=1, unique=True)},
            {"artifactChanges"}),
    "artifactChange": ({"artifactLocation": obj("artifactLocation"),
                        "replacements": array(obj("replacement"), min_items=1)},
                       {"artifactLocation", "replacements"}),
    "replacement": ({"deletedRegion": obj("region"), "insertedContent": obj("artifactContent")},
                    {"deletedRegion"}),
    "artifactContent": ({"text": string}, set()),
}


def _message_has_text_or_id(value: dict[str, Any], where: str) -> list[str]:
    return [] if "text" in value or "id" in value else [f"{where}: message without text or id"]


def _region_in_order(value: dict[str, Any], where: str) -> list[str]:
    start = (value.get("startLine", 1), value.get("startColumn", 1))
    end = (value.get("endLine", start[0]), value.get("endColumn", start[1]))
    return [] if end >= start else [f"{where}: region ends before it starts"]


def _rule_indexes_match(value: dict[str, Any], where: str) -> list[str]:
    problems = []
    for run_number, run in enumerate(value.get("runs", [])):
        rules = run.get("tool", {}).get("driver", {}).get("rules", [])
        for index, result in enumerate(run.get("results", [])):
            if "ruleIndex" not in result:
                continue
            rule_index = result["ruleIndex"]
            if not 0 <= rule_index < len(rules) or rules[rule_index]["id"] != result.get("ruleId"):
                problems.append(f"{where}.runs[{run_number}].results[{index}]: ruleIndex "
                                f"{rule_index} does not name rule {result.get('ruleId')!r}")
    return problems


EXTRA_RULES: dict[str, Check] = {
    "message": _message_has_text_or_id,
    "region": _region_in_order,
    "sarifLog": _rule_indexes_match,
}


def sarif_problems(log: Any) -> list[str]:
    """Every way `log` departs from the modelled part of SARIF 2.1.0 (empty: none)."""
    return obj("sarifLog")(log, "$")
