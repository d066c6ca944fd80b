# Quick start: `make demo` and `make test`. Both set up .venv on first use.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
PLUGINS := $(wildcard plugins/*/pyproject.toml)
STAMP := $(VENV)/.installed
EDITABLES := -e ".[dev]" $(foreach p,$(PLUGINS),-e $(dir $(p)))
# uv (installed into the venv from the package index) or pip
INSTALLER ?= uv

.PHONY: venv bytecode demo test lint typecheck pytest docs bench clean

venv: $(STAMP)

$(STAMP): pyproject.toml $(PLUGINS)
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	@echo "Installing mdframework and $(words $(PLUGINS)) plugins into $(VENV)"
	$(BIN)/python -m pip install --progress-bar on "setuptools>=77"
	@# uv installs every distribution in one call, downloading and building the editable ones in
	@# parallel with the setuptools just installed, and compiles their bytecode as pip does (else
	@# the examples that make demo runs side by side would each compile it on first import);
	@# where uv cannot be had or fails (or with INSTALLER=pip), one pip call does the same,
	@# listing each distribution as it goes
	@if [ "$(INSTALLER)" = uv ] && echo "Installing with uv" \
		&& $(BIN)/python -m pip install --progress-bar on uv \
		&& $(BIN)/uv pip install --python $(BIN)/python --no-build-isolation --compile-bytecode \
			$(EDITABLES); then \
		:; \
	else \
		echo "Installing with pip"; \
		$(BIN)/python -m pip install --progress-bar on --upgrade pip \
		&& $(BIN)/python -m pip install --progress-bar on --no-build-isolation $(EDITABLES); \
	fi
	touch $(STAMP)

# Bytecode caches of the project's own modules, as a non-editable pip install writes them: with
# PYTHONDONTWRITEBYTECODE set (as on some CI machines) every `mdf` process would otherwise compile
# the core and all plugins again (a third of a short run's start-up). Only changed files recompile.
bytecode: $(STAMP)
	@$(BIN)/python -m compileall -q src plugins > /dev/null

# the CMU experiment (the longest job, so first) and every example run go $(JOBS) at a time (one
# per core); then the side-by-side figure of the LFM and FMCW walks
JOBS ?= $(shell nproc 2>/dev/null || echo 2)

demo: bytecode
	@mkdir -p out/demo
	@{ echo examples/experiment_cmu.toml; ls examples/*.toml | grep -v '/experiment_'; } | \
		xargs -P $(JOBS) -I{} sh -c 'name=$$(basename {} .toml); \
		case $$name in experiment_*) cmd=experiment;; *) cmd=run;; esac; \
		echo "mdf $$cmd {} --out out/demo/$$name"; \
		$(BIN)/mdf $$cmd {} --out out/demo/$$name || exit 255'
	$(BIN)/python examples/side_by_side.py out/demo
	@echo "spectrograms: out/demo/*/spectrogram.png; FMCW points: out/demo/fmcw_walk/points.csv; experiment report: out/demo/experiment_cmu/report.md"

lint: $(STAMP)
	$(BIN)/ruff check src plugins tests benchmarks docs examples/plugin-example examples/plugin-template
	$(BIN)/ruff format --check src plugins tests benchmarks docs examples/plugin-example examples/plugin-template

typecheck: $(STAMP)
	$(BIN)/mypy src

pytest: bytecode
	$(BIN)/pytest -q

# the documentation site (mkdocs, strict: a broken link or docstring reference fails), with the
# API reference generated from the docstrings; into out/site
docs: $(STAMP)
	$(BIN)/mkdocs build --strict --quiet

test: lint typecheck pytest docs

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_pipeline.py

clean:
	rm -rf out .pytest_cache .mypy_cache .ruff_cache
