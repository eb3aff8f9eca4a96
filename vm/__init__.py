"""RL/I runtime: the language facts every stage shares, the instruction set, the .ilc
container and verifier, the reference VM and the devices it drives. Imports nothing
from rl1.compiler or rl1.lsp."""
