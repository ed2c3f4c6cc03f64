"""A real MLflow tracking server for tests (a subprocess on 127.0.0.1) and a small client of
its REST API (the endpoints the MLflow UI itself calls)."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.parse
import urllib.request
from pathlib import Path

START_SECONDS = 120.0  # the server imports MLflow (slow on a loaded machine)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class TrackingServer:
    """``mlflow server`` on a SQLite store, one worker, no job runner; ``url`` once
    :meth:`wait` returned; :meth:`stop` ends its process group."""

    def __init__(self, store: Path, log: Path) -> None:
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        mlflow = Path(sys.executable).parent / "mlflow"
        env = dict(os.environ, MLFLOW_SERVER_ENABLE_JOB_EXECUTION="false")
        env.pop("MLFLOW_TRACKING_URI", None)
        cmd = [str(mlflow), "server", "--backend-store-uri", f"sqlite:///{store}", "--host",
               "127.0.0.1", "--port", str(self.port), "--workers", "1"]  # fmt: skip
        self.log = log
        with open(log, "w") as out:
            self.proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, env=env,
                                         cwd=log.parent, start_new_session=True)  # fmt: skip

    def wait(self) -> str:
        """The server's URL once its ``/health`` answers; a clear failure otherwise."""
        deadline = time.monotonic() + START_SECONDS
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"mlflow server exited:\n{self.log.read_text()[-3000:]}")
            try:
                urllib.request.urlopen(f"{self.url}/health", timeout=2).close()
                return self.url
            except OSError:
                time.sleep(0.5)
        raise RuntimeError(f"mlflow server did not answer in {START_SECONDS:.0f} s")

    def stop(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()


class Rest:
    """GET and POST on a tracking server's REST API (``/api/2.0/mlflow/...``) and its
    artifact route (``/get-artifact``)."""

    def __init__(self, url: str) -> None:
        self.url = url

    def get(self, endpoint: str, **query) -> dict:
        q = urllib.parse.urlencode(query)
        with urllib.request.urlopen(f"{self.url}/api/2.0/mlflow/{endpoint}?{q}", timeout=30) as r:
            return json.load(r)

    def post(self, endpoint: str, body: dict) -> dict:
        req = urllib.request.Request(
            f"{self.url}/api/2.0/mlflow/{endpoint}",
            data=json.dumps(body).encode(),
            headers={"Content-Type": "application/json"},
        )
        with urllib.request.urlopen(req, timeout=30) as r:
            return json.load(r)

    def runs(self, exp_id: str) -> list[dict]:
        """Every run of experiment ``exp_id`` (all pages)."""
        out, token = [], None
        while True:
            body = {"experiment_ids": [exp_id], "max_results": 1000}
            page = self.post("runs/search", body | ({"page_token": token} if token else {}))
            out += page.get("runs", [])
            token = page.get("next_page_token")
            if not token:
                return out

    def artifact(self, run_id: str, path: str) -> bytes:
        """An artifact's bytes as the UI fetches them."""
        q = urllib.parse.urlencode({"path": path, "run_uuid": run_id})
        with urllib.request.urlopen(f"{self.url}/get-artifact?{q}", timeout=30) as r:
            return r.read()

    def artifact_paths(self, run_id: str, path: str = "") -> set[str]:
        """Every file artifact of a run under ``path`` (recursively)."""
        files = self.get("artifacts/list", run_id=run_id, path=path).get("files", [])
        out = set()
        for f in files:
            out |= self.artifact_paths(run_id, f["path"]) if f["is_dir"] else {f["path"]}
        return out


def tags(run: dict) -> dict[str, str]:
    return {t["key"]: t["value"] for t in run["data"].get("tags", [])}


def params(run: dict) -> dict[str, str]:
    return {p["key"]: p["value"] for p in run["data"].get("params", [])}


def metrics(run: dict) -> dict[str, float]:
    return {m["key"]: m["value"] for m in run["data"].get("metrics", [])}
