"""RL/I language server (rl1-lsp)."""
