"""`python -m rl1.lsp`: the same as the `rl1-lsp` command."""

from .server import main

main()
