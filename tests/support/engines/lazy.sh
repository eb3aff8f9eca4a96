#!/bin/sh
# An exec: engine of `rl1c fuzz` that runs nothing and says the watchdog stopped it: it
# must disagree with every run that ends within its budget (tests/cli/test_fuzz_cli.py).
echo '{"status": {"code": "budget", "line": null}, "variables": {}, "trace": []}'
