"""`rl1c docs`: print the documents that the help texts and messages name (docs/*.md, the
specifications spec/*.md and the C header of the hardware interface), from the installed
package as from a checkout, so that `spec/sensors.md` in a help text can be read after
`pipx install` too.

The wheel holds docs/ and spec/ as the package data of `rl1.docs` and `rl1.spec`
(pyproject.toml), beside `rl1.compiler`, as they sit beside compiler/ in a checkout: one
lookup, two folders up from this file, serves both.
"""

from __future__ import annotations

import sys
from pathlib import Path

import click

from .command import Command, CommandError

SECTION = "Documents"

# The folders of the documents, in the order `rl1c docs` lists them.
FOLDERS = tuple(Path(__file__).resolve().parents[2] / name for name in ("docs", "spec"))
SUFFIXES = (".md", ".h")


def documents() -> dict[str, Path]:
    """Every document by its topic: the file's name without `.md` (`sensors` for
    spec/sensors.md; the C header keeps its `.h`)."""
    found: dict[str, Path] = {}
    for folder in FOLDERS:
        for path in sorted(folder.glob("*")):
            if path.suffix in SUFFIXES and path.is_file():
                found.setdefault(path.name.removesuffix(".md"), path)
    return found


def topic_name(topic: str) -> str:
    """The name of the document a topic means, as `rl1c docs` takes it or as a help text
    writes it: `sensors`, `sensors.md` and `spec/sensors.md` are all `sensors`."""
    return topic.strip().replace("\\", "/").rsplit("/", 1)[-1].removesuffix(".md")


def title(path: Path) -> str:
    """The document's first heading, or the first line of a C header's comment."""
    with path.open(encoding="utf-8") as lines:
        for line in lines:
            text = line.strip().lstrip("#/* ").strip()
            if text:
                return text
    return ""


@click.command(cls=Command)
@click.argument("name", required=False, metavar="[NAME]")
def docs(name: str | None) -> int:
    """Print a document: the guides and the specifications that help texts name.

    `rl1c docs` lists the documents; `rl1c docs sensors` (or `rl1c docs spec/sensors.md`,
    as help texts name it) prints one. Pipe it to a pager: `rl1c docs sensors | less`.
    Exit status: 0, 2 no such document."""
    known = documents()
    if name is None:
        for topic, path in known.items():
            print(f"{topic:<16} {path.parent.name}/{path.name}: {title(path)}")
        return 0
    wanted = known.get(topic_name(name))
    if wanted is None:
        import difflib  # for this message only

        close = difflib.get_close_matches(topic_name(name), list(known), n=1)
        hint = f"did you mean `rl1c docs {close[0]}`? " if close else ""
        raise CommandError(f"`{name}` is no document of rl1c\n"
                           f"  = help: {hint}`rl1c docs` lists every document")
    sys.stdout.write(wanted.read_text(encoding="utf-8"))
    return 0


COMMANDS = (docs,)
