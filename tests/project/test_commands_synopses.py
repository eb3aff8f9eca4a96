"""docs/commands.md's synopses (the code block that opens a command's section, `rl1c
check PATH... [--format ...]`) name every option the command takes, and only those: a
new option not written there, or one renamed, fails here."""

from __future__ import annotations

import re

import click
from support import ROOT

from rl1.compiler.cli.main import rl1c

COMMANDS_MD = ROOT / "docs" / "commands.md"
FENCE = re.compile(r"^```(?P<language>\w*)\n(?P<body>.*?)^```", re.MULTILINE | re.DOTALL)
# An option as a synopsis writes it: `--world`, `-o`, `-O0` (click's `-O` with its value).
OPTION = re.compile(r"(?<![\w-])(--?[A-Za-z][\w-]*)")


def synopses(markdown: str) -> dict[str, set[str]]:
    """The options each `rl1c` command's synopses name, by command (`compile` for
    `rl1c FILE.rob`): a synopsis is a line of a plain code block that starts with
    `rl1c `, with the indented lines that go on with it."""
    named: dict[str, set[str]] = {}
    for block in FENCE.finditer(markdown):
        if block["language"]:
            continue
        command = None
        for line in block["body"].splitlines():
            if line.startswith("rl1c "):
                word = line.split()[1]
                command = "compile" if word.startswith("FILE") else word
            elif not line.startswith(" "):
                command = None
            if command is not None:
                named.setdefault(command, set()).update(OPTION.findall(line))
    return named


def names(option: click.Option) -> set[str]:
    return {*option.opts, *option.secondary_opts}


def written(option: click.Option, shown: set[str]) -> bool:
    """Whether a synopsis names `option`: one of its names, or a short option given
    with its value (`-O0` for `-O`)."""
    return any(name in shown or (not name.startswith("--") and any(
        word.startswith(name) for word in shown)) for name in names(option))


def test_a_synopsis_is_read_with_its_indented_lines_and_by_command() -> None:
    markdown = ("```\nrl1c run FILE [--sensors FILE]\n         [--trace all]\n"
                "rl1c run --batch\n```\n```\nrl1c FILE.rob [-o X] [-O0|-O1]\n```\n"
                "```sh\nrl1c sim x --seed 3\n```\n```\n$ rl1c sim x --runs 3\n```\n")
    assert synopses(markdown) == {"run": {"--sensors", "--trace", "--batch"},
                                  "compile": {"-o", "-O0", "-O1"}}


def test_every_command_s_synopsis_names_each_of_its_options_and_no_other() -> None:
    documented = synopses(COMMANDS_MD.read_text(encoding="utf-8"))
    context = click.Context(rl1c)
    for name in rl1c.list_commands(context):
        command = rl1c.get_command(context, name)
        assert command is not None, name
        assert name in documented, f"docs/commands.md has no synopsis of `rl1c {name}`"
        options = [param for param in command.params if isinstance(param, click.Option)]
        missing = [option.opts[-1] for option in options
                   if not written(option, documented[name])]
        assert not missing, f"`rl1c {name}`'s synopsis in docs/commands.md lacks {missing}"
        known = {name for option in options for name in names(option)}
        unknown = [word for word in documented[name]
                   if word not in known and not any(word.startswith(short) for short in known
                                                    if not short.startswith("--"))]
        assert not unknown, f"`rl1c {name}` has no option {unknown} (docs/commands.md)"
