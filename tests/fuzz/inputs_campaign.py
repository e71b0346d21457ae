"""A fuzz campaign on linkages with several inputs, through the CLI (one child process per run).

Seeded mutations of the shipped several-input examples (fivebar_5r, pick_fivebar, three_rrr,
forbal2) and random valid five-bars with random motions, run through ``analyze``,
``optimize``, ``pareto``, ``plot --cycle`` and the refusing verbs. Each run is classified by
its exit code, its stderr (one ``balancer: error:`` line on failure, ``balancer: note:`` lines
allowed) and whether an output file is left behind by a failing run.

    python -m tests.fuzz.inputs_campaign --runs 400 --seed 0 --log /tmp/inputs.jsonl
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from collections import Counter
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ["fivebar_5r", "pick_fivebar", "three_rrr", "forbal2"]
OUTPUTS = ("out.csv", "out.toml", "cycle.png", "front.csv")


# --- TOML writing (enough for specs) -------------------------------------------------------


def _key(k: str) -> str:
    ok = k and all(c.isascii() and (c.isalnum() or c in "-_") for c in k)
    return k if ok else json.dumps(k)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v) or math.isinf(v):
            return "1e308"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(type(v))


def dumps(d: dict[str, Any], prefix: str = "") -> str:
    lines: list[str] = []
    tables: list[tuple[str, Any]] = []
    for k, v in d.items():
        inline = prefix.endswith("!") or prefix.count(".") >= 2 or k in ("com", "counterweight")
        if isinstance(v, dict) and not inline:
            tables.append((k, v))
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v) and not prefix:
            tables.append((k, v))
        else:
            lines.append(f"{_key(k)} = {_value(v)}")
    out = "\n".join(lines) + ("\n" if lines else "")
    for k, v in tables:
        name = (prefix + "." if prefix else "") + _key(k)
        if isinstance(v, list):
            for item in v:
                out += f"\n[[{name}]]\n" + dumps(item, name + "!")
        else:
            out += f"\n[{name}]\n" + dumps(v, name)
    return out


# --- mutations ------------------------------------------------------------------------------


def _leaves(d: Any, path: tuple = ()) -> list[tuple]:
    out = []
    if isinstance(d, dict):
        for k, v in d.items():
            out.append(path + (k,))
            out += _leaves(v, path + (k,))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            if isinstance(v, (dict, list)):
                out += _leaves(v, path + (i,))
    return out


def _get(d, path):
    for p in path:
        d = d[p]
    return d


def _set(d, path, v):
    _get(d, path[:-1])[path[-1]] = v


HOSTILE = [0, -1, 1e300, -1e300, 1e-300, 5e-324, 2**63, -(2**63), "x", "", True, [], [[]],
           {}, [1.0], [1.0, 2.0, 3.0], "NaN", "inf", 1e6, -0.0]


def m_drop(r, d):
    path = r.choice(_leaves(d))
    del _get(d, path[:-1])[path[-1]]
    return f"drop {'.'.join(map(str, path))}"


def m_retype(r, d):
    path = r.choice(_leaves(d))
    v = copy.deepcopy(r.choice(HOSTILE))
    _set(d, path, v)
    return f"set {'.'.join(map(str, path))} = {v!r}"


def m_scale_number(r, d):
    nums = [p for p in _leaves(d) if isinstance(_get(d, p), (int, float))
            and not isinstance(_get(d, p), bool)]
    if not nums:
        return m_retype(r, d)
    path = r.choice(nums)
    f = r.choice([0.0, -1.0, 1e-12, 1e12, 1e200, -3.0, 1e-200])
    _set(d, path, _get(d, path) * f)
    return f"scale {'.'.join(map(str, path))} by {f}"


def _links(d):
    return [k for k in d.get("links", {}) if k != "ground"]


def _nongrounded(d):
    ground = set(d["links"]["ground"]["points"])
    return [k for k in _links(d) if not set(d["links"][k]["points"]) & ground]


def m_inputs(r, d):
    ins = list(d["mechanism"]["inputs"])
    links = _links(d)
    choice = r.randrange(11)
    if choice == 0:
        ins[0] = "ground"
    elif choice == 1:
        ins[-1] = ins[0]
    elif choice == 2 and _nongrounded(d):
        ins[-1] = r.choice(_nongrounded(d))
    elif choice == 3:
        ins = []
    elif choice == 4:
        ins = ins[:-1]
    elif choice == 5:
        ins = ins + [r.choice([x for x in links if x not in ins] or links)]
    elif choice == 6:
        ins[0] = "nosuchlink"
    elif choice == 7:
        d["mechanism"]["input"] = ins[0]
    elif choice == 8:
        del d["mechanism"]["inputs"]
        d["mechanism"]["input"] = ins[0]
    elif choice == 9:
        ins = ins[:1]
    else:
        ins = "".join(ins)
    d["mechanism"]["inputs"] = ins
    return f"inputs -> {ins!r} (case {choice})"


def m_workspace(r, d):
    ws = d.setdefault("workspace", {})
    ins = list(d["mechanism"]["inputs"])
    choice = r.randrange(14)
    pts = d["mechanism"]["points"]
    counts = Counter(p for link in d["links"].values() for p in link["points"])
    if choice == 0:
        ws[r.choice(_links(d) + ["nosuch"])] = [-0.1, 0.1]
    elif choice == 1:
        ws.pop(r.choice(ins), None)
    elif choice == 2:
        ws[r.choice(ins)] = [0.3, -0.3]
    elif choice == 3:
        ws[r.choice(ins)] = [0.0, 0.0]
    elif choice == 4:
        ws["samples"] = r.choice([0, -1, 1, 2, 10**6, 2.5, "9", 300])
    elif choice == 5:
        ws[r.choice(ins)] = r.choice([[-100.0, 100.0], [-1e300, 1e300], [-7.0, 7.0]])
    elif choice == 6:
        ones = [p for p in pts if counts[p] == 1]
        ws["joints"] = {r.choice(ones or list(pts)): [-0.5, 0.5]}
    elif choice == 7:
        many = [p for p in pts if counts[p] >= 3]
        ws["joints"] = {r.choice(many or list(pts)): [-0.5, 0.5]}
    elif choice == 8:
        ws["joints"] = {"nosuch": [-0.5, 0.5]}
    elif choice == 9:
        ws["joints"] = {r.choice(list(pts)): r.choice([[0.5, -0.5], [0.0, 0.0], [1.0], "x"])}
    elif choice == 10:
        del d["workspace"]
    elif choice == 11:
        ws[r.choice(ins)] = r.choice([[], [1.0, 2.0, 3.0], 0.5, ["a", "b"]])
    elif choice == 12:
        ws["joints"] = {ground_pt: [-0.5, 0.5] for ground_pt in d["links"]["ground"]["points"][:1]}
    else:
        ws["joints"] = [1, 2]
    return f"workspace case {choice}: {d.get('workspace')!r}"[:200]


def m_motion(r, d):
    motions = d.setdefault("motion", [])
    if not motions:
        return "no motion"
    m = r.choice(motions)
    choice = r.randrange(24)
    times = m.get("times", [0.0, 1.0])
    dur = times[-1] - times[0] if times and isinstance(times[-1], (int, float)) else 1.0
    if choice == 0:
        m["point"] = "nosuch"
    elif choice == 1:  # a point path for all inputs (three for the 3-RRR)
        m["point"] = r.choice(list(d["mechanism"]["points"]))
        m["path"] = [[0.0, 0.0] for _ in times]
    elif choice == 2:  # out of reach
        m["path"] = [[x * 10 if isinstance(x, float) else x for x in row] for row in m["path"]]
        m["path"][len(m["path"]) // 2] = [9.0] * len(m["path"][0])
    elif choice == 3:
        m["law"] = "spline"
        m["path"][-1] = [x + 0.01 for x in m["path"][-1]]
    elif choice == 4:
        m["law"] = "trapezoid"
        m["acc_time"] = dur / 2
    elif choice == 5:
        m["law"] = "trapezoid"
        m["acc_time"] = r.choice([dur * 0.75, dur, 0.0, -0.1, 1e300])
    elif choice == 6:
        m["times"] = list(reversed(times))
    elif choice == 7:
        t = list(times)
        if len(t) > 2:
            t[1] = t[0]
        else:
            t[1] = t[0]
        m["times"] = t
    elif choice == 8:
        m["path"][0] = m["path"][0] + [0.0]
    elif choice == 9:
        m["path"] = []
        m["times"] = []
    elif choice == 10:
        m["samples"] = r.choice([8, 1, 2, 0, -5, 10**6, 3, 2.5, "200"])
    elif choice == 11:
        motions.append(copy.deepcopy(m))
    elif choice == 12:
        m["law"] = r.choice(["linear", "", "Quintic", 3])
    elif choice == 13:
        m["times"] = times[:-1]
    elif choice == 14:
        m.pop(r.choice(["name", "times", "path", "law", "samples", "point"]), None)
    elif choice == 15:
        m["name"] = r.choice(["", " ", "a b", "é", "--json", "x" * 300])
    elif choice == 16:  # a point on the ground / input link
        m["point"] = r.choice(d["links"]["ground"]["points"] + d["links"][
            d["mechanism"]["inputs"][0]]["points"])
    elif choice == 17:
        d["motion"] = []
    elif choice == 18:
        d["motion"] = {"name": "x"}
    elif choice == 19:
        m["times"] = [t * r.choice([1e-9, 1e9, 1e-300]) for t in times]
    elif choice == 20:
        m["law"] = r.choice(["cubic", "quintic", "spline", "trapezoid"])
        m.pop("acc_time", None)
    elif choice == 21:
        m["file"] = "motion.csv"
    elif choice == 22:
        m["times"] = [float(i) for i in range(len(times))]
        m["path"] = [[0.0] * len(m["path"][0]) for _ in times]
        m.pop("point", None)
    else:
        m["times"] = [times[0], times[0]]
        m["path"] = m["path"][:2]
    return f"motion {m.get('name')!r} case {choice}"


def m_mobility(r, d):
    choice = r.randrange(4)
    links = _links(d)
    if choice == 0:
        victim = r.choice([x for x in links if x not in d["mechanism"]["inputs"]] or links)
        del d["links"][victim]
        d.get("balance", {}).pop(victim, None)
        return f"drop link {victim}"
    if choice == 1:  # a link joining two points adds a constraint
        pts = list(d["mechanism"]["points"])
        a, b = r.sample(pts, 2)
        d["links"]["extra"] = {"points": [a, b], "mass": 0.1, "inertia": 0.001,
                               "com": {"e": 0.01, "f": 0.0}}
        return f"extra link {a}-{b}"
    if choice == 2:
        d["links"]["ground"]["points"] = []
        return "ground empty"
    d["links"]["ground"]["points"] = list(d["mechanism"]["points"])[:2]
    return "ground two first points"


def m_fold(r, d):
    """A folded (singular) parallelogram at the reference pose."""
    d2 = tomllib.loads((ROOT / "examples/pick_fivebar.toml").read_text())
    d.clear()
    d.update(d2)
    d["mechanism"]["points"] = {"A": [0.0, 0.0], "P1": [0.2, 0.0], "P2": [0.15, 0.0],
                                "Q": [0.35, 0.0], "E": [0.43, 0.0]}
    d["motion"][0]["path"] = [[0.43, 0.0], [0.42, 0.01], [0.43, 0.0]]
    return "folded parallelogram"


def m_link_points(r, d):
    link = r.choice(_links(d))
    choice = r.randrange(4)
    pts = d["links"][link]["points"]
    if choice == 0:
        pts.append("nosuch")
    elif choice == 1:
        pts.append(pts[0])
    elif choice == 2:
        d["links"][link]["points"] = pts[:1]
    else:
        d["mechanism"]["points"][pts[-1]] = list(d["mechanism"]["points"][pts[0]])
    return f"link {link} points case {choice}"


MUTATIONS = [m_drop, m_retype, m_scale_number, m_inputs, m_inputs, m_workspace, m_workspace,
             m_motion, m_motion, m_motion, m_motion, m_mobility, m_fold, m_link_points]


# --- random valid five-bars ---------------------------------------------------------------


def random_fivebar(r: random.Random) -> dict[str, Any]:
    """A general 5R five-bar in a random assembled pose with random motions of E."""
    for _ in range(1000):
        A = (0.0, 0.0)
        B = (r.uniform(0.02, 0.3), r.uniform(-0.05, 0.05))
        a1, a2 = r.uniform(0.3, 2.8), r.uniform(0.3, 2.8)
        l1, l2 = r.uniform(0.05, 0.3), r.uniform(0.05, 0.3)
        C = (A[0] + l1 * math.cos(a1), A[1] + l1 * math.sin(a1))
        D = (B[0] + l2 * math.cos(a2), B[1] + l2 * math.sin(a2))
        E = ((C[0] + D[0]) / 2 + r.uniform(-0.1, 0.1), max(C[1], D[1]) + r.uniform(0.03, 0.3))
        # angle at E between EC and ED away from singular
        v1 = (C[0] - E[0], C[1] - E[1])
        v2 = (D[0] - E[0], D[1] - E[1])
        cross = v1[0] * v2[1] - v1[1] * v2[0]
        if abs(cross) / (math.hypot(*v1) * math.hypot(*v2)) > 0.3:
            break

    def link(p, q):
        return {"points": [p, q], "mass": round(r.uniform(0.05, 1.0), 4),
                "inertia": round(r.uniform(1e-4, 5e-3), 6),
                "com": {"e": round(r.uniform(-0.05, 0.15), 4),
                        "f": round(r.uniform(-0.02, 0.02), 4)}}

    d: dict[str, Any] = {
        "title": "random five-bar",
        "mechanism": {"type": "linkage", "inputs": ["left", "right"],
                      "points": {"A": list(A), "B": list(B), "C": list(C), "D": list(D),
                                 "E": list(E)}},
        "links": {"ground": {"points": ["A", "B"]}, "left": link("A", "C"),
                  "right": link("B", "D"), "ul": link("C", "E"), "ur": link("D", "E")},
        "balance": {"force_balance": True,
                    "objective": {"shaking_moment": 1.0, "driving_torque": 0.0,
                                  "shaking_force": 0.0, "added_mass": 0.01}},
        "workspace": {"left": [-r.uniform(0.05, 0.5), r.uniform(0.05, 0.5)],
                      "right": [-r.uniform(0.05, 0.5), r.uniform(0.05, 0.5)],
                      "samples": r.choice([5, 9, 15])},
        "motion": [],
    }
    for name in ("left", "right", "ul", "ur"):
        d["balance"][name] = {"counterweight": {"mass": [0.0, 2.0], "radius": 0.1,
                                                "gyration": 0.0}}
    for i in range(r.randint(1, 3)):
        law = r.choice(["trapezoid", "cubic", "quintic", "spline"])
        n = r.randint(2, 6)
        T = r.uniform(0.2, 3.0)
        times = [T * k / (n - 1) for k in range(n)]
        if r.random() < 0.5:
            amp = r.uniform(0.001, 0.03)
            path = [list(E)] + [[E[0] + r.uniform(-amp, amp), E[1] + r.uniform(-amp, amp)]
                                for _ in range(n - 2)] + [list(E)]
            m = {"name": f"m{i}", "point": "E", "times": times, "path": path}
        else:
            path = [[0.0, 0.0]] + [[r.uniform(-0.1, 0.1), r.uniform(-0.1, 0.1)]
                                   for _ in range(n - 2)] + [[0.0, 0.0]]
            m = {"name": f"m{i}", "times": times, "path": path}
        m["law"] = law
        if law == "trapezoid":
            m["acc_time"] = T * r.uniform(0.05, 0.45)
        m["samples"] = r.choice([20, 50, 100])
        d["motion"].append(m)
    return d


# --- command lines --------------------------------------------------------------------------


def command(r: random.Random, d: dict[str, Any]) -> list[str]:
    names = [m.get("name") for m in d.get("motion", []) if isinstance(m, dict)]
    names = [n for n in names if isinstance(n, str)] or ["nosuch"]
    verb = r.choice(["analyze"] * 5 + ["optimize"] * 3 + ["pareto", "plot", "plot",
                     "simulate", "verify", "sweep"])
    argv = [verb, "spec.toml"]
    if verb == "analyze":
        if r.random() < 0.5:
            argv += ["--motion", r.choice(names + ["nosuch"])]
        if r.random() < 0.5:
            argv += ["--csv", "out.csv"]
        if r.random() < 0.3:
            argv += ["--json"]
        if r.random() < 0.3:
            argv += ["--gravity", r.choice(["0,-9.81", "0,0", "1e300,0", "x", "1,2,3", "-9.81"])]
    elif verb == "optimize":
        argv += ["--no-verify"] if r.random() < 0.8 else []
        if r.random() < 0.6:
            argv += ["--out", "out.toml"]
        if r.random() < 0.3:
            argv += ["--json"]
        if r.random() < 0.3:
            argv += ["--backend", "convex"]
    elif verb == "pareto":
        argv += ["--against", r.choice(["added-mass", "driving-torque"]),
                 "--points", r.choice(["3", "2", "1", "0"])]
        if r.random() < 0.5:
            argv += ["--csv", "front.csv"]
    elif verb == "plot":
        argv += ["--cycle", "cycle.png"]
        if r.random() < 0.7:
            argv += ["--motion", r.choice(names + ["nosuch"])]
    elif verb == "simulate":
        argv += ["--out", "out.csv"]
    elif verb == "verify":
        pass
    else:
        argv += ["--vary", "links.left.mass=0.1:0.2:2", "--out", "out.parquet"]
    return argv


def make(seed: int) -> tuple[str, list[str], list[str]]:
    r = random.Random(seed)
    notes: list[str] = []
    if r.random() < 0.2:
        d = random_fivebar(r)
        notes.append("random five-bar")
        if r.random() < 0.3:
            notes.append(r.choice(MUTATIONS)(r, d))
    else:
        ex = r.choice(EXAMPLES)
        d = tomllib.loads((ROOT / "examples" / f"{ex}.toml").read_text())
        notes.append(ex)
        # keep the runs short
        for m in d.get("motion", []):
            m["samples"] = min(m.get("samples", 100), 60)
        if "workspace" in d:
            d["workspace"]["samples"] = min(d["workspace"].get("samples", 9), 11)
        for _ in range(r.choice([1, 1, 1, 2])):
            try:
                notes.append(r.choice(MUTATIONS)(r, d))
            except (KeyError, IndexError, TypeError, ValueError, AttributeError) as exc:
                notes.append(f"(mutation skipped: {exc!r})")
    return dumps(d), command(r, d), notes


def classify(rc: int | None, stdout: str, stderr: str, leftovers: list[str]) -> list[str]:
    defects = []
    if rc is None:
        return ["timeout"]
    if "Traceback" in stderr:
        defects.append("traceback")
    if "internal error" in stderr:
        defects.append("internal error")
    if rc not in (0, 1, 2):
        defects.append(f"exit code {rc}")
    lines = [ln for ln in stderr.splitlines() if ln.strip()]
    if rc != 0:
        errors = [ln for ln in lines if ln.startswith("balancer: error:")]
        others = [ln for ln in lines if not ln.startswith(("balancer: error:", "balancer: note:"))]
        if len(errors) != 1 or others:
            defects.append("stderr not one error line")
        if leftovers:
            defects.append("partial output after failure")
    else:
        quiet = ("balancer: note:", "balancer: warning:", "wrote ")
        others = [ln for ln in lines if not ln.startswith(quiet)]
        if others:
            defects.append("stray stderr on success")  # ("wrote F" lines are the design's)
    return defects


def run_one(seed: int, timeout: float) -> dict[str, Any]:
    spec, argv, notes = make(seed)
    folder = Path(tempfile.mkdtemp(prefix="bal-inputs-"))
    try:
        (folder / "spec.toml").write_text(spec)
        (folder / "motion.csv").write_text("t,a,b\n0,0,0\n1,0.1,0.1\n")
        env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
        start = time.perf_counter()
        try:
            p = subprocess.run([sys.executable, "-m", "balancer", *argv], cwd=folder, env=env,
                               capture_output=True, text=True, timeout=timeout)
            rc, out, err = p.returncode, p.stdout, p.stderr
        except subprocess.TimeoutExpired:
            rc, out, err = None, "", ""
        secs = time.perf_counter() - start
        leftovers = [f for f in os.listdir(folder) if f not in ("spec.toml", "motion.csv")]
        defects = classify(rc, out, err, leftovers)
        return {"seed": seed, "argv": argv, "notes": notes, "rc": rc, "seconds": round(secs, 2),
                "stderr": err[-3000:], "leftovers": leftovers, "defects": defects,
                "spec": spec if defects or rc else ""}
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=100)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=90.0)
    ap.add_argument("--log", default="/tmp/inputs_campaign.jsonl")
    a = ap.parse_args()
    with open(a.log, "a") as log:
        for seed in range(a.seed, a.seed + a.runs):
            res = run_one(seed, a.timeout)
            log.write(json.dumps(res) + "\n")
            log.flush()
            tag = ",".join(res["defects"]) or "ok"
            last = res["stderr"].strip().splitlines()[-1:] or [""]
            print(f"{seed} rc={res['rc']} {res['seconds']}s {tag} {' '.join(res['argv'][:1])} "
                  f"{res['notes']} | {last[0][:160]}", flush=True)


if __name__ == "__main__":
    main()
