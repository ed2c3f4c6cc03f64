"""The tracking store is checked for what it is before any work: a web server that does not
answer MLflow's REST API is named as such at once, a local SQLite store that is not an
intact database is named with its file. The web servers here are the test's own, on
127.0.0.1, stopped at the end; no other address is contacted."""

import http.server
import sqlite3
import threading
import time

import pytest

from vnrrt.tracking.store import MLFLOW_PROBE, TrackingError, check_store


class _Answer(http.server.BaseHTTPRequestHandler):
    status, body, seen = 404, b"<html>not found</html>", []

    def do_GET(self):
        self.seen.append(self.path)
        self.send_response(self.status)
        self.send_header("Content-Type", "text/html")
        self.end_headers()
        self.wfile.write(self.body)

    def log_message(self, *args):
        pass


@pytest.fixture
def web():
    """Start a plain web server on 127.0.0.1 answering ``(status, body)``; stop it after."""
    servers = []

    def start(status: int, body: bytes) -> str:
        handler = type("Handler", (_Answer,), {"status": status, "body": body, "seen": []})
        server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
        threading.Thread(target=server.serve_forever, daemon=True).start()
        servers.append(server)
        return f"http://127.0.0.1:{server.server_address[1]}"

    yield start
    for server in servers:
        server.shutdown()
        server.server_close()


@pytest.mark.parametrize(
    ("status", "body", "why"),
    [
        (404, b"<html>not found</html>", "HTTP 404"),
        (200, b"<html>a wiki</html>", "no JSON object"),
        (200, b"[1, 2]", "no JSON object"),
        (405, b"", "HTTP 405"),
    ],
)
def test_a_server_that_is_not_mlflow_is_named_at_once(web, status, body, why):
    url = web(status, body)
    tick = time.monotonic()
    with pytest.raises(TrackingError) as err:
        check_store(url)
    text = str(err.value)
    assert f"{url} answers but is not an MLflow tracking server" in text and why in text, text
    assert "\n" not in text and time.monotonic() - tick < 3.0


def test_a_json_answer_or_a_request_for_credentials_passes(web):
    for status, body in ((200, b'{"experiments": []}'), (401, b""), (403, b"")):
        url = web(status, body)
        check_store(url)  # no error
        check_store.cache_clear()


def test_a_server_error_and_a_closed_port_are_named(web):
    url = web(503, b"")
    with pytest.raises(TrackingError, match="answers HTTP 503"):
        check_store(url)
    closed = url.rsplit(":", 1)[0] + ":1"  # port 1 of 127.0.0.1: nothing listens
    with pytest.raises(TrackingError, match="does not answer"):
        check_store(closed)


def test_the_probe_is_an_mlflow_rest_path(web):
    url = web(200, b"{}")
    check_store(url)
    assert MLFLOW_PROBE.startswith("/api/2.0/mlflow/")


def _database(path):
    with sqlite3.connect(path) as con:
        con.execute("CREATE TABLE runs (id INTEGER PRIMARY KEY, name TEXT)")
        con.executemany(
            "INSERT INTO runs (name) VALUES (?)", [(f"run {i}" * 20,) for i in range(3000)]
        )
    con.close()
    return path


def test_a_healthy_or_missing_sqlite_store_passes(tmp_path):
    check_store(f"sqlite:///{_database(tmp_path / 'mlflow.db')}")
    check_store(f"sqlite:///{tmp_path / 'new' / 'mlflow.db'}")  # created by MLflow


@pytest.mark.parametrize("damage", ["text", "truncated", "flipped"])
def test_a_damaged_sqlite_store_is_named_with_its_file(tmp_path, damage):
    db = _database(tmp_path / "mlflow.db")
    raw = db.read_bytes()
    if damage == "text":
        db.write_text("this is not a database\n")
    elif damage == "truncated":
        db.write_bytes(raw[: len(raw) // 3])
    else:  # the root page of table runs, in the middle of the file: damaged b-tree
        b = bytearray(raw)
        for pos in range(4096 + 0, 4096 + 16):
            b[pos] ^= 0xFF
        db.write_bytes(bytes(b))
    with pytest.raises(TrackingError) as err:
        check_store(f"sqlite:///{db}")
    text = str(err.value)
    assert str(db) in text and "\n" not in text and "move it aside" in text, text


@pytest.mark.slow
def test_a_real_mlflow_server_passes(tmp_path):
    from tests.mlflow_server import TrackingServer

    server = TrackingServer(tmp_path / "mlflow.db", tmp_path / "server.log")
    try:
        check_store(server.wait())
    finally:
        server.stop()
