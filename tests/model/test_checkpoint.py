"""Checkpoints are safe and tamper-evident: loading runs no code a file names (crafted files
touch nothing), a changed weight is caught from the file itself, non-finite weights and
out-of-range record values are refused, older checkpoints load only beside a matching
``.sha256``, and every failure is one :class:`CheckpointError` line."""

import inspect
import os
from pathlib import Path

import numpy as np
import pytest
import torch

from tests.conftest import REPO
from vnrrt.model import VertexNet
from vnrrt.model.checkpoint import (
    CheckpointError,
    checksum_file,
    load_network,
    read_checkpoint,
    write_checksum,
)

SKIP = ("__pycache__", ".hypothesis", ".pytest_cache", ".ruff_cache", ".tmp-")


def snapshot(*roots: Path) -> dict[Path, tuple[int, int]]:
    """(mtime ns, size) of every file under ``roots`` (caches of tools left out)."""
    out = {}
    for root in roots:
        for path in root.rglob("*"):
            if path.is_file() and not any(s in str(path) for s in SKIP):
                st = path.stat()
                out[path] = (st.st_mtime_ns, st.st_size)
    return out


def outcome(fn):
    """The exception ``fn()`` raised, or None."""
    try:
        fn()
    except Exception as err:
        return err
    return None


def save_legacy(ckpt: dict, path: Path) -> Path:
    """``ckpt`` written as checkpoints were before records carried a digest, with the
    ``.sha256`` file the pipeline wrote beside them."""
    ckpt["vnrrt"] = {k: v for k, v in ckpt["vnrrt"].items() if k != "sha256"}
    torch.save(ckpt, path)
    write_checksum(path)
    return path


def crafted_nets(victim: Path, created: Path) -> dict[str, dict]:
    """``record.net`` configs that ran code when a checkpoint was loaded through
    ``hydra.utils.instantiate``: truncating ``victim`` (opened for writing; Hydra blocks
    ``os.truncate`` but not ``open``), writing ``created``."""
    truncate = {"_target_": "builtins.open", "_args_": [str(victim), "w"]}
    path = {"_target_": "pathlib.Path", "_args_": [str(created)]}
    write = {"_target_": "pathlib.Path.write_text", "_args_": [path, "pwned"]}
    return {
        "another class": {"_target_": "builtins.dict", "a": truncate, "b": write},
        "a nested value": {
            "_target_": "vnrrt.model.VertexNet",
            "encoder": "resnet18",
            "encoder_width": 0.5,
            "decoder_width": 0.25,
            "prior": truncate,
        },
    }


@pytest.mark.parametrize("craft", ["another class", "a nested value"])
def test_a_crafted_checkpoint_runs_no_code_and_touches_no_file(trained, tmp_path, craft):
    victim, created = tmp_path / "victim.txt", tmp_path / "created.txt"
    victim.write_text("precious")
    ckpt = read_checkpoint(trained / "models" / "vertexnet.ckpt")
    ckpt["vnrrt"]["net"] = crafted_nets(victim, created)[craft]
    torch.save(ckpt, tmp_path / "crafted.ckpt")
    before = snapshot(REPO, trained, tmp_path)
    err = outcome(lambda: load_network(tmp_path / "crafted.ckpt"))
    assert victim.read_text() == "precious" and not created.exists()
    assert snapshot(REPO, trained, tmp_path) == before  # no file touched anywhere we look
    assert isinstance(err, CheckpointError) and "\n" not in str(err)
    assert "crafted.ckpt: record.net" in str(err)


def test_the_checked_arguments_are_exactly_vertexnets():
    from vnrrt.model.checkpoint import NET_ARGS, TRAINING_ARGS

    params = set(inspect.signature(VertexNet).parameters)
    assert params == set(NET_ARGS) | set(TRAINING_ARGS)


def test_a_flipped_weight_byte_is_caught_without_a_sidecar(trained, tmp_path):
    """The digest in the record catches one flipped byte inside a weight tensor, with no
    ``.sha256`` beside the file (torch itself loads such a file without complaint)."""
    good = trained / "models" / "vertexnet.ckpt"
    weight = read_checkpoint(good)["state_dict"]["net.head.weight"]
    data = bytearray(good.read_bytes())
    at = data.find(weight.numpy().tobytes()[:64])
    assert at > 0  # the tensor's bytes lie in the archive as they are
    data[at + 10] ^= 0x01
    (tmp_path / "flipped.ckpt").write_bytes(bytes(data))
    assert not checksum_file(tmp_path / "flipped.ckpt").exists()
    assert torch.load(tmp_path / "flipped.ckpt", weights_only=True)  # loads as garbage
    with pytest.raises(CheckpointError, match="do not match the sha256 stored in it"):
        load_network(tmp_path / "flipped.ckpt")


def test_an_older_checkpoint_loads_only_beside_its_sha256(trained, tmp_path):
    ckpt = read_checkpoint(trained / "models" / "vertexnet.ckpt")
    legacy = save_legacy(ckpt, tmp_path / "legacy.ckpt")
    net, record = load_network(legacy, "vertexnet", verify=True)
    want = load_network(trained / "models" / "vertexnet.ckpt")[0].state_dict()
    for key, value in net.state_dict().items():
        torch.testing.assert_close(value, want[key], msg=key)
    assert "sha256" not in record
    checksum_file(legacy).unlink()
    with pytest.raises(CheckpointError, match=r"stores no sha256 .* beside it: retrain it"):
        load_network(legacy)


def test_non_finite_weights_are_refused_and_predict_writes_nothing(trained, tmp_path, capsys):
    from vnrrt.cli.main import main

    ckpt = read_checkpoint(trained / "models" / "vertexnet.ckpt")
    ckpt["state_dict"]["net.head.weight"][0, 0, 0, 0] = float("nan")
    nan = save_legacy(ckpt, tmp_path / "nan.ckpt")  # its sha256 matches: only NaN is wrong
    with pytest.raises(CheckpointError, match=r"non-finite weights \(NaN or inf\) in "
                                              r"net\.head\.weight: retrain it"):  # fmt: skip
        load_network(nan)
    np.save(tmp_path / "map.npy", np.zeros((64, 64), np.uint8))
    out = tmp_path / "h.npy"
    rc = main(["predict", "--checkpoint", str(nan), "--map", str(tmp_path / "map.npy"),
               "--start", "3.5,3.5", "--goal", "60.5,60.5", "--out", str(out)])  # fmt: skip
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "non-finite weights" in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("where", "value", "message"),
    [
        ("net.encoder", "resnet9000", r"record\.net\.encoder='resnet9000' is not one of"),
        ("net.decoder_width", 1e6, r"record\.net\.decoder_width=1000000\.0 is not a number in"),
        ("net.out_channels", True, r"record\.net\.out_channels=True is not an integer"),
        ("net.activation", "gelu", r"record\.net\.activation is not an argument of"),
        ("target.kind", "door", r"record\.target .* has no kind in \('vertex', 'path'\)"),
        ("render.extra", 1, r"record\.render .* is not \{marker_radius"),
    ],
)  # fmt: skip
def test_record_values_out_of_range_are_refused_naming_the_key(trained, tmp_path, where, value,
                                                               message):  # fmt: skip
    """Sealed (a digest that matches), so only the value itself is wrong."""
    from vnrrt.model.checkpoint import seal

    ckpt = read_checkpoint(trained / "models" / "vertexnet.ckpt")
    section, key = where.split(".")
    ckpt["vnrrt"][section][key] = value
    torch.save(seal(ckpt), tmp_path / "bad.ckpt")
    with pytest.raises(CheckpointError, match=message):
        load_network(tmp_path / "bad.ckpt")


def test_every_loading_failure_is_one_checkpoint_error_line(trained, tmp_path):
    good = trained / "models" / "vertexnet.ckpt"
    cases = {"missing.ckpt": None, "empty.ckpt": b"", "text.ckpt": b"not a checkpoint",
             "cut.ckpt": good.read_bytes()[: os.path.getsize(good) // 2]}  # fmt: skip
    for name, data in cases.items():
        if data is not None:
            (tmp_path / name).write_bytes(data)
        err = outcome(lambda name=name: load_network(tmp_path / name))
        assert isinstance(err, CheckpointError) and "\n" not in str(err), (name, err)
        assert name in str(err)
    ckpt = torch.load(good, weights_only=True)
    ckpt["state_dict"]["net.head.bias"] = [1.0, 2.0]  # not a tensor
    torch.save(ckpt, tmp_path / "list.ckpt")
    with pytest.raises(CheckpointError, match="holds more than named tensors"):
        load_network(tmp_path / "list.ckpt")
