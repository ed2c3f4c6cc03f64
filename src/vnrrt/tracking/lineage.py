"""MLflow lineage shared by the stages' runs: pipeline files as datasets with their DVC
hashes, the runs and logged models a run builds on, and links into the MLflow UI.

* **Datasets**: a pipeline file becomes an MLflow dataset (:func:`file_dataset`) whose digest
  is the file's md5, the hash DVC records for it in ``dvc.lock`` (DVC hashes a file's bytes);
  a folder of parts is one dataset per part. Logged as run inputs with a context
  (``training``, ``evaluation`` ...) by :func:`log_datasets`.
* **Runs found by content**: a run that logs a pipeline file (``predict.json``,
  ``ideas.json``) carries the file's md5 as a tag (:func:`content_tag`); a later stage reading
  the same file finds that run with :func:`run_for_file`, so the link holds for exactly the
  numbers it read.
* **Models**: a training run's logged model and registry version are in its training metrics
  file (``mlflow_run_id``, ``mlflow_model_id``, ``mlflow_model_version``), read with
  :func:`training_lineage`.
* **Links** are relative to the UI's page (``#/experiments/...``, ``get-artifact?...``), so
  they work whatever host, port or static prefix the UI is served at.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from urllib.parse import quote, urlencode

CONTENT_TAG = "md5/"  # prefix of the tag holding the md5 of a file a run logged


def file_md5(path: str | Path) -> str:
    """The md5 of a file's bytes: the hash DVC records for a file output (hex)."""
    from vnrrt.infra.io import file_digest

    return file_digest(path, "md5")


def file_dataset(path: str | Path, name: str):
    """An MLflow dataset for the pipeline file ``path`` (its source), named ``name``, with
    the file's DVC hash (:func:`file_md5`) as its digest."""
    from mlflow.data.dataset_source_registry import get_registered_sources
    from mlflow.data.meta_dataset import MetaDataset

    local = next(s for s in get_registered_sources() if s._get_source_type() == "local")
    return MetaDataset(local(str(Path(path).resolve())), name=name, digest=file_md5(path))


def log_datasets(client, run_id: str, files: dict[str, Path], context: str,
                 models: list[str] = ()) -> None:  # fmt: skip
    """Log the existing ``files`` (dataset name -> file) as inputs of run ``run_id`` in
    ``context``, and the logged models ``models`` (their ids) as its model inputs."""
    from mlflow.entities import DatasetInput, InputTag, LoggedModelInput
    from mlflow.utils.mlflow_tags import MLFLOW_DATASET_CONTEXT

    tags = [InputTag(MLFLOW_DATASET_CONTEXT, context)]
    inputs = [
        DatasetInput(file_dataset(path, name)._to_mlflow_entity(), tags)
        for name, path in files.items()
        if Path(path).is_file()
    ]
    client.log_inputs(run_id, datasets=inputs, models=[LoggedModelInput(m) for m in models])


def content_tag(name: str, path: str | Path) -> dict[str, str]:
    """The tag saying that a run logged the file ``path`` (as ``name``): its md5."""
    return {CONTENT_TAG + name: file_md5(path)}


def run_for_file(client, exp_id: str, name: str, path: str | Path):
    """The newest finished run of experiment ``exp_id`` that logged the file ``path`` as
    ``name`` (:func:`content_tag`: the same bytes), or None."""
    if not Path(path).is_file():
        return None
    (key, md5), = content_tag(name, path).items()  # fmt: skip
    query = f"tags.`{key}` = '{md5}' and attributes.status = 'FINISHED'"
    runs = client.search_runs([exp_id], query, order_by=["attributes.start_time DESC"])
    return runs[0] if runs else None


@dataclass(frozen=True)
class Training:
    """What a training metrics file says about its MLflow run: the run, the logged model's
    id and its registry version (``models:/<name>/<version>``); None where not logged."""

    network: str
    run_id: str | None
    model_id: str | None
    model_version: str | None


def training_lineage(network: str, path: str | Path) -> Training:
    """The :class:`Training` of ``network``'s training metrics file ``path`` (missing: all
    None)."""
    from vnrrt.infra.io import read_json

    info = read_json(path) if Path(path).is_file() else {}
    keys = ("mlflow_run_id", "mlflow_model_id", "mlflow_model_version")
    return Training(network, *(info.get(k) for k in keys))


def training_links(exp_id: str, trainings: list[Training]) -> list[str]:
    """Markdown list lines linking each network's training run and registry version."""
    lines = []
    for t in trainings:
        parts = [f"[training run]({run_link(exp_id, t.run_id)})"] if t.run_id else []
        if t.model_version:
            version = t.model_version.removeprefix("models:/")
            parts.append(f"[{version}]({model_version_link(t.model_version)})")
        lines.append(f"- `{t.network}`: " + (", ".join(parts) or "not tracked"))
    return lines


def run_link(exp_id: str, run_id: str) -> str:
    """The UI page of a run."""
    return f"#/experiments/{exp_id}/runs/{run_id}"


def artifact_link(exp_id: str, run_id: str, path: str) -> str:
    """The UI page of one artifact of a run (the artifact viewer, opened on ``path``)."""
    return f"{run_link(exp_id, run_id)}/artifacts/{quote(path)}"


def model_version_link(uri: str) -> str:
    """The UI page of a registry version ``models:/<name>/<version>``."""
    name, version = uri.removeprefix("models:/").rsplit("/", 1)
    return f"#/models/{quote(name)}/versions/{version}"


def artifact_url(run_id: str, path: str) -> str:
    """The URL the UI serves an artifact's bytes at (for images in a run description)."""
    return "get-artifact?" + urlencode({"path": path, "run_uuid": run_id})


def search_link(exp_id: str, query: str) -> str:
    """The UI's run list of experiment ``exp_id`` filtered by ``query`` (MLflow's search
    syntax)."""
    return f"#/experiments/{exp_id}/runs?searchFilter={quote(query)}"
