"""The back end: a checked AST lowered to the IR, the IR to an .ilc image, and the
compile pipeline in one call (driver.py)."""
