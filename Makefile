# Quick start: `make demo` and `make test`. Both set up .venv on first use.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
PLUGINS := $(wildcard plugins/*/pyproject.toml)
STAMP := $(VENV)/.installed

.PHONY: venv demo test lint typecheck pytest bench clean

venv: $(STAMP)

$(STAMP): pyproject.toml $(PLUGINS)
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[dev]" $(foreach p,$(PLUGINS),-e $(dir $(p)))
	touch $(STAMP)

demo: $(STAMP)
	@mkdir -p out/demo
	@for cfg in examples/*.toml; do \
		name=$$(basename $$cfg .toml); \
		case $$name in experiment_*) continue;; esac; \
		echo "mdf run $$cfg --out out/demo/$$name"; \
		$(BIN)/mdf run $$cfg --out out/demo/$$name || exit 1; \
	done
	$(BIN)/python examples/side_by_side.py out/demo
	$(BIN)/mdf experiment examples/experiment_cmu.toml --out out/demo/experiment_cmu
	@echo "spectrograms: out/demo/*/spectrogram.png; FMCW points: out/demo/fmcw_walk/points.csv; experiment report: out/demo/experiment_cmu/report.md"

lint: $(STAMP)
	$(BIN)/ruff check src plugins tests benchmarks docs examples/plugin-example
	$(BIN)/ruff format --check src plugins tests benchmarks docs examples/plugin-example

typecheck: $(STAMP)
	$(BIN)/mypy src

pytest: $(STAMP)
	$(BIN)/pytest -q

test: lint typecheck pytest

bench: $(STAMP)
	$(BIN)/python benchmarks/bench_pipeline.py

clean:
	rm -rf out .pytest_cache .mypy_cache .ruff_cache
