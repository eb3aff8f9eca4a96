"""`rl1c studio`'s server (spec/studio.md): the page, the language server and the
debugging core on the simulator, over WebSockets, for one folder. `start.py` starts it,
`server.py` answers requests, `language.py` is `/lsp`'s session, `connection.py` speaks
the studio's protocol, `run.py` runs a program, `files.py` confines the files,
`shapes.py` gives the page its data; `static/` is the page, built from editors/studio/."""
