"""``--out`` of ``vnrrt plan`` and ``vnrrt predict`` never clobbers what the command did not
write: only the kinds it writes, an existing file of another kind refused (left byte for
byte), a missing directory an error (exit 2, one line naming --out)."""

import numpy as np
import pytest

from vnrrt.cli.main import main

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def map_npy(tmp_path):
    g = np.zeros((40, 40), np.uint8)
    path = tmp_path / "map.npy"
    np.save(path, g)
    return path


def _plan(map_npy, out):
    return main(["plan", "--map", str(map_npy), "--start", "4.5,4.5", "--goal", "30.5,20.5",
                 "--out", str(out)])  # fmt: skip


def _one_line_error(capsys, *words):
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for w in words:
        assert w in err, err


@pytest.mark.parametrize("name", ["important.txt", "plan.npy", "plan.PNG.bak", "plan"])
def test_plan_refuses_a_name_of_a_kind_it_does_not_write(map_npy, tmp_path, capsys, name):
    out = tmp_path / name
    out.write_bytes(b"precious text\n")
    assert _plan(map_npy, out) == 2
    _one_line_error(capsys, "--out", str(out), ".png")
    assert out.read_bytes() == b"precious text\n"


def test_plan_never_overwrites_an_existing_file_that_is_not_a_png(map_npy, tmp_path, capsys):
    out = tmp_path / "notes.png"
    out.write_bytes(b"a text file named .png\n")
    assert _plan(map_npy, out) == 2
    _one_line_error(capsys, "not overwriting", str(out))
    assert out.read_bytes() == b"a text file named .png\n"


def test_plan_replaces_its_own_kind_of_file(map_npy, tmp_path, capsys):
    out = tmp_path / "plan.png"
    assert _plan(map_npy, out) == 0
    first = out.read_bytes()
    assert first.startswith(PNG)
    assert _plan(map_npy, out) == 0  # a PNG (an earlier figure) is replaced
    assert out.read_bytes().startswith(PNG)


def test_a_missing_directory_is_an_error_and_nothing_is_created(map_npy, tmp_path, capsys):
    out = tmp_path / "no" / "such" / "plan.png"
    assert _plan(map_npy, out) == 2
    _one_line_error(capsys, "does not exist", str(out.parent))
    assert not (tmp_path / "no").exists()


@pytest.mark.parametrize(
    ("name", "content", "words"),
    [
        ("heat.txt", b"text\n", ["give a .npy or .png"]),
        ("heat.npy", b"not numpy\n", ["not overwriting"]),
        ("heat.png", b"not a png\n", ["not overwriting"]),
        ("missing/heat.npy", None, ["does not exist"]),
    ],
)
def test_predict_checks_out_the_same_way_before_loading_anything(map_npy, tmp_path, capsys,
                                                                 name, content, words):  # fmt: skip
    out = tmp_path / name
    if content is not None:
        out.write_bytes(content)
    rc = main(["predict", "--checkpoint", str(tmp_path / "absent.ckpt"), "--map", str(map_npy),
               "--start", "4.5,4.5", "--goal", "30.5,20.5", "--out", str(out)])  # fmt: skip
    assert rc == 2
    _one_line_error(capsys, *words)
    if content is not None:
        assert out.read_bytes() == content
