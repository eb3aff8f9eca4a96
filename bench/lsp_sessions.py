"""The language server's memory as clients come and go: `rl1-lsp --tcp` and `--ws`, each
in a process of its own, serve well-behaved clients one after another (each opens a
document, gets its diagnostics and leaves; tests/support/hostile.py's probe). After a
warm-up, prints the server's resident memory per client served, which must stay near
zero (what ended sessions leave behind; issue 23 found 0.31 MiB a client), and, as the
reference in the same run, what the server held after the warm-up; with the processor
time the server spends on a client (collecting an ended session's garbage among it).

    .venv/bin/python bench/lsp_sessions.py [--clients 300]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from server_growth import growth  # noqa: E402  (bench/ is this script's folder)
from support.hostile import ServedLsp, serve_one_after_another  # noqa: E402  (tests/ is put on the path just above)


def measure(transport: str, clients: int) -> None:
    server = ServedLsp(transport)
    try:
        print(growth(server, serve_one_after_another, clients, f"rl1-lsp --{transport}",
                     "client"))
    finally:
        server.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clients", type=int, default=300)
    options = parser.parse_args()
    for transport in ("tcp", "ws"):
        measure(transport, options.clients)


if __name__ == "__main__":
    main()
