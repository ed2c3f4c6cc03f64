"""``vnrrt plan`` on MovingAI files: a ``.map`` wherever a map goes, and a batch of a
``.scen`` file's queries (selection by index, longest, limit; one row per query, skipped
queries named, a summary line; exit codes), checked against the files' own text."""

from __future__ import annotations

import pytest

from tests.conftest import REPO
from vnrrt.cli.main import main

MAI = REPO / "data" / "movingai"
ARENA = ["--map", str(MAI / "arena.map")]


def _rows(out: str) -> tuple[list[list[str]], str]:
    lines = out.strip().splitlines()
    assert lines[0].split() == ["line", "bucket", "start", "goal", "solved", "cost", "optimal",
                                "time_ms"]  # fmt: skip
    assert lines[-1].startswith("summary: ")
    return [line.split() for line in lines[1:-1]], lines[-1]


def _file_rows(name: str) -> list[list[str]]:
    return [line.split("\t") for line in (MAI / name).read_text().splitlines()[1:]]


def test_a_map_file_plans_one_query_with_its_references(capsys):
    f = _file_rows("arena.map.scen")[-1]  # the file's last query and its published length
    start, goal = f"{int(f[4]) + 0.5},{int(f[5]) + 0.5}", f"{int(f[6]) + 0.5},{int(f[7]) + 0.5}"
    assert main(["plan", *ARENA, "--start", start, "--goal", goal]) == 0
    out = capsys.readouterr().out
    assert "success=True" in out
    assert f"reference lengths: A* {float(f[8]):.2f} px" in out


def test_the_longest_queries_are_planned_one_row_each(capsys):
    scen = ["--scen", str(MAI / "arena.map.scen")]
    assert main(["plan", *ARENA, *scen, "--longest", "4", "--stop", "optimal"]) == 0
    rows, summary = _rows(capsys.readouterr().out)
    file_rows = _file_rows("arena.map.scen")
    by_length = sorted(range(len(file_rows)), key=lambda i: (-float(file_rows[i][8]), i))
    assert [int(r[0]) for r in rows] == sorted(i + 2 for i in by_length[:4])  # 1-based lines
    for r in rows:
        f = file_rows[int(r[0]) - 2]
        assert r[2] == f"({f[4]},{f[5]})" and r[3] == f"({f[6]},{f[7]})"
        assert float(r[6]) == pytest.approx(float(f[8]), abs=5e-4) and r[4] == "yes"
        assert float(r[5]) <= 1.01 * float(f[8])  # stop rule: within 1% of the A* length
    assert summary.startswith("summary: solved 4 of 4 planned (0 skipped) of 160 in ")
    assert "planner rrt_star, stop optimal, budget 200000 iterations / 30 s" in summary


def test_rows_limit_and_skipped_queries(capsys):
    lost = ["--map", str(MAI / "losttemple.map"), "--scen", str(MAI / "losttemple.map.scen")]
    assert main(["plan", *lost, "--scen-rows", "38-40,3", "--limit", "3"]) == 0
    rows, summary = _rows(capsys.readouterr().out)
    assert [r[0] for r in rows] == ["5", "40", "41"]  # indices 3, 38, 39: lines 5, 40, 41
    assert main(["plan", *lost, "--scen-rows", "40"]) == 0  # line 42: a start on a wall
    rows, summary = _rows(capsys.readouterr().out)
    assert " ".join(rows[0]) == "42 4 (390,443) (377,432) skipped: start (390, 443) lies on " \
                                "an obstacle of the map"  # fmt: skip
    assert "solved 0 of 0 planned (1 skipped) of 1238" in summary


def test_a_budget_hit_in_a_batch_exits_1(capsys):
    scen = ["--scen", str(MAI / "arena.map.scen"), "--longest", "2", "--stop", "optimal"]
    assert main(["plan", *ARENA, *scen, "--set", "max_iterations=1"]) == 1
    rows, summary = _rows(capsys.readouterr().out)
    assert [r[4] for r in rows] == ["no", "no"]
    assert "solved 0 of 2 planned" in summary and "--set max_iterations=1" in summary


@pytest.mark.parametrize(("extra", "message"), [
    (["--scen", str(MAI / "lak304d.map.scen")],
     "lak304d.map.scen, line 2: scenario for a 193x194 map, but the map is 49x49"),
    (["--scen", str(MAI / "arena.map.scen"), "--start", "1,1"], "--start does not go with"),
    (["--scen", str(MAI / "arena.map.scen"), "--scen-rows", "5-2"], "--scen-rows '5-2'"),
    (["--scen", str(MAI / "arena.map.scen"), "--scen-rows", "160"], "not a range in [0, 160)"),
    (["--scen", str(MAI / "arena.map.scen"), "--scen-rows", "a"], "expected indices"),
    (["--scen", str(MAI / "arena.map.scen"), "--longest", "0"], "--longest 0: must be at"),
    (["--scen", "missing.scen"], "scenario file missing.scen not found"),
    (["--scen", str(MAI / "arena.map.scen"), "--planner", "vnrrt_star"], "needs --checkpoint"),
    (["--limit", "3"], "--limit needs --scen"),
])  # fmt: skip
def test_bad_batch_arguments_are_one_line_and_exit_2(extra, message, capsys):
    assert main(["plan", *ARENA, *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_a_malformed_map_names_its_line_and_exits_2(tmp_path, capsys):
    bad = tmp_path / "bad.map"
    bad.write_text("type octile\nheight 2\nwidth 3\nmap\n...\n.x.\n")
    assert main(["plan", "--map", str(bad), "--start", "0.5,0.5", "--goal", "2.5,0.5"]) == 2
    assert f"{bad}, line 6: unknown terrain 'x' at x=1" in capsys.readouterr().err
    scen = tmp_path / "bad.scen"
    scen.write_text("version 1\n1\tarena.map\t49\t49\t1\t11\n")
    assert main(["plan", *ARENA, "--scen", str(scen)]) == 2
    assert f"{scen}, line 2: expected 9 fields" in capsys.readouterr().err
