#!/bin/sh
# An exec: engine of `rl1c fuzz` whose watchdog fires 100 times too early: the reference
# VM run with a hundredth of the budget. Usage: early_watchdog.sh RL1C ILC SENSORS BUDGET
# (tests/cli/test_fuzz_cli.py).
exec "$1" run "$2" --sensors "$3" --budget $(($4 / 100)) --format json
