"""The benchmarks' description of the machine (benchmarks/tables.py): every field, never a crash.

Every benchmark table is printed under it (issue 40): the processor, numpy's SIMD level, the
BLAS core, the cores, the CPU-narrowing environment, versions and the date. It must say
``unknown`` rather than fail where threadpoolctl is missing or the library cannot be asked,
and show the environment variables that change the arithmetic when they are set.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parent.parent / "benchmarks"
FIELDS = ("processor", "simd", "blas", "numba", "cores", "environment", "python", "numpy",
          "system", "date")


@pytest.fixture
def tables():
    spec = importlib.util.spec_from_file_location("bench_tables", BENCHMARKS / "tables.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_machine_has_every_field(tables):
    info = tables.machine()
    assert set(FIELDS) <= set(info)
    for name in FIELDS:
        assert isinstance(info[name], str) and info[name], name
    assert info["python"] == ".".join(map(str, sys.version_info[:3]))
    import numpy as np

    assert info["numpy"] == np.__version__
    ext = tables.simd()
    assert set(ext) == {"baseline", "found", "not_found"}
    # Every dispatched feature is found or not, once.
    assert not set(ext["found"]) & set(ext["not_found"])
    assert "core " in info["blas"]
    lines = tables.machine_lines(info)
    assert len(lines) == 3
    text = "\n".join(lines)
    for name in ("processor", "simd", "blas", "date"):
        assert info[name] in text


def test_without_threadpoolctl_and_with_the_cpu_narrowed(tables, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "threadpoolctl", None)  # import raises ImportError
    monkeypatch.setenv("NPY_DISABLE_CPU_FEATURES", "X86_V4")
    monkeypatch.setenv("NUMBA_CPU_NAME", "generic")
    monkeypatch.setenv("OPENBLAS_CORETYPE", "Haswell")
    info = tables.machine()
    assert "NPY_DISABLE_CPU_FEATURES=X86_V4" in info["environment"]
    assert "NUMBA_CPU_NAME=generic" in info["environment"]
    assert "OPENBLAS_CORETYPE=Haswell" in info["environment"]
    assert info["numba"] == "generic"
    assert "core " in info["blas"]  # from the library through ctypes, or unknown
    for markdown in (False, True):
        tables.print_machine(markdown=markdown)
        assert "NUMBA_CPU_NAME=generic" in capsys.readouterr().out


def test_a_library_that_cannot_be_asked_gives_unknown(tables, monkeypatch):
    monkeypatch.setitem(sys.modules, "threadpoolctl", None)
    monkeypatch.setattr(tables, "_openblas_libraries", lambda: ["/nonexistent/libopenblas.so",
                                                                "/dev/null"])
    assert tables.blas().endswith("(core unknown)")
    monkeypatch.setattr(tables.Path, "read_text", _refuse)  # no /proc to read
    info = tables.machine()
    assert info["processor"]  # platform's answer, or "unknown"
    assert info["blas"].endswith("(core unknown)")


def _refuse(*args, **kwargs):
    raise OSError("not here")


def test_the_numpy_features_disabled_by_the_environment_are_not_found():
    """In a fresh process with numpy's widest level turned off, it is among the not found."""
    code = ("import sys; sys.path.insert(0, sys.argv[1]); import tables; "
            "e = tables.simd(); print(' '.join(e['found'])); print(' '.join(e['not_found']))")
    probe = subprocess.run([sys.executable, "-c", code, str(BENCHMARKS)], capture_output=True,
                           text=True, check=True)
    found = probe.stdout.splitlines()[0].split()
    levels = [f for f in found if f.startswith("X86_V")]
    if not levels:
        pytest.skip("no x86 dispatch level found by numpy on this machine")
    env = {"NPY_DISABLE_CPU_FEATURES": levels[-1], "PATH": "/usr/bin:/bin"}
    narrowed = subprocess.run([sys.executable, "-c", code, str(BENCHMARKS)],
                              capture_output=True, text=True, check=True, env=env)
    assert levels[-1] in narrowed.stdout.splitlines()[1].split()
