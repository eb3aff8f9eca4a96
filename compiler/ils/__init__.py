"""The .ils text form of .ilc files, both ways: the assembler and the disassembler."""
