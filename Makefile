# The two entry points on a fresh machine: `make demo` and `make test`.
# Both create the virtual environment .venv and install the project into it first.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test quick lint typecheck pytest clean vscode-test vscode-package c-test studio-check studio-page mutation

# pip byte-compiles what it installs, but an editable install leaves rl1 to its first
# run, which cannot write bytecode where PYTHONDONTWRITEBYTECODE is set: compileall.
# setuptools' "Editable installation" notice (mind folders named like the package) is
# for pip's own users, not for ours, so it is filtered out.
$(STAMP): pyproject.toml
	@echo 'Setting up .venv: the rl1 package and its development tools (a minute or two, once)'
	@$(PYTHON) -m venv $(VENV)
	@$(BIN)/python -m pip install --quiet --upgrade pip
	@PYTHONWARNINGS='ignore:Editable installation' $(BIN)/python -m pip install --quiet -e '.[dev]'
	@$(BIN)/python -m compileall -q compiler vm lsp
	@touch $(STAMP)

# What a user reads: each command as they would type it with .venv activated, then its
# output. Compiling checks first, so the checker's warnings are printed once, here.
demo: $(STAMP)
	@mkdir -p build
	@echo '$$ rl1c examples/sample.rob -o build/sample.ilc'
	@$(BIN)/rl1c examples/sample.rob -o build/sample.ilc
	@echo
	@echo '$$ rl1c run build/sample.ilc --sensors examples/sample.sensors.json'
	@$(BIN)/rl1c run build/sample.ilc --sensors examples/sample.sensors.json
	@echo
	@echo '$$ rl1c sim build/sample.ilc --world examples/sample.world.toml --svg build/sample.svg --html build/sample.html > build/sample.sim.txt'
	@$(BIN)/rl1c sim build/sample.ilc --world examples/sample.world.toml --svg build/sample.svg --html build/sample.html > build/sample.sim.txt
	@sed -n '/^the program/,$$p' build/sample.sim.txt
	@echo "Listing 1 simulated on the scene of Fig. 4: the trace is build/sample.sim.txt,"
	@echo "the picture build/sample.svg, the replay build/sample.html (open it in a browser)."
	@echo "It succeeds only with the stand placed to a tenth of a millimetre (README.md says why);"
	@echo "examples/fig4.rob is the program that succeeds 97 times in 100 with sensor noise."
	@echo
	@echo 'Next: `. .venv/bin/activate`, then the first session in README.md.'

test: lint typecheck vscode-test studio-check c-test pytest

# The fast tests alone, in under a minute, while working: no test marked slow or needing
# a C compiler, Node.js or a browser (tests/support/markers.py marks them). `make test` runs all.
QUICK := not slow and not needs_cc and not needs_node and not needs_browser

quick: $(STAMP)
	$(BIN)/pytest -n 2 -m '$(QUICK)'

# Mutation testing (tests/mutation/README.md): cosmic-ray's session M (machine, constants,
# signs, verifier or ilc) in a clone of its own. Slow (an hour or more), never in `make test`.
mutation:
	tests/mutation/run $(or $(M),machine)

# The C VM (vm/c/): the Debian packages it needs when missing (CI runs as root),
# then its builds, the conformance vectors under sanitizers and on emulated targets,
# cross builds and a bounded fuzzing run.
c-test: $(STAMP)
	vm/c/install-tools
	$(MAKE) -C vm/c test RL1_PYTHON=$(CURDIR)/$(BIN)/python

lint: $(STAMP)
	$(BIN)/ruff check compiler vm lsp tests bench spec/vectors
	$(BIN)/lint-imports --no-cache

# mypy cannot follow setuptools' editable-install mapping of rl1.compiler onto
# compiler/, so it checks a tree of symlinks with the installed names.
typecheck: $(STAMP)
	rm -rf .typecheck && mkdir -p .typecheck/rl1
	ln -s ../../compiler .typecheck/rl1/compiler
	ln -s ../../vm .typecheck/rl1/vm
	ln -s ../../lsp .typecheck/rl1/lsp
	MYPYPATH=.typecheck:spec/vectors $(BIN)/mypy -p rl1.compiler -p rl1.vm -p rl1.lsp
	MYPYPATH=.typecheck:spec/vectors:tests $(BIN)/mypy tests $(wildcard bench/*.py) spec/vectors \
	    $(wildcard vm/c/test/*.py)

# Debian's chromium for the browser tests, and Emacs, eglot and Neovim for the editor
# tests, when missing (CI runs as root).
pytest: $(STAMP)
	tests/browser/install-chromium
	tests/editors/install-editors
	$(BIN)/pytest -n 2

# The VS Code extension (editors/vscode): its exact dependencies from the npm lock file
# (none needs its install script: esbuild's binary comes in its platform's package), then
# tsc, then its grammar and settings tests on node. The package is esbuild's bundle.
VSCODE := editors/vscode
VSCODE_STAMP := $(VSCODE)/node_modules/.installed

$(VSCODE_STAMP): $(VSCODE)/package-lock.json
	cd $(VSCODE) && npm ci --ignore-scripts --no-audit --no-fund
	touch $@

vscode-test: $(VSCODE_STAMP)
	cd $(VSCODE) && npm run --silent compile && npm test --silent

vscode-package: vscode-test
	cd $(VSCODE) && npm run --silent package

# The studio's page (editors/studio): its exact dependencies from the npm lock file, then
# tsc. The page is committed built in lsp/studio/static/ (a pipx install needs no
# Node.js); tests/project/test_studio_bundle.py rebuilds it apart and compares the bytes.
# After editing its sources, `make studio-page` rebuilds it in place, to be committed.
STUDIO := editors/studio
STUDIO_STAMP := $(STUDIO)/node_modules/.installed

$(STUDIO_STAMP): $(STUDIO)/package-lock.json
	cd $(STUDIO) && npm ci --ignore-scripts --no-audit --no-fund
	touch $@

studio-check: $(STUDIO_STAMP)
	cd $(STUDIO) && npm run --silent check

studio-page: studio-check
	cd $(STUDIO) && npm run --silent build

clean:
	rm -rf $(VENV) .typecheck .mypy_cache .pytest_cache .ruff_cache .hypothesis
	rm -rf $(VSCODE)/node_modules $(VSCODE)/out $(VSCODE)/dist $(VSCODE)/rl1.vsix
	rm -rf $(STUDIO)/node_modules
	$(MAKE) -C vm/c clean
