"""The documents that `rl1c` names in its help texts and messages, as it writes them:
spec/sensors.md, docs/commands.md, spec/rl1_hardware.h; and README.md, which the package
does not install (so none may name it)."""

import re

DOCUMENT_NAME = re.compile(r"\b(?:(?:spec|docs)/[\w.-]+\.(?:md|h)|README\.md)\b")
