"""The CLI loads only what a command needs, and its option values are the stages' own."""

import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

import pytest
from support import SAMPLE
from support.cli import rl1c

from rl1.compiler.backend import driver, firmware
from rl1.compiler.cli import build as cli
from rl1.compiler.cli import main

# What `rl1c check` must not load: heavy packages that only other commands need (lark
# builds the parser's tables offline, numpy is for the simulator, hypothesis for the
# strategies, pygls and lsprotocol for the language server).
COSTLY = {"lark", "numpy", "hypothesis", "pygls", "lsprotocol"}


def test_option_values_are_the_stages_own() -> None:
    assert (*driver.EMITS, *firmware.FORMATS, "ils") == cli.EMIT_CHOICES
    assert set(cli.EMIT_SUFFIXES) == set(cli.EMIT_CHOICES)


def test_rl1c_compile_and_compile_text_compile_at_one_default_level(tmp_path: Path) -> None:
    compiled = tmp_path / "sample.ilc"
    assert rl1c(SAMPLE, "--strip", "-o", compiled).exit_code == 0
    default = driver.compile_text(SAMPLE.read_text(encoding="utf-8"), "sample.rob",
                                  strip_debug=True)
    assert compiled.read_bytes() == default.output
    assert default.output != driver.compile_text(SAMPLE.read_text(encoding="utf-8"),
                                                 "sample.rob", strip_debug=True,
                                                 level=0).output  # a level that shows


def modules_loaded_by(argv: list[str]) -> tuple[int, set[str]]:
    """The exit status of `rl1c argv` run in a fresh process, and the modules it loaded.
    Costly modules that the interpreter's start-up loaded already (the editable install's
    import hook loads pathlib) are forgotten first, so that a use of them still shows."""
    program = (
        "import sys\n"
        f"for name in {sorted(COSTLY)!r}:\n"
        "    sys.modules.pop(name, None)\n"
        "from rl1.compiler.cli.main import rl1c\n"
        f"status = rl1c.main({argv!r}, standalone_mode=False)\n"
        "print(status, *sys.modules)\n"
    )
    result = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True,
                            check=True)
    status, *loaded = result.stdout.splitlines()[-1].split()
    return int(status), set(loaded)


@pytest.fixture(scope="module")
def loaded_by_check() -> set[str]:
    status, loaded = modules_loaded_by(["check", str(SAMPLE)])
    assert status == 0
    return loaded


def test_check_loads_neither_the_back_end_nor_the_vm_nor_lark(loaded_by_check: set[str]) -> None:
    assert "rl1.compiler.checker" in loaded_by_check
    back_end = {"rl1.compiler.backend.codegen", "rl1.compiler.backend.lower",
                "rl1.compiler.ils.asm", "rl1.compiler.formatter", "rl1.vm.machine",
                "rl1.vm.scripted", "rl1.vm.verifier", "rl1.compiler.interpreter"}
    assert loaded_by_check & back_end == set()
    # The parser runs the tables make_tables.py wrote; lark itself costs 40 ms to import.
    assert "rl1.compiler.frontend.lalr_tables" in loaded_by_check


def test_check_loads_only_its_own_commands(loaded_by_check: set[str]) -> None:
    assert "rl1.compiler.cli.source" in loaded_by_check
    assert loaded_by_check & {"rl1.compiler.cli.build", "rl1.compiler.cli.sim",
                              "rl1.vm.faults"} == set()


def test_the_lazy_table_names_each_modules_commands() -> None:
    for module, names in main.MODULES:
        commands = main.command_module(module).COMMANDS
        assert tuple(command.name for command in commands) == names


def test_check_loads_nothing_costly(loaded_by_check: set[str]) -> None:
    assert loaded_by_check & COSTLY == set()


def test_rl1cs_own_commands_read_no_entry_points(loaded_by_check: set[str],
                                                 tmp_path: Path) -> None:
    # importlib.metadata, which finds the plugins' commands (cli/plugins.py), takes
    # tens of milliseconds to load: check, and compile without a command, do without.
    assert "importlib.metadata" not in loaded_by_check
    status, loaded = modules_loaded_by([str(SAMPLE), "-o", str(tmp_path / "sample.ilc")])
    assert status == 0 and "importlib.metadata" not in loaded


def test_json_is_loaded_for_the_json_format_only() -> None:
    status, loaded = modules_loaded_by(["check", "--format", "json", str(SAMPLE)])
    assert status == 0 and "json" in loaded


def test_version_reads_the_installed_metadata_when_asked() -> None:
    shown = subprocess.run([sys.executable, "-c", "from rl1.compiler.cli.main import rl1c; "
                            "rl1c.main(['--version'])"], capture_output=True, text=True,
                           check=False)
    assert (shown.returncode, shown.stdout) == (0, f"rl1c, version {version('rl1')}\n")
