"""Large messages at once under the shared bound of bytes in flight (lsp/transports.py,
InFlight): in each round, a fresh `rl1-lsp --ws` and eight clients each sending an
initialize of 60 MiB (JSON escapes of 10 MiB of text) at once, as
tests/lsp/test_hostile_transports.py does. Prints, over the rounds, how many of the
eight were answered (the others refused: the bound holds two such messages), the rounds
in which none was, and the server's greatest growth at its peak, against what its
messages in flight may take (transports.MEMORY_IN_FLIGHT) as the reference.

    .venv/bin/python bench/lsp_in_flight.py [--rounds 5]
"""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

from rl1.lsp.transports import MAX_SESSIONS, MEMORY_IN_FLIGHT

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT / "tests")]

from support.hostile import ServedLsp, large_messages_at_once  # noqa: E402  (tests/ on the path just above)


def one_round() -> tuple[int, float]:
    """The clients answered, and the server's growth at its peak in MiB."""
    server = ServedLsp("ws")
    try:
        answered = large_messages_at_once(server)
        return len(answered), server.peak_mib() - server.started_mib
    finally:
        server.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    rounds = parser.parse_args().rounds
    # A refused client's library logs the connection's end as an error, with a traceback.
    logging.getLogger("websockets.client").setLevel(logging.CRITICAL)
    results = [one_round() for _ in range(rounds)]
    answers = [answered for answered, _ in results]
    print(f"{MAX_SESSIONS} WebSocket clients sending 60 MiB at once, {rounds} rounds: "
          f"answered {answers} (none in {answers.count(0)} rounds); growth at the peak "
          f"at most {max(peak for _, peak in results):.0f} MiB, of the "
          f"{MEMORY_IN_FLIGHT // 2**20} MiB messages in flight may take")


if __name__ == "__main__":
    main()
