"""Records what a pipeline stage script writes (tests/pipeline/test_pipeline.py puts this folder on
``PYTHONPATH`` for ``dvc repro``): a process running ``stages/<name>.py`` snapshots the files
under its working directory at start and at exit, and appends the files it created or changed
to ``$VNRRT_WRITE_LOG`` as one JSON line ``{"argv": [...], "written": [...]}``. Other
processes (DVC itself) are left alone."""

import atexit
import json
import os
import sys
from pathlib import Path

SKIP = {".git", ".dvc", "__pycache__"}


def _snapshot(root: Path) -> dict[str, tuple[int, int]]:
    out = {}
    for folder, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if d not in SKIP]
        for name in files:
            path = Path(folder) / name
            try:
                st = path.stat()
            except OSError:
                continue
            out[str(path.relative_to(root))] = (st.st_mtime_ns, st.st_size)
    return out


def _install() -> None:
    log = os.environ.get("VNRRT_WRITE_LOG")
    script = sys.argv[0] if sys.argv else ""
    if not log or Path(script).parent.name != "stages":
        return
    root = Path.cwd()
    before = _snapshot(root)

    def record() -> None:
        after = _snapshot(root)
        written = sorted(k for k, v in after.items() if before.get(k) != v)
        with open(log, "a") as f:
            f.write(json.dumps({"argv": sys.argv, "written": written}) + "\n")

    atexit.register(record)


_install()
