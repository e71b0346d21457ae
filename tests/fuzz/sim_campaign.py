"""Fuzz campaign: simulate / verify / optimize along motions of several-input linkages.

Hostile but plausible mutations of the several-input examples (and a crank and slide):
paths near singular poses or out of the workspace, tiny and huge durations, samples, masses
and gravity, springs, loads and counter-rotors, malformed motion files, force balance along
tiny motions, extreme tolerances; each case run through the command line in a subprocess and
judged by the project's rules (exit 2 naming a key for bad input, 1 for a failure said in a
line, no internal error, nothing partial, no NaN in a table). What it found in its first 586
cases is fixed and kept as tests (tests/simulation/test_motions.py).

    python -m tests.fuzz.sim_campaign --runs 300 --seed 0 --log /tmp/sim.jsonl
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

from tests.fuzz.inputs_campaign import dumps
from tests.linkage import several_inputs_specs

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ["fivebar_5r", "pick_fivebar", "three_rrr", "forbal2", "crank_slider"]


def crank_slider() -> dict:
    """The crank and slide of the several-input tests, with a balance, workspace and motion."""
    return several_inputs_specs.crank_slider() | {
        "title": "crank and slide",
        "balance": {"force_balance": True, "objective": {"shaking_moment": 1.0,
                                                         "added_mass": 0.01},
                    "crank": {"counterweight": {"mass": [0.0, 2.0], "radius": 0.1}},
                    "upper": {"counterweight": {"mass": [0.0, 2.0], "radius": 0.1}},
                    "lower": {"counterweight": {"mass": [0.0, 2.0], "radius": 0.1}}},
        "workspace": {"crank": [-0.3, 0.3], "block": [-0.05, 0.05], "samples": 9},
        "motion": [{"name": "stroke", "times": [0.0, 0.5, 1.0],
                    "path": [[0.0, 0.0], [0.2, 0.03], [0.0, 0.0]], "law": "quintic",
                    "samples": 100}],
    }


def base(name: str) -> dict:
    if name == "crank_slider":
        return crank_slider()
    return tomllib.loads((ROOT / "balancer/examples" / f"{name}.toml").read_text())


def _links(d):
    return [k for k in d["links"] if k != "ground"]


def _grounded(d):
    g = set(d["links"]["ground"]["points"])
    return [k for k in _links(d) if set(d["links"][k].get("points", [])) & g]


MUTATED: list[str] = []


def _motion(r, d):
    ms = d.get("motion") or []
    m = r.choice(ms) if ms else None
    if m is not None:
        MUTATED.append(m["name"])
    return m


# --- mutations ------------------------------------------------------------------------------


def m_scale_path(r, d, folder):
    m = _motion(r, d)
    k = r.choice([1.5, 2.0, 3.0, 5.0, 10.0, 30.0, r.uniform(1.0, 6.0), r.uniform(1.0, 3.0)])
    p0 = m["path"][0]
    m["path"] = [[a + k * (x - a) for x, a in zip(row, p0, strict=True)] for row in m["path"]]
    return f"scale path of {m['name']} about its start by {k:.4g}"


def m_shift_path(r, d, folder):
    m = _motion(r, d)
    dx = [r.choice([0.05, 0.1, 0.2, 0.5, -0.1, -0.3, 1.0, 3.0]) for _ in m["path"][0]]
    i = r.randrange(len(m["path"]))
    m["path"][i] = [x + y for x, y in zip(m["path"][i], dx, strict=True)]
    return f"shift waypoint {i} of {m['name']} by {dx}"


def m_singular(r, d, folder):
    """Drive a point motion towards a singular pose (the reach limit) or an input path to a
    large angle."""
    m = _motion(r, d)
    pts = d["mechanism"]["points"]
    if m.get("point"):
        e = pts[m["point"]]
        # far along the direction away from the ground origin: stretch towards full reach
        g = pts[d["links"]["ground"]["points"][0]]
        v = [e[0] - g[0], e[1] - g[1]]
        f = r.choice([1.2, 1.35, 1.5, 1.6, 1.7, 1.8, 2.0, r.uniform(1.1, 2.0)])
        tgt = [g[0] + v[0] * f, g[1] + v[1] * f]
        m["path"][len(m["path"]) // 2] = tgt
        return f"singular: {m['name']} mid waypoint {tgt} (reach x{f:.3g})"
    ang = r.choice([1.0, 1.5, 2.0, 3.0, math.pi, 6.0])
    m["path"][len(m["path"]) // 2] = [ang * r.choice([1, -1, 0.5]) for _ in m["path"][0]]
    return f"singular: {m['name']} mid waypoint inputs ~{ang}"


def m_times(r, d, folder):
    m = _motion(r, d)
    f = r.choice([1e-9, 1e-6, 1e-3, 0.01, 100.0, 1e4, 1e6, 1e9])
    m["times"] = [t * f for t in m["times"]]
    if "acc_time" in m:
        m["acc_time"] *= f
    return f"times of {m['name']} x{f}"


def m_samples(r, d, folder):
    m = _motion(r, d)
    m["samples"] = r.choice([8, 9, 10, 13, 20000, 100000])
    return f"samples of {m['name']} = {m['samples']}"


def m_mass(r, d, folder):
    link = r.choice(_links(d))
    what = r.choice(["mass", "inertia", "both", "com"])
    f = r.choice([0.0, 1e-12, 1e-6, 1e6, 1e12])
    L = d["links"][link]
    if what in ("mass", "both"):
        L["mass"] = L["mass"] * f if f else 1e-300
    if what in ("inertia", "both"):
        L["inertia"] = L["inertia"] * f
    if what == "com":
        L["com"] = {"e": r.choice([1e3, -1e3, 1e-9, 0.0]), "f": r.choice([0.0, 1e3, 1e-9])}
    return f"{what} of {link} x{f}"


def m_all_light(r, d, folder):
    f = r.choice([1e-9, 1e-15, 1e9])
    for k in _links(d):
        d["links"][k]["mass"] *= f
        d["links"][k]["inertia"] *= f
    return f"every link's mass and inertia x{f}"


def m_gravity(r, d, folder):
    g = r.choice([[0.0, -9.81], [0.0, -1e6], [9.81, 0.0], [0.0, 1e-12], [1e12, 1e12]])
    where = "operation"  # ([simulation] of any kind: an internal error, reported)
    if where in ("simulation", "both"):
        d.setdefault("simulation", {})["gravity"] = g
    if where in ("operation", "both"):
        d.setdefault("operation", {})["speed"] = 1.0
        d["operation"]["gravity"] = g
    return f"gravity {g} in {where}"


def m_spring(r, d, folder):
    pts = list(d["mechanism"]["points"])
    a, b = r.sample(pts, 2)
    k = r.choice([1.0, 100.0, 1e4, 1e5, 0.0])
    pa, pb = d["mechanism"]["points"][a], d["mechanism"]["points"][b]
    L = math.hypot(pa[0] - pb[0], pa[1] - pb[1])
    fl = r.choice([0.0, L, L * 0.5, L * 2, 100.0])
    d.setdefault("springs", []).append({"points": [a, b], "stiffness": k, "free_length": fl})
    return f"spring {a}-{b} k={k} free={fl:.4g}"


def m_loads(r, d, folder):
    link = r.choice(_links(d))
    F = r.choice([[1.0, -2.0], [0.0, -1e6], [1e9, 0.0], [1e-9, 0.0]])
    d["links"][link]["force"] = F
    if r.random() < 0.5:
        d["links"][link]["moment"] = r.choice([0.5, -100.0, 1e8])
    return f"loads on {link}: force {F} moment {d['links'][link].get('moment')}"


def m_counter_rotor(r, d, folder):
    gl = _grounded(d)
    if not gl:
        return "no grounded link"
    link = r.choice(gl)
    d["links"][link]["counter_rotor"] = r.choice([0.001, 1.0, 1e6])
    return f"counter_rotor on {link}"


CSV_VARIANTS = [
    "valid", "valid_long", "reorder", "missing_col", "extra_col", "text", "empty",
    "header_only", "one_row", "dup_time", "nan", "inf", "bom", "crlf", "spaces", "semicolon",
    "huge_values", "blank_lines", "quoted", "latin1", "huge_field", "negative_time",
    "trailing_comma", "tiny_dt", "two_rows", "big_step", "directory", "missing_file", "nul",
    "exp_notation", "unterminated_quote",
]


def m_csv(r, d, folder):
    m = _motion(r, d)
    ins = list(d["mechanism"]["inputs"])
    variant = r.choice(CSV_VARIANTS)
    head = "t," + ",".join(ins)
    n = len(ins)

    def rows(k, amp=0.05, T=1.0):
        out = []
        for i in range(k):
            t = T * i / (k - 1)
            out.append([t] + [amp * math.sin(math.pi * t / T) * (j + 1) / n for j in range(n)])
        return out

    def fmt(rs):
        return "\n".join(",".join(repr(x) for x in row) for row in rs) + "\n"

    body = fmt(rows(5))
    name = "motion.csv"
    text: str | bytes
    if variant == "valid":
        text = head + "\n" + body
    elif variant == "valid_long":
        text = head + "\n" + fmt(rows(r.choice([200, 5000]), amp=0.1, T=2.0))
    elif variant == "reorder":
        text = "t," + ",".join(reversed(ins)) + "\n" + body
    elif variant == "missing_col":
        text = "t," + ",".join(ins[:-1]) + "\n" + body
    elif variant == "extra_col":
        text = head + ",extra\n" + "\n".join(line + ",0" for line in body.splitlines()) + "\n"
    elif variant == "text":
        text = head + "\n" + body.replace("0.0", "zero", 1)
    elif variant == "empty":
        text = ""
    elif variant == "header_only":
        text = head + "\n"
    elif variant == "one_row":
        text = head + "\n" + "0.0" + ",0.0" * n + "\n"
    elif variant == "two_rows":
        text = head + "\n" + "0.0" + ",0.0" * n + "\n1.0" + ",0.01" * n + "\n"
    elif variant == "dup_time":
        text = head + "\n" + body + body.splitlines()[-1] + "\n"
    elif variant == "nan":
        text = head + "\n" + body + "2.0" + ",nan" * n + "\n"
    elif variant == "inf":
        text = head + "\n" + body + "2.0" + ",inf" * n + "\n"
    elif variant == "bom":
        text = "\ufeff" + head + "\n" + body
    elif variant == "crlf":
        text = (head + "\n" + body).replace("\n", "\r\n")
    elif variant == "spaces":
        text = " t , " + " , ".join(ins) + "\n" + body.replace(",", " , ")
    elif variant == "semicolon":
        text = (head + "\n" + body).replace(",", ";")
    elif variant == "huge_values":
        text = head + "\n" + fmt([[row[0]] + [x * 1e6 for x in row[1:]] for row in rows(5)])
    elif variant == "blank_lines":
        text = "\n\n" + head + "\n\n" + body.replace("\n", "\n\n")
    elif variant == "quoted":
        text = '"t",' + ",".join(f'"{i}"' for i in ins) + "\n" + body
    elif variant == "latin1":
        text = (head + "\n# comment é\n" + body).encode("latin-1")
    elif variant == "huge_field":
        text = head + "\n" + body + "9.0," + "1" * 200000 + ",0" * (n - 1) + "\n"
    elif variant == "negative_time":
        text = head + "\n" + fmt([[row[0] - 5.0] + row[1:] for row in rows(5)])
    elif variant == "trailing_comma":
        text = head + ",\n" + "\n".join(line + "," for line in body.splitlines()) + "\n"
    elif variant == "tiny_dt":
        text = head + "\n" + fmt([[row[0] * 1e-12] + row[1:] for row in rows(5)])
    elif variant == "big_step":
        rs = rows(5)
        rs[2] = [rs[2][0]] + [3.0] * n
        text = head + "\n" + fmt(rs)
    elif variant == "directory":
        (folder / "motdir").mkdir()
        name = "motdir"
        text = None
    elif variant == "missing_file":
        name = "nosuch.csv"
        text = None
    elif variant == "nul":
        text = head + "\n" + body + "\x00\n"
    elif variant == "exp_notation":
        text = head + "\n" + body.replace("1.0", "1e0")
    else:
        text = head + "\n" + body + '"3.0,0.1' + ",0.1" * (n - 1) + "\n"
    if text is not None:
        (folder / name).write_bytes(text if isinstance(text, bytes) else text.encode())
    for k in ("times", "path", "point", "acc_time"):
        m.pop(k, None)
    m["file"] = name
    if r.random() < 0.4:
        m["law"] = r.choice(["spline", "cubic", "quintic", "trapezoid"])
        if m["law"] == "trapezoid":
            m["acc_time"] = 0.2
    else:
        m.pop("law", None)
    return f"csv {variant} for {m['name']} law {m.get('law')}"


def m_force_motion(r, d, folder):
    d.setdefault("balance", {})["force"] = "motion"
    d["balance"]["force_balance"] = True
    amp = r.choice([0.0, 1e-15, 1e-12, 1e-9, 1e-6, 1e-3, None])
    if amp is not None:
        for m in d.get("motion", []):
            p0 = m["path"][0]
            m["path"] = [[a + amp * (x - a) / (abs(x - a) or 1.0) if x != a else a
                          for x, a in zip(row, p0, strict=True)] for row in m["path"]]
    return f"force = motion, motion amplitude {amp}"


def m_slide_stroke(r, d, folder):
    if "block" not in d["mechanism"]["inputs"]:
        return m_scale_path(r, d, folder)
    m = d["motion"][0]
    s = r.choice([0.1, 0.2, 0.3, 0.5, 1.0, 10.0, -0.3, -1.0])
    c = r.choice([0.0, 0.2, 1.0, 3.0])
    m["path"] = [[0.0, 0.0], [c, s], [0.0, 0.0]]
    if r.random() < 0.3:
        d["workspace"]["block"] = [-abs(s), abs(s)]
    return f"slide stroke {s} crank {c}"


def m_simulation_table(r, d, folder):
    sim = d.setdefault("simulation", {})
    key = r.choice(["duration", "rtol", "atol", "outputs", "drive", "method"])
    sim[key] = {"duration": r.choice([1e-9, 1e-3, 100.0, 1e5]),
                "rtol": r.choice([1e-14, 1e-3, 0.5, 1e-20]),
                "atol": r.choice([0.0, 1e-20, 1.0, 1e6]),
                "outputs": r.choice([1, 2, 3, 100000]),
                "drive": r.choice(["free", "constant-speed", "motion"]),
                "method": r.choice(["multibody", "input-coordinates", "lie-group",
                                    "crank-angle"])}[key]
    return f"[simulation] {key} = {sim[key]!r}"


def m_torque_objective(r, d, folder):
    obj = d.setdefault("balance", {}).setdefault("objective", {})
    obj["torque"] = r.choice([1.0, 1e-12, 1e12, 0.0])
    if r.random() < 0.3:
        obj["driving_torque"] = 1.0
    if r.random() < 0.3:
        obj["shaking_moment"] = 0.0
    return f"objective {obj}"


def m_spline_open(r, d, folder):
    m = _motion(r, d)
    m["law"] = "spline"
    m.pop("acc_time", None)
    last = m["path"][-1]
    eps = r.choice([1e-12, 1e-9, 1e-6, 1e-3, 0.02])
    m["path"][-1] = [x + eps for x in last]
    return f"spline on an open path of {m['name']} (end off by {eps})"


def m_z(r, d, folder):
    link = r.choice(_links(d))
    d["links"][link]["z"] = r.choice([0.1, -0.5, 1e3])
    return f"z of {link}"


def m_motion_weights(r, d, folder):
    ms = [m["name"] for m in d.get("motion", [])]
    d.setdefault("balance", {})["motions"] = {n: r.choice([0.0, 1e-12, 1e12, 2.0]) for n in ms}
    return f"motion weights {d['balance']['motions']}"


def m_trapezoid(r, d, folder):
    m = _motion(r, d)
    dur = m["times"][-1] - m["times"][0]
    m["law"] = "trapezoid"
    m["acc_time"] = dur * r.choice([1e-9, 1e-4, 0.01, 0.5, 0.4999999])
    return f"trapezoid of {m['name']} acc {m['acc_time']:.3g}"


MUTATIONS = [m_scale_path, m_shift_path, m_singular, m_singular, m_times, m_samples, m_mass,
             m_all_light, m_gravity, m_spring, m_loads, m_counter_rotor, m_csv, m_csv,
             m_force_motion, m_force_motion, m_slide_stroke, m_slide_stroke,
             m_torque_objective, m_spline_open, m_z, m_motion_weights, m_trapezoid]


# --- command lines --------------------------------------------------------------------------


def hostile(r, which):
    if r.random() < 0.8:
        return {
            "duration": ["1e-12", "1e-6", "1e-3", "0.05", "2", "20", "200"],
            "rtol": ["1e-14", "1e-12", "1e-6", "1e-3", "0.1"],
            "atol": ["1e-300", "1e-20", "1e-12", "1e-3", "1", "1e6"],
            "outputs": ["2", "3", "7", "1001", "2001"],
        }[which]
    return {
        "duration": ["1e-12", "1e-6", "0", "-1", "0.001", "2", "50", "1e4", "nan", "inf", "x"],
        "rtol": ["0", "1e-16", "1e-20", "1e-3", "1", "10", "nan", "-1e-6"],
        "atol": ["0", "1e-30", "1e-3", "1e10", "inf", "-1"],
        "outputs": ["0", "1", "2", "3", "7", "100000", "-1", "2.5"],
    }[which]


def command(r, d):
    names = [m.get("name") for m in d.get("motion", [])] or ["nosuch"]
    if MUTATED and MUTATED[-1] in names and r.random() < 0.7:
        names = [MUTATED[-1]]
    verb = r.choice(["simulate"] * 6 + ["verify"] * 3 + ["optimize"] * 3)
    argv = [verb, "spec.toml"]
    if verb == "simulate":
        if r.random() < 0.6:
            argv += ["--drive", r.choice(["free", "motion", "free"])]
        if r.random() < 0.6:
            argv += ["--method", r.choice(["multibody", "input-coordinates"])]
        if r.random() < 0.7:
            argv += ["--motion", r.choice(names)]
        for opt in ("duration", "rtol", "atol", "outputs"):
            if r.random() < 0.25:
                argv += [f"--{opt}=" + r.choice(hostile(r, opt))]
        if r.random() < 0.5:
            argv += ["--out", "out.csv"]
        if r.random() < 0.3:
            argv += ["--json"]
    elif verb == "verify":
        if r.random() < 0.4:
            argv += ["--plot", r.choice(["fig.png", "fig.svg"])]
        if r.random() < 0.3:
            argv += ["--json"]
        if r.random() < 0.3:
            argv += ["--duration=" + r.choice(hostile(r, "duration"))]
        if r.random() < 0.3:
            argv += ["--method", r.choice(["multibody", "input-coordinates", "lie-group"])]
    else:
        if r.random() < 0.5:
            argv += ["--no-verify"]
        elif r.random() < 0.3:
            argv += ["--verify-duration=" + r.choice(hostile(r, "duration"))]
        if r.random() < 0.4:
            argv += ["--out", "out.toml"]
        if r.random() < 0.3:
            argv += ["--json"]
    return argv


def make(seed, folder):
    r = random.Random(seed)
    MUTATED.clear()
    ex = r.choice(EXAMPLES)
    d = base(ex)
    notes = [ex]
    for m in d.get("motion", []):
        m["samples"] = min(m.get("samples", 400), 120)
    if "workspace" in d:
        d["workspace"]["samples"] = min(d["workspace"].get("samples", 9), 11)
    for _ in range(r.choice([1, 1, 2, 2, 3])):
        mut = r.choice(MUTATIONS)
        try:
            notes.append(mut(r, d, folder))
        except (KeyError, IndexError, TypeError, ValueError, AttributeError) as exc:
            notes.append(f"(skipped {mut.__name__}: {exc!r})")
    return d, command(r, d), notes


NONSENSE = re.compile(r"(?<![A-Za-z_])(nan|inf|-inf|NaN|Infinity)(?![A-Za-z_])")


def classify(rc, out, err, folder, argv, secs):
    defects = []
    if rc is None:
        return ["timeout"]
    if secs > 30:
        defects.append("slow>30s")
    if "Traceback" in err:
        defects.append("traceback")
    if "internal error" in err:
        defects.append("internal error")
    if rc not in (0, 1, 2):
        defects.append(f"exit code {rc}")
    lines = [ln for ln in err.splitlines() if ln.strip()]
    outs = [a for a in ("out.csv", "out.toml", "fig.png", "fig.svg") if a in argv]
    present = [o for o in outs if (folder / o).exists()]
    if rc != 0:
        errors = [ln for ln in lines if ln.startswith("balancer: error:")]
        others = [ln for ln in lines if not ln.startswith(("balancer: error:", "balancer: note:",
                                                          "balancer: warning:"))]
        if len(errors) != 1 or others:
            defects.append("stderr not one error line")
        if present:
            defects.append("partial output after failure")
    else:
        quiet = ("balancer: note:", "balancer: warning:", "wrote ")
        if [ln for ln in lines if not ln.startswith(quiet)]:
            defects.append("stray stderr on success")
        if set(outs) - set(present):
            defects.append("output missing on success")
        if NONSENSE.search(out):
            defects.append("nan/inf in stdout")
        if "--json" in argv:
            try:
                json.loads(out, parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
            except ValueError as exc:
                defects.append(f"bad json: {str(exc)[:60]}")
        if "out.csv" in present:
            txt = (folder / "out.csv").read_text()
            if NONSENSE.search(txt):
                defects.append("nan/inf in csv")
    return defects


def run_one(seed, timeout, keep):
    folder = Path(tempfile.mkdtemp(prefix="bal-sim-"))
    try:
        d, argv, notes = make(seed, folder)
        spec = dumps(d)
        (folder / "spec.toml").write_text(spec)
        env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
        start = time.perf_counter()
        try:
            p = subprocess.run([sys.executable, "-m", "balancer", *argv], cwd=folder, env=env,
                               capture_output=True, text=True, timeout=timeout)
            rc, out, err = p.returncode, p.stdout, p.stderr
        except subprocess.TimeoutExpired:
            rc, out, err = None, "", ""
        secs = time.perf_counter() - start
        defects = classify(rc, out, err, folder, argv, secs)
        res = {"seed": seed, "argv": argv, "notes": notes, "rc": rc, "seconds": round(secs, 2),
               "stderr": err[-3000:], "stdout": out[-3000:] if defects else "",
               "defects": defects, "spec": spec}
        if defects and keep:
            dest = Path(keep) / f"case{seed}"
            shutil.copytree(folder, dest, dirs_exist_ok=True)
        return res
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=100)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--log", default="/tmp/sim_campaign.jsonl")
    ap.add_argument("--keep", default="/tmp/sim_cases")
    ap.add_argument("--budget", type=float, default=1e9, help="stop after this many seconds")
    a = ap.parse_args()
    Path(a.keep).mkdir(exist_ok=True)
    t0 = time.time()
    with open(a.log, "a") as log:
        for seed in range(a.seed, a.seed + a.runs):
            if time.time() - t0 > a.budget:
                break
            res = run_one(seed, a.timeout, a.keep)
            log.write(json.dumps(res) + "\n")
            log.flush()
            tag = ",".join(res["defects"]) or "ok"
            last = res["stderr"].strip().splitlines()[-1:] or [""]
            print(f"{seed} rc={res['rc']} {res['seconds']}s {tag} {' '.join(res['argv'])} "
                  f"{res['notes']} | {last[0][:200]}", flush=True)


if __name__ == "__main__":
    main()
