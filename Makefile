# Quick start: `make demo` and `make test`. Both set up .venv on first use.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
PLUGINS := $(wildcard plugins/*/pyproject.toml)
STAMP := $(VENV)/.installed

.PHONY: venv bytecode demo test lint typecheck pytest docs bench clean

venv: $(STAMP)

$(STAMP): pyproject.toml $(PLUGINS)
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	@echo "Installing mdframework and $(words $(PLUGINS)) plugins into $(VENV): pip reports every distribution"
	$(BIN)/python -m pip install --progress-bar on --upgrade pip "setuptools>=70.1"
	@# one pip call for every editable distribution; they all build with the setuptools just
	@# installed, instead of one isolated build environment each
	$(BIN)/python -m pip install --progress-bar on --no-build-isolation \
		-e ".[dev]" $(foreach p,$(PLUGINS),-e $(dir $(p)))
	touch $(STAMP)

# Bytecode caches of the project's own modules, as a non-editable pip install writes them: with
# PYTHONDONTWRITEBYTECODE set (as on some CI machines) every `mdf` process would otherwise compile
# the core and all plugins again (a third of a short run's start-up). Only changed files recompile.
bytecode: $(STAMP)
	@$(BIN)/python -m compileall -q src plugins > /dev/null

# the example runs go $(JOBS) at a time (one per core), then the CMU experiment
JOBS ?= $(shell nproc 2>/dev/null || echo 2)

demo: bytecode
	@mkdir -p out/demo
	@ls examples/*.toml | grep -v '/experiment_' | xargs -P $(JOBS) -I{} sh -c \
		'name=$$(basename {} .toml); echo "mdf run {} --out out/demo/$$name"; \
		$(BIN)/mdf run {} --out out/demo/$$name || exit 255'
	$(BIN)/python examples/side_by_side.py out/demo
	$(BIN)/mdf experiment examples/experiment_cmu.toml --out out/demo/experiment_cmu
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
