# The two entry points on a fresh machine: `make demo` and `make test`.
# Both create the virtual environment .venv and install the project into it first.

PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test lint typecheck pytest clean vscode-test vscode-package

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	# pip byte-compiles what it installs, but an editable install leaves rl1 to its
	# first run, which cannot write bytecode where PYTHONDONTWRITEBYTECODE is set.
	$(BIN)/python -m compileall -q compiler vm lsp
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/rl1c check examples/sample.rob
	mkdir -p build
	$(BIN)/rl1c examples/sample.rob -o build/sample.ilc
	$(BIN)/rl1c run build/sample.ilc --sensors examples/sample.sensors.json
	$(BIN)/rl1c sim build/sample.ilc --world examples/sample.world.toml \
		--svg build/sample.svg --html build/sample.html > build/sample.sim.txt
	@tail -n 2 build/sample.sim.txt
	@echo "Listing 1 simulated on the scene of Fig. 4: the trace is build/sample.sim.txt,"
	@echo "the picture build/sample.svg, the replay build/sample.html (open it in a browser)"

test: lint typecheck vscode-test pytest

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
	MYPYPATH=.typecheck $(BIN)/mypy -p rl1.compiler -p rl1.vm -p rl1.lsp
	MYPYPATH=.typecheck:spec/vectors:tests $(BIN)/mypy tests $(wildcard bench/*.py) spec/vectors

pytest: $(STAMP)
	$(BIN)/pytest -n 2

# The VS Code extension (editors/vscode): its exact dependencies from the npm lock file
# (none needs an install script), then tsc, then its grammar and settings tests on node.
VSCODE := editors/vscode
VSCODE_STAMP := $(VSCODE)/node_modules/.installed

$(VSCODE_STAMP): $(VSCODE)/package-lock.json
	cd $(VSCODE) && npm ci --ignore-scripts --no-audit --no-fund
	touch $@

vscode-test: $(VSCODE_STAMP)
	cd $(VSCODE) && npm run --silent compile && npm test --silent

vscode-package: vscode-test
	cd $(VSCODE) && npm run --silent package

clean:
	rm -rf $(VENV) .typecheck .mypy_cache .pytest_cache .ruff_cache .hypothesis
	rm -rf $(VSCODE)/node_modules $(VSCODE)/out $(VSCODE)/rl1.vsix
