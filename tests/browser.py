"""Headless Chromium (Debian's ``chromium``) driven over the DevTools protocol on a pipe
(``--remote-debugging-pipe``: no extra Python package, no port), for the MLflow UI checks and
the README's screenshot.

As a command, the screenshot of an evaluation run's page for the README:
``python -m tests.browser <UI url> <experiment id> <run id> docs/mlflow_evaluation_run.png``.
"""

from __future__ import annotations

import base64
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--remote-debugging-pipe"]  # fmt: skip
CLICK = """(text) => { const hit = [...document.querySelectorAll(
  'button,[role=button],[role=tab],a,span,label')].filter(e =>
  (e.innerText || e.getAttribute('aria-label') || '').trim() === text).pop();
  if (hit) { hit.click(); } return Boolean(hit); }"""


def chromium() -> str | None:
    """The Chromium binary on PATH (``chromium`` or ``chromium-browser``), or None."""
    return shutil.which("chromium") or shutil.which("chromium-browser")


class Browser:
    """One headless Chromium with one page of ``width`` x ``height`` CSS px; a context
    manager. Messages are JSON, NUL-terminated, on fds 3 (to Chromium) and 4 (from it)."""

    def __init__(self, width: int = 1400, height: int = 1300) -> None:
        self.profile = tempfile.mkdtemp(prefix="vnrrt-chromium-")
        to_child, self._write = os.pipe()
        self._read, from_child = os.pipe()

        def fds() -> None:  # in the child: its ends as fds 3 and 4
            a, b = os.dup(to_child), os.dup(from_child)
            os.dup2(a, 3)
            os.dup2(b, 4)

        cmd = [chromium(), *FLAGS, f"--user-data-dir={self.profile}", "about:blank"]
        quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
        self.proc = subprocess.Popen(cmd, preexec_fn=fds, close_fds=False, **quiet)
        os.close(to_child)
        os.close(from_child)
        self._buf, self._id = b"", 0
        target = self.send("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.send("Target.attachToTarget", targetId=target, flatten=True)[
            "sessionId"
        ]
        self.send("Page.enable", session=True)
        self.send("Emulation.setDeviceMetricsOverride", session=True, width=width,
                  height=height, deviceScaleFactor=1, mobile=False)  # fmt: skip

    def send(self, method: str, session: bool = False, **params) -> dict:
        """One DevTools command's result (on the page when ``session``)."""
        self._id += 1
        msg = {"id": self._id, "method": method, "params": params}
        if session:
            msg["sessionId"] = self.session
        os.write(self._write, json.dumps(msg).encode() + b"\0")
        while True:
            while b"\0" not in self._buf:
                chunk = os.read(self._read, 1 << 20)
                if not chunk:
                    raise RuntimeError("chromium closed its pipe")
                self._buf += chunk
            raw, self._buf = self._buf.split(b"\0", 1)
            reply = json.loads(raw)
            if reply.get("id") == self._id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply["result"]

    def goto(self, url: str, settle: float = 4.0) -> None:
        self.send("Page.navigate", session=True, url=url)
        time.sleep(settle)

    def js(self, expression: str):
        """The value of a JavaScript expression in the page (promises awaited)."""
        r = self.send("Runtime.evaluate", session=True, expression=expression,
                      returnByValue=True, awaitPromise=True)  # fmt: skip
        return r.get("result", {}).get("value")

    def click(self, text: str) -> bool:
        """Click the last element whose text (or label) is ``text``; whether there was one."""
        return bool(self.js(f"({CLICK})({json.dumps(text)})"))

    def wait_for(self, expression: str, seconds: float = 30.0):
        """Poll ``expression`` until it is truthy (its value) or ``seconds`` pass (None)."""
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            value = self.js(expression)
            if value:
                return value
            time.sleep(0.5)
        return None

    def screenshot(self, out: Path) -> None:
        data = self.send("Page.captureScreenshot", session=True, format="png")["data"]
        Path(out).write_bytes(base64.b64decode(data))

    def __enter__(self) -> Browser:
        return self

    def __exit__(self, *exc) -> None:
        self.proc.kill()
        self.proc.wait()
        os.close(self._write)
        os.close(self._read)
        shutil.rmtree(self.profile, ignore_errors=True)


def open_run_page(b: Browser, ui: str, exp: str, run: str) -> None:
    """The run's overview page in the UI's model-training view, the assistant panel closed
    and the description expanded."""
    b.goto(f"{ui}/#/experiments/{exp}/runs/{run}")
    b.wait_for("document.body.innerText.includes('Description')")
    b.click("Model training")  # the toggle leaves the run page for the run list
    time.sleep(2)
    b.goto(f"{ui}/#/experiments/{exp}/runs/{run}")
    b.wait_for("document.body.innerText.includes('Show more')", 15)
    b.click("Close")  # the assistant panel
    b.click("Show more")
    time.sleep(1.5)


if __name__ == "__main__":
    ui, exp_id, run_id, png = sys.argv[1:5]
    with Browser(width=1760, height=1240) as page:
        open_run_page(page, ui, exp_id, run_id)
        page.screenshot(Path(png))
