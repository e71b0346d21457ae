"""The benchmarks' one table printer (aligned text, or Markdown for docs/benchmarks.md), and the
description of the machine every table is printed with (:func:`print_machine`).

A time means little without the machine it was taken on: the same sweep runs 120 points/s on
one 2-core cloud machine and 50 on another. So every benchmark prints, above its table, the
processor, the SIMD level numpy dispatches to, whether numpy's or numba's CPU features were
narrowed by the environment, the BLAS library and the core type it chose, the cores, Python's
and numpy's versions and the date (:func:`machine_lines`). Each part that cannot be found says
``unknown`` rather than stopping the benchmark.
"""

from __future__ import annotations

import ctypes
import datetime
import glob
import os
import platform
import sys
from collections.abc import Sequence
from pathlib import Path

#: Environment variables that change the arithmetic or its speed, reported when set: numpy's
#: and numba's CPU features, OpenBLAS's core type and threads.
ENVIRONMENT = ("NPY_DISABLE_CPU_FEATURES", "NPY_ENABLE_CPU_FEATURES", "NUMBA_CPU_NAME",
               "NUMBA_CPU_FEATURES", "OPENBLAS_CORETYPE", "OPENBLAS_NUM_THREADS",
               "OMP_NUM_THREADS")
#: The names OpenBLAS builds export for its core type (numpy's and SciPy's bundled
#: ``scipy_openblas`` with its 64-bit-integer suffix or without, a plain OpenBLAS).
CORENAME_SYMBOLS = ("scipy_openblas_get_corename64_", "scipy_openblas_get_corename",
                    "openblas_get_corename")


def print_table(header: Sequence[str], rows: Sequence[Sequence[str]], *,
                markdown: bool = False, right: Sequence[int] = ()) -> None:
    """Print ``rows`` (cells as strings) under ``header``.

    Text: columns padded to their widest cell (those in ``right`` aligned right), a rule under
    the header. Markdown: a pipe table.
    """
    table = [tuple(header), *(tuple(r) for r in rows)]
    if markdown:
        for i, r in enumerate(table):
            print("| " + " | ".join(c.replace("|", "\\|") for c in r) + " |")
            if i == 0:
                print("|" + "---|" * len(header))
        return
    widths = [max(len(r[i]) for r in table) for i in range(len(header))]
    for i, r in enumerate(table):
        print("  ".join(c.rjust(w) if j in right else c.ljust(w)
                        for j, (c, w) in enumerate(zip(r, widths, strict=True))).rstrip())
        if i == 0:
            print("  ".join("-" * w for w in widths))


# -- the machine --------------------------------------------------------------------------------


def processor() -> str:
    """The processor's model name (Linux: /proc/cpuinfo; elsewhere what ``platform`` says)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith(("model name", "Model name", "cpu model")):
                return " ".join(line.split(":", 1)[1].split())
    except OSError:
        pass
    if sys.platform == "darwin":
        import subprocess

        try:
            out = subprocess.run(["sysctl", "-n", "machdep.cpu.brand_string"],
                                 capture_output=True, text=True, timeout=5, check=False)
            if out.stdout.strip():
                return out.stdout.strip()
        except (OSError, subprocess.SubprocessError):
            pass
    return platform.processor() or platform.machine() or "unknown"


def simd() -> dict[str, list[str]]:
    """numpy's SIMD extensions as ``numpy.show_runtime()`` lists them.

    ``baseline`` (compiled in), ``found`` and ``not_found`` (the dispatched ones this machine
    runs, or does not: a feature disabled by ``NPY_DISABLE_CPU_FEATURES`` is not found).
    Empty lists where numpy does not say.
    """
    try:
        from numpy._core._multiarray_umath import (  # numpy ≥ 2
            __cpu_baseline__,
            __cpu_dispatch__,
            __cpu_features__,
        )
    except ImportError:
        try:
            from numpy.core._multiarray_umath import (  # type: ignore[no-redef]  # numpy 1.x
                __cpu_baseline__,
                __cpu_dispatch__,
                __cpu_features__,
            )
        except ImportError:
            return {"baseline": [], "found": [], "not_found": []}
    found = [f for f in __cpu_dispatch__ if __cpu_features__.get(f)]
    return {"baseline": list(__cpu_baseline__), "found": found,
            "not_found": [f for f in __cpu_dispatch__ if f not in found]}


def simd_level(ext: dict[str, list[str]]) -> str:
    """One phrase: the widest level numpy runs and what it leaves out.

    E.g. ``X86_V4 (found X86_V3 X86_V4 AVX512_ICL; not found AVX512_SPR)``.
    """
    found, missing = ext["found"], ext["not_found"]
    levels = [f for f in found if f.startswith("X86_V")] or found or ext["baseline"]
    top = levels[-1] if levels else "unknown"
    return (f"{top} (baseline {' '.join(ext['baseline']) or '—'}; found "
            f"{' '.join(found) or '—'}; not found {' '.join(missing) or '—'})")


def _openblas_libraries() -> list[str]:
    """Paths of the OpenBLAS libraries numpy (and SciPy) bring, the loaded ones first."""
    paths: list[str] = []
    try:  # what this process has mapped (Linux)
        for line in Path("/proc/self/maps").read_text().splitlines():
            path = line.split()[-1] if len(line.split()) >= 6 else ""
            if "openblas" in path.lower() and path not in paths:
                paths.append(path)
    except OSError:
        pass
    try:
        import numpy as np

        site = Path(np.__file__).resolve().parent.parent
        for pattern in ("numpy.libs/*openblas*", "numpy/.dylibs/*openblas*",
                        "scipy_openblas*/lib/*openblas*"):
            paths += [p for p in sorted(glob.glob(str(site / pattern))) if p not in paths]
    except ImportError:
        pass
    return paths


def blas() -> str:
    """The BLAS numpy uses and its core type, e.g. ``scipy-openblas 0.3.31 (core SkylakeX)``.

    The core type from threadpoolctl where it is installed, else from the library itself
    (``openblas_get_corename`` through ctypes); ``unknown`` where neither says.
    """
    name = "unknown"
    try:
        import numpy as np

        deps = np.show_config(mode="dicts").get("Build Dependencies", {})  # type: ignore[union-attr]
        info = deps.get("blas", {})
        if info.get("name"):
            name = f"{info['name']} {info.get('version', '')}".strip()
    except Exception:  # noqa: BLE001 - a description, never a failure
        pass
    core = "unknown"
    try:
        from threadpoolctl import threadpool_info

        for pool in threadpool_info():
            if pool.get("user_api") == "blas":
                core = str(pool.get("architecture") or "unknown")
                name = f"{pool.get('internal_api', name)} {pool.get('version', '')}".strip()
                break
    except Exception:  # noqa: BLE001 - not installed, or it failed: ask the library
        core = "unknown"
    if core == "unknown":
        core = _corename_by_ctypes()
    return f"{name} (core {core})"


def _corename_by_ctypes() -> str:
    """OpenBLAS's ``get_corename`` of the first library that has one, else ``unknown``."""
    for path in _openblas_libraries():
        try:
            lib = ctypes.CDLL(path)
        except OSError:
            continue
        for symbol in CORENAME_SYMBOLS:
            fn = getattr(lib, symbol, None)
            if fn is None:
                continue
            fn.restype = ctypes.c_char_p
            fn.argtypes = []
            try:
                value = fn()
            except Exception:  # noqa: BLE001 - a description, never a failure
                continue
            if value:
                return value.decode(errors="replace").strip()
    return "unknown"


def numba_target() -> str:
    """The CPU numba compiles for: ``NUMBA_CPU_NAME`` where set, else LLVM's host CPU name."""
    if os.environ.get("NUMBA_CPU_NAME"):
        return os.environ["NUMBA_CPU_NAME"]
    try:
        import llvmlite.binding as llvm

        return str(llvm.get_host_cpu_name())
    except Exception:  # noqa: BLE001 - not installed, or it failed
        return "unknown"


def machine() -> dict[str, str]:
    """The machine a benchmark runs on, field by field (each a string; ``unknown`` if unknown).

    ``processor``, ``simd``, ``blas``, ``numba`` (its target CPU), ``cores``,
    ``environment`` (the variables of :data:`ENVIRONMENT` that are set, or ``none set``),
    ``python``, ``numpy``, ``system``, ``date``.
    """
    try:
        import numpy as np

        numpy_version = np.__version__
        level = simd_level(simd())
    except ImportError:
        numpy_version, level = "unknown", "unknown"
    env = [f"{k}={os.environ[k]}" for k in ENVIRONMENT if k in os.environ]
    try:
        cores = len(os.sched_getaffinity(0))
        count = f"{cores} usable of {os.cpu_count()}"
    except AttributeError:
        count = str(os.cpu_count() or "unknown")
    return {
        "processor": processor(),
        "simd": level,
        "blas": blas(),
        "numba": numba_target(),
        "cores": count,
        "environment": " ".join(env) or "none set",
        "python": platform.python_version(),
        "numpy": numpy_version,
        "system": f"{platform.system()} {platform.release()} {platform.machine()}".strip(),
        "date": datetime.datetime.now().astimezone().isoformat(timespec="minutes"),
    }


def machine_lines(info: dict[str, str] | None = None) -> list[str]:
    """The machine in three lines (see :func:`machine`)."""
    m = machine() if info is None else info
    return [
        f"machine: {m['processor']}, {m['cores']} cores; {m['system']}",
        f"numpy {m['numpy']} SIMD: {m['simd']}; BLAS: {m['blas']}",
        f"Python {m['python']}; numba target {m['numba']}; CPU environment: "
        f"{m['environment']}; date {m['date']}",
    ]


def print_machine(*, markdown: bool = False) -> None:
    """Print :func:`machine_lines` (Markdown: as a paragraph that renders line by line)."""
    lines = machine_lines()
    if markdown:
        print("  \n".join(lines))
    else:
        print("\n".join(lines))
    print(flush=True)
