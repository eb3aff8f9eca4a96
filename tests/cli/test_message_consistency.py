"""Messages that say one thing the same way wherever it is said, as a user meets them
through `rl1c`: a fault's help said once, whichever engine meets it."""

from __future__ import annotations

from pathlib import Path

import pytest
from support.cli import rl1c

LOOP = ":10 A=A+1\n#10\n(END)\n"


@pytest.mark.parametrize(("engine", "counted"), [("vm", "instructions"),
                                                 ("ast", "statements")])
def test_a_used_up_budget_says_what_to_do_once_whichever_engine_runs(
    tmp_path: Path, engine: str, counted: str
) -> None:
    (tmp_path / "loop.rob").write_text(LOOP)
    result = rl1c("run", tmp_path / "loop.rob", "--budget", "100", "--engine", engine)
    assert result.exit_code == 12
    assert f"error[E1012]: the program ran more than 100 {counted} without ending\n" \
           in result.stdout
    assert result.stdout.count("raise") == 1  # the help alone says to raise the budget
    assert "= help: if the program should run longer, raise --budget;" in result.stdout
