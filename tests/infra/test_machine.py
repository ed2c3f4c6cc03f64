"""The machine's description: the first CPU's model, the usable cores, native bf16 or AVX2."""

import os

from vnrrt.infra.machine import describe

CPU = "processor\t: {i}\nmodel name\t: AMD  EPYC 9R14\nflags\t\t: fpu {flags}\n\n"


def test_a_cpu_is_named_by_model_cores_and_vector_units(tmp_path):
    cores = f"{len(os.sched_getaffinity(0))} cores"
    for flags, simd in (("avx2 avx512f avx512_bf16", ", avx512_bf16"), ("sse avx2", ", avx2"),
                        ("sse", "")):  # fmt: skip
        info = tmp_path / "cpuinfo"
        info.write_text("".join(CPU.format(i=i, flags=flags) for i in range(2)))
        assert describe(info) == f"AMD EPYC 9R14, {cores}{simd}"


def test_without_cpuinfo_the_platform_names_the_cpu(tmp_path):
    text = describe(tmp_path / "missing")
    assert "cores" in text and not text.startswith(",")


def test_trademarks_clock_and_core_count_are_left_out(tmp_path):
    info = tmp_path / "cpuinfo"
    intel = ("Intel(R) Xeon(R) Platinum 8375C CPU @ 2.90GHz", "Intel Xeon Platinum 8375C")
    for model, name in (intel, ("AMD EPYC 7R13 48-Core Processor", "AMD EPYC 7R13")):
        info.write_text(f"model name\t: {model}\nflags\t: avx2\n")
        assert describe(info).startswith(f"{name}, ")
