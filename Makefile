# vnrrt: `make help` lists the targets. Everything runs inside .venv (created on demand).
SHELL := /bin/bash
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
export PATH := $(CURDIR)/$(BIN):$(PATH)

.PHONY: help setup test test-all lint format params repro plots repro-cpu repro-cpu-budget-seed1 bench clean

help:  ## list the targets
	@grep -E '^[a-z0-9-]+:.*## ' $(MAKEFILE_LIST) | awk -F':.*## ' '{printf "  %-10s %s\n", $$1, $$2}'

$(STAMP): pyproject.toml requirements/constraints.txt
	test -x $(BIN)/python || $(PY) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	$(BIN)/python -m pip install -q -c requirements/constraints.txt -e '.[dev]'
	touch $(STAMP)

setup: $(STAMP)  ## create .venv and install the pinned environment

test: $(STAMP)  ## run the default test suite (excludes tests marked slow)
	$(BIN)/python -m pytest -q -n 2 --dist loadfile

test-all: $(STAMP)  ## run every test, slow ones included
	$(BIN)/python -m pytest -q -m ''

lint: $(STAMP)  ## ruff lint and format check
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

format: $(STAMP)  ## apply ruff fixes and formatting
	$(BIN)/ruff check --fix .
	$(BIN)/ruff format .

params: $(STAMP)  ## write params.yaml from conf/ (the default composition, as DVC does; validated)
	$(BIN)/python -m vnrrt.pipeline.params --out params.yaml

repro: $(STAMP)  ## run the whole pipeline (dvc repro) at the default scale; saved as experiment local-default
	$(BIN)/dvc repro
	@# this machine's own default run, the baseline an ablation is compared with (dvc exp diff)
	$(BIN)/dvc exp save --force --name local-default \
		|| echo "note: dvc exp save failed; compare an ablation with 'dvc exp diff HEAD <exp>'" >&2

PLOTS_TEMPLATE := .dvc/tmp/plots_offline.html
plots: $(STAMP)  ## the DVC plots as a page that renders offline: dvc_plots/index.html (Vega bundled)
	$(BIN)/python -m vnrrt.viz.plots_page --out $(PLOTS_TEMPLATE)
	$(BIN)/dvc plots show --html-template $(PLOTS_TEMPLATE)

CPU_REPORTS := reports/cpu
# The study's reports first, so that a run cut short still leaves them: the pipeline at
# train.seed 0 (paper comparison and sampling ideas), then both networks at train.seed 1, then
# the training-budget curve at seed 0. Wall time measured on 2026-12-02 (2-core AVX-512 machine
# with bf16): ~38 min for the data and both trainings, ~2 min trials, ~4 min
# oracle selection, ~26 min the oracle evaluation and regime grid (regime@0, 49,980 jobs of 2
# planner runs), ~3 min the reports; ~37 min for seed 1's trainings; ~63 min the budget
# curve.
repro-cpu: $(STAMP)  ## the CPU study scale (about 3 h on 2 cores): the pipeline at seed 0 (reports first), both networks at train.seed 1, the training-budget curve and the benchmark-maps study; reports copied to reports/cpu/, the per-trial tables behind them to reports/cpu/results/
	$(BIN)/dvc exp run -S scale=cpu ideas report
	rm -rf $(CPU_REPORTS) && mkdir -p $(CPU_REPORTS)/seed1
	cp -r reports/paper_comparison.md reports/sampling_ideas.md reports/metrics reports/figures $(CPU_REPORTS)/
	$(BIN)/python -m vnrrt.pipeline.recompute export --params params.yaml --out $(CPU_REPORTS)/results
	$(BIN)/dvc exp run -S scale=cpu -S train.seed=1 predict_metrics
	cp reports/metrics/train_*.json reports/metrics/predict.json $(CPU_REPORTS)/seed1/
	$(BIN)/dvc exp run -S scale=cpu
	cp -r reports/training_budget.md reports/benchmark_maps.md reports/metrics reports/figures $(CPU_REPORTS)/

repro-cpu-budget-seed1: $(STAMP)  ## after repro-cpu: the training-budget curve at train.seed 1 (~75 min on 2 cores); to reports/cpu/seed1/
	$(BIN)/dvc exp run -S scale=cpu -S train.seed=1 budget_report@training_budget
	mkdir -p $(CPU_REPORTS)/seed1/figures $(CPU_REPORTS)/seed1/metrics
	cp reports/training_budget.md $(CPU_REPORTS)/seed1/
	cp reports/metrics/training_budget.json $(CPU_REPORTS)/seed1/metrics/
	rm -rf $(CPU_REPORTS)/seed1/figures/budget && cp -r reports/figures/budget $(CPU_REPORTS)/seed1/figures/

bench: $(STAMP)  ## run the benchmarks
	for f in benchmarks/bench_*.py; do $(BIN)/python $$f || exit 1; done

clean:  ## remove caches (not data, models or .venv)
	rm -rf .pytest_cache .ruff_cache .hypothesis
	find . -name __pycache__ -prune -exec rm -rf {} +
