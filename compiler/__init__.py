"""RL/I front end and compiler: scanner, parser, checker, formatter, code generator, CLI."""
