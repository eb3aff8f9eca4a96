"""rl1-lsp with bugs planted in several features and in the whole-program checker, to
test that a failing feature is answered with an error and the server keeps serving.
Run as a script by test_robustness.py."""

from __future__ import annotations

from typing import NoReturn

from rl1.compiler import checker
from rl1.lsp import completion, hover, navigation, server, tokens


def planted(*args: object, **kwargs: object) -> NoReturn:
    raise RuntimeError("planted failure")


hover.hover = planted
completion.complete = planted
navigation.definition = planted
navigation.symbols = planted
tokens.encode = planted
checker.check_program = planted
server.main()
