"""The front end: source bytes to text and lines, tokens, the LALR(1) parser and the
plain AST, with the diagnostics it and the checker report."""
