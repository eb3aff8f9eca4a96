"""The reference VM with one shift rule broken (a negative count shifts left by nothing:
`1<-1` gives 1, not 0), as an `exec:` engine of `rl1c fuzz`, which must catch it.

    python broken_vm.py FILE.ilc SENSORS.json BUDGET
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from rl1.vm import machine
from rl1.vm.drive import drive
from rl1.vm.hardware import Blocking
from rl1.vm.scripted import ScriptedDevice, decode_script, run_document
from rl1.vm.verifier import verify


def broken_left(value: int, count: int) -> int:
    if count < 0:
        return value  # should shift right by -count
    return 0 if count >= 16 else machine._wrap(value << count)


def main() -> None:
    ilc, sensors, budget = sys.argv[1:]
    machine._shift_left = broken_left
    device = ScriptedDevice(decode_script(Path(sensors).read_bytes(), sensors))
    vm = machine.Machine(verify(Path(ilc).read_bytes()),
                         Blocking(device, lambda: vm.current_line()), int(budget))
    result = drive(vm, device)  # as `rl1c run`: the script's losses after instruction counts
    json.dump(run_document(result, device.trace), sys.stdout)


if __name__ == "__main__":
    main()
