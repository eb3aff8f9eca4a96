"""Which of the device's duties (vm/c/README.md, "The device's duties, in one table") a
port broke, from what the host runner of the conformance vectors printed with the port's
fake vehicle in place of test/scripted.c (make -C vm/c port-check HW=...): reads the
runner's output on standard input, prints each broken duty with the vectors that show
it, and exits 1 when any vector failed.

Each vector tests the VM and the device together; a vector named here fails, with the VM
as shipped, only when the device does not do the duties named beside it."""

from __future__ import annotations

import re
import sys

DUTIES = {
    1: "every callback answers OK or ERROR, only poll BUSY; an ERROR where the device fails",
    2: "no callback blocks; poll answers BUSY until the built-in is done, on device time",
    3: "call and poll fill `out` with what the built-in read",
    4: "INP reads 0..255 and CAM R 0..784",
    6: "end does not stop the vehicle",
    7: "stop stops the vehicle; RL1_ERROR when it cannot",
    8: "modes 0 and 1 post nothing; the mode stays as set",
    9: "a loss in mode 2 or 3 while motion is in effect is posted, as MOV or MVI; none "
       "without motion",
    10: "a post while one is pending is dropped",
    11: "mode 2: the device stops the vehicle itself",
    12: "mode 3: the motion carries on; a background MVI posts again, until replaced",
    13: "a TIM or MVI in progress answers its next poll OK when a loss is posted",
    14: "device time in 32 bits",
}

# Vector name (a regular expression, matched whole) -> the duties its failure points at.
VECTORS: list[tuple[str, tuple[int, ...]]] = [
    (r"mode-[01]-lost-during-.*|mode-persists-after-the-jump", (8,)),
    (r"mode-2-lost-during-mov", (9, 11)),
    (r"mode-2-lost-during-mvi", (9, 11, 13)),
    (r"mode-3-lost-during-mov", (9, 12)),
    (r"mode-3-lost-during-mvi", (9, 12, 13)),
    (r"lost-without-motion|mvi-zero-distance", (9,)),
    (r"one-event-pending|two-losses-in-one-millisecond", (10,)),
    (r"lost-during-an-operand|event-at-the-end-of-a-wait", (13,)),
    (r"mode-2-during-a-background-mvi", (11, 12)),
    (r"(mov|fre)-replaces-a-background-mvi", (12,)),
    (r"event-.*", (9,)),
    (r"listing-1-.*", (9, 12, 13)),
    (r"(inp|cam-r)-results", (3, 4)),
    (r".*-results|listing-1", (3,)),
    (r"timing|call-(mvi|tim|rot|str|stl|stx)", (2, 14)),
    (r"end-keeps-moving", (6,)),
    (r"failing-stop", (7,)),
    (r"failing-poll|device-error.*|readings-run-out|no-readings", (1,)),
]

LABEL = re.compile(r"^([a-z0-9-]+)\.(?:ilc|stripped) \(steps of")


def duties_of(name: str) -> tuple[int, ...]:
    for pattern, duties in VECTORS:
        if re.fullmatch(pattern, name):
            return duties
    return ()


def main() -> int:
    failing: dict[tuple[int, ...], set[str]] = {}  # duties -> the vectors that point there
    summary = ""
    for line in sys.stdin:
        sys.stdout.write(line)
        if line.startswith("conformance:"):
            summary = line.strip()
        match = LABEL.match(line)
        if match is not None:
            failing.setdefault(duties_of(match.group(1)), set()).add(match.group(1))
    if not summary:
        print("port-check: the runner printed no summary: it crashed (see above)")
        return 1
    for duties, names in sorted(failing.items()):
        vectors = ", ".join(sorted(names))
        if not duties:
            print(f"port-check: {vectors} failed: the VM's own work, which the VM as "
                  "shipped passes: is it built as shipped?")
            continue
        print(f"port-check: {vectors} failed: a duty broken, "
              + " or ".join(f"{duty} ({DUTIES[duty]})" for duty in duties))
    if failing:
        return 1
    print(f"port-check: every duty kept ({summary})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
