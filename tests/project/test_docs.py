"""The documents a newcomer reads: the README stays one screen that leads to docs/, every
link in them resolves (the file, and the heading an anchor names), and every document
the command line names is one that `rl1c docs` prints, from a checkout as from the
installed package (tests/project/test_wheel.py runs it there)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from support import ROOT
from support.cli import rl1c
from support.documents import DOCUMENT_NAME

from rl1.compiler.cli import docs

README = ROOT / "README.md"
DOCS = ROOT / "docs"
PAGES = [README, *sorted(DOCS.glob("*.md"))]

# A link or an image: [text](target) or ![alt](target), the target without spaces.
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^```.*?^```", re.MULTILINE | re.DOTALL)
HEADING = re.compile(r"^#{1,6} +(.+?) *#*$", re.MULTILINE)


def _prose(markdown: str) -> str:
    """The text outside fenced code blocks, where links and headings are."""
    return FENCE.sub("", markdown)


def slug(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, no punctuation but `-` and `_`,
    spaces as hyphens."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


def anchors(page: Path) -> set[str]:
    found: set[str] = set()
    for heading in HEADING.findall(_prose(page.read_text(encoding="utf-8"))):
        base = slug(heading)
        name, count = base, 0
        while name in found:  # GitHub numbers repeated headings: name, name-1, ...
            count += 1
            name = f"{base}-{count}"
        found.add(name)
    return found


def links(page: Path) -> list[str]:
    return LINK.findall(_prose(page.read_text(encoding="utf-8")))


def broken_links(page: Path) -> list[str]:
    """The links of `page` to a file that does not exist or a heading it does not have."""
    broken = []
    for target in links(page):
        if re.match(r"[a-z]+:", target):  # https:, mailto:: not ours to check here
            continue
        path_part, _, anchor = target.partition("#")
        path = (page.parent / path_part).resolve() if path_part else page
        if not path.exists():
            broken.append(f"{target} (no such file)")
        elif anchor and (path.suffix != ".md" or anchor not in anchors(path)):
            broken.append(f"{target} (no heading with that anchor in {path.name})")
    return broken


def test_the_slug_is_github_s() -> None:
    assert slug("Controlling `rl1c check`") == "controlling-rl1c-check"
    assert slug("`rl1c FILE.rob` (compile)") == "rl1c-filerob-compile"
    assert slug("11. Canonical layout") == "11-canonical-layout"


def test_a_missing_file_or_heading_is_a_broken_link(tmp_path: Path) -> None:
    (tmp_path / "other.md").write_text("# Other\n\n## A part\n", encoding="utf-8")
    page = tmp_path / "page.md"
    page.write_text("# Page\n[ok](other.md#a-part) [me](#page) [gone](nothing.md)\n"
                    "[no part](other.md#b-part)\n```\n[in code](ignored.md)\n```\n",
                    encoding="utf-8")
    assert broken_links(page) == ["nothing.md (no such file)",
                                  "other.md#b-part (no heading with that anchor in other.md)"]


@pytest.mark.parametrize("page", PAGES, ids=lambda page: page.relative_to(ROOT).as_posix())
def test_every_link_resolves(page: Path) -> None:
    assert links(page), f"{page.name} links nowhere"
    assert broken_links(page) == []


def test_the_readme_is_one_screen_that_leads_to_every_guide() -> None:
    text = README.read_text(encoding="utf-8")
    # The two commands come first, before any prose.
    assert re.search(r"\A# .*\n\n```sh\nmake demo .*\nmake test .*\n```", text)
    assert len(text.split()) <= 600, "the README grew past one screen: move it to docs/"
    linked = {(README.parent / target.partition("#")[0]).resolve() for target in links(README)}
    unlinked = [page.name for page in DOCS.glob("*.md") if page.resolve() not in linked]
    assert not unlinked, f"the README does not lead to {unlinked}"


def test_each_document_has_one_name() -> None:
    names = [path.name.removesuffix(".md") for folder in docs.FOLDERS
             for path in folder.glob("*") if path.suffix in docs.SUFFIXES]
    assert sorted(names) == sorted(set(names)), "two documents would share an `rl1c docs` name"
    assert set(names) == set(docs.documents())


def _names_in(text: str) -> set[str]:
    return set(DOCUMENT_NAME.findall(text))


def test_every_document_the_command_line_names_is_one_rl1c_docs_prints() -> None:
    """What `rl1c` says (help texts, messages, explanations) may name spec/ and docs/
    files, which the package installs, and never README.md, which it does not."""
    said = [*ROOT.joinpath("compiler", "cli").glob("*.py"),
            *ROOT.joinpath("compiler", "reporting", "explanations").glob("*.md")]
    named = {name: path.name for path in said
             for name in _names_in(path.read_text(encoding="utf-8"))}
    assert "spec/sensors.md" in named  # the scan sees the help of `rl1c run`
    unknown = {name: where for name, where in named.items()
               if docs.topic_name(name) not in docs.documents()}
    assert not unknown, f"named but not printed by `rl1c docs`: {unknown}"


def test_the_help_leads_to_the_guides() -> None:
    shown = rl1c("--help")
    assert shown.exit_code == 0
    # The names, not the placeholder of `rl1c docs NAME`.
    topics = re.findall(r"`rl1c docs ([a-z][\w./-]*)`", " ".join(shown.stdout.split()))
    assert {"tutorial", "commands", "editors", "firmware"} <= set(topics)
    assert all(docs.topic_name(topic) in docs.documents() for topic in topics), topics


@pytest.mark.parametrize("topic", ["sensors", "sensors.md", "spec/sensors.md"])
def test_rl1c_docs_prints_a_document_by_any_of_its_names(topic: str) -> None:
    shown = rl1c("docs", topic)
    assert (shown.exit_code, shown.stderr) == (0, "")
    assert shown.stdout == (ROOT / "spec" / "sensors.md").read_text(encoding="utf-8")


def test_rl1c_docs_lists_every_document_with_its_title() -> None:
    shown = rl1c("docs")
    assert shown.exit_code == 0
    listed = [line.split()[0] for line in shown.stdout.splitlines()]
    assert listed == list(docs.documents())
    assert "tutorial         docs/tutorial.md: A first program and a world of your own" in (
        shown.stdout.splitlines())


def test_an_unknown_document_is_a_usage_error_with_a_suggestion() -> None:
    shown = rl1c("docs", "spec/sensor.md")
    assert shown.exit_code == 2
    assert shown.stdout == ""
    assert "`spec/sensor.md` is no document of rl1c" in shown.stderr
    assert "did you mean `rl1c docs sensors`?" in shown.stderr


def test_the_development_guide_runs_every_benchmark() -> None:
    """Each script of bench/ (a module with a `__main__`, not a shared helper) has its
    command line in docs/development.md, where a newcomer looks for the benchmarks."""
    guide = (DOCS / "development.md").read_text(encoding="utf-8")
    scripts = [path for path in sorted((ROOT / "bench").glob("*.py"))
               if 'if __name__ == "__main__":' in path.read_text(encoding="utf-8")]
    assert len(scripts) > 20, "bench/ has scripts to run"
    missing = [path.name for path in scripts if f"bench/{path.name}" not in guide]
    assert not missing, f"docs/development.md does not say how to run {missing}"
