#!/usr/bin/env bash
# The paper's network (resnet34 U-Net VertexNet, 41,221,168 parameters) and the NRRT* network
# trained on one GPU machine inside a time budget; writes only small files to --out (issue 27,
# src/vnrrt/pipeline/gpu/run.py). Needs torch, Lightning, numba, OpenCV, numpy, torchmetrics,
# tqdm: all on the nvidia-h200 machine, so no wheels travel (the script imports no
# Hydra/OmegaConf/MLflow/DVC).
#
# 1. Here, once (with Hydra; data/ is git-ignored, so the bundle travels only through carry):
#      python -m vnrrt.pipeline.gpu.bundle --instances data/cpu/instances.npz  # -> data/gpu/bundle
# 2. On the machine, the one command (device tool: carry ["data/gpu/bundle"], timeout_s 420):
#      bash scripts/gpu/paper_network.sh --device cuda --budget 300 --out "$OUT"
#    It ends within the budget (seconds from its start) plus Python's start-up; leave the rest
#    of timeout_s for the machine's start and the transfers, and the lease for a rerun.
# 3. Here: vnrrt.data.returned.read_returned(<files_at>, "data/cpu/instances.npz") checks them.
#
# Other options: python -m vnrrt.pipeline.gpu.run --help (shares of the budget, batch range,
# compile).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
export PYTHONPATH="$root/src${PYTHONPATH:+:$PYTHONPATH}" PYTHONUNBUFFERED=1
cd "$root"
exec "${PYTHON:-python3}" -m vnrrt.pipeline.gpu.run "$@"
