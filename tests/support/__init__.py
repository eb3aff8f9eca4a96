"""What tests share: the project's paths, and helpers for each stage (checker.py, cli.py,
ilc.py, sarif.py, semantics.py). pytest puts tests/ on the path (pyproject.toml)."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
SAMPLE = EXAMPLES / "sample.rob"
SAMPLE_SENSORS = EXAMPLES / "sample.sensors.json"
TEST_DATA = ROOT / "tests" / "data"
