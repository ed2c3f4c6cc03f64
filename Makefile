# vnrrt: `make help` lists the targets. Everything runs inside .venv (created on demand).
SHELL := /bin/bash
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed
export PATH := $(CURDIR)/$(BIN):$(PATH)

.PHONY: help setup test test-all lint format params repro plots repro-cpu bench clean

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
# train.seed 0 (paper comparison and sampling ideas), then the training-budget curve at
# training seeds 0-3 (the claims read over the four network pairs at the largest budget) and
# the benchmark-maps study. Wall time on a 2-core AVX-512 machine with bf16: ~40 min for the
# data and both trainings, ~35 min the trials, oracle selection and regime grid, ~3 min the
# reports; ~3.7 h the budget curve (32 trainings: a network pair ~30, 15, 8 and 4 min at
# 4,800, 2,400, 1,200 and 600 steps); the per-trial tables of both go to
# reports/cpu/results/.
repro-cpu: $(STAMP)  ## the CPU study scale (about 5.5 h on 2 cores): the pipeline at seed 0 (reports first), the training-budget curve at 4 training seeds and the benchmark-maps study; reports copied to reports/cpu/, the per-trial tables behind them to reports/cpu/results/
	$(BIN)/dvc exp run -S scale=cpu ideas report
	rm -rf $(CPU_REPORTS) && mkdir -p $(CPU_REPORTS)
	cp -r reports/paper_comparison.md reports/sampling_ideas.md reports/metrics reports/figures $(CPU_REPORTS)/
	$(BIN)/python -m vnrrt.pipeline.recompute export --params params.yaml --out $(CPU_REPORTS)/results
	$(BIN)/dvc exp run -S scale=cpu
	cp -r reports/training_budget.md reports/benchmark_maps.md reports/metrics reports/figures $(CPU_REPORTS)/
	cd data/cpu && cp --parents budget/*/trials.csv ../../$(CPU_REPORTS)/results/

bench: $(STAMP)  ## run the benchmarks
	for f in benchmarks/bench_*.py; do $(BIN)/python $$f || exit 1; done

clean:  ## remove caches (not data, models or .venv)
	rm -rf .pytest_cache .ruff_cache .hypothesis
	find . -name __pycache__ -prune -exec rm -rf {} +
