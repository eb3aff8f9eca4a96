"""The `rl1c` command line: thin wrappers over the stages."""
