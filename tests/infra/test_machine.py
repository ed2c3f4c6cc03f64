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
