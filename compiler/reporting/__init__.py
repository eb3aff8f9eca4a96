"""Diagnostics for people and machines: the catalogue of codes with their long
explanations, and the renderers (rustc-style text, JSON, SARIF)."""
