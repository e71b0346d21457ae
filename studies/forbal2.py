"""The Forbal-2 robot's force balance: the published design reproduced, then asked further.

Source: Y. Vyas, M. Bottin, *Forbal: Force Balanced 2-5 Degree of Freedom Robot Manipulator
Built from a Five Bar Linkage*, arXiv 2509.03119 (2025), with the data of the authors'
repository yjvyas/forbal as ``examples/forbal2.toml`` holds it: the parallelogram five-bar with
its steel counter rings merged into links 11, 21 and 22, its workspace (their joint limits) and
its three motions (diamond, circle, figure-eight), in a vertical plane.

What it reproduces and asks:

1. **The published design.** Its loads along the three motions (``balancer.analyze_motions``),
   without gravity and with gravity (0, −9.81) m/s²; the total centre of mass's excursion over
   the workspace and along each motion; the force-balance conditions' residual. Then what the
   rings buy: the same robot without them (each ring's mass, centre and inertia taken off its
   link exactly as the example's comments put them on) analysed alike. The paper reports that
   the counter masses cut the average reaction moments by up to 66 % and the joint torques by
   up to 79 % (measured on the real robot); the model's reductions are set beside those.
2. **The least added mass** that force-balances the bare robot for every motion
   (``balancer.optimize``: ``[balance] force_balance = true``, objective the added mass, one
   counterweight on each of links 11, 21 and 22 within the rings' reach), against the rings'
   0.443 kg; its closed form (the parallelogram's first moments along each independent
   direction, over the radius) beside it; the balanced design's centre of mass over the
   workspace.
3. **The trade-off front** (``balancer.pareto(..., against="added-mass")``): the least RMS
   shaking moment along the motions against the added mass, force balance imposed; the
   published design's point beside it (it is not exactly force-balanced, so not on it).

Run ``python studies/forbal2.py [--out DIR] [--quick]``; it writes its figures and
``forbal2.md`` into ``studies/out/forbal2/`` (or ``DIR``).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from balancer import (
    BalanceProblem,
    CounterweightFreedom,
    Design,
    LinkFreedom,
    Objective,
    analyze_motions,
    dumps_design,
    load_design,
    loads_design,
    motion_drawing,
    motion_figure,
    optimize,
    pareto,
)
from balancer.plots import COLOURS, SERIES, save_png
from balancer.report import markdown_table

NAME = "forbal2"
#: The report it writes into its output folder.
REPORT = "forbal2.md"
ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "examples" / "forbal2.toml"

#: The steel counter rings (forbal2.urdf.xacro's ringmass), kg, each at e = RING_AT on its link.
RINGS = {"link11": 0.02982881, "link21": 0.32560040, "link22": 0.08713178}
RING_AT = -0.2                          # m, along the link from its first point
RING_RADII = (0.0032, 0.02)             # m, inner and outer
#: A ring's radius of gyration about its axis, m: J = m·(r₁² + r₂²)/2 = m·ρ².
RING_GYRATION = math.sqrt((RING_RADII[0] ** 2 + RING_RADII[1] ** 2) / 2)
#: Every link between joints, m (the parallelogram's sides).
LENGTH = 0.2
#: The motors' axis O, m (the shaking moment is about the world origin; O's is the study's).
AXIS = complex(0.01616, 0.2275)
GRAVITY = (0.0, -9.81)                  # m/s²: their robot works in a vertical plane
#: The paper's reported reductions (Vyas & Bottin 2025, abstract), measured on the robot.
PAPER_MOMENT_CUT, PAPER_TORQUE_CUT = 0.66, 0.79

#: The counterweights the optimiser may add to the bare robot: one per ringed link, its centre
#: within the rings' reach (0.2 m of the link's first point, O for links 11 and 21, B for link
#: 22), up to 1 kg each (more than the whole bare robot's 0.877 kg: the least mass does not
#: reach the bound), its own radius of gyration at least a ring's (a ring-like body).
COUNTERWEIGHT = CounterweightFreedom(mass=(0.0, 1.0), radius=0.2, gyration=RING_GYRATION)

DESIGN_COLOURS = {"bare": COLOURS["before"], "published": SERIES[0],
                  "least mass": COLOURS["after"]}
LOADS = (("shaking_force", "shaking force", "N"), ("shaking_moment", "shaking moment", "N·m"),
         ("torque_link11", "torque on link 11", "N·m"),
         ("torque_link21", "torque on link 21", "N·m"))


# -- the study's own arithmetic: taking the rings off, rebuilding a design of the front -------


def without_ring(link, ring_mass: float):
    """A link with its ring (``ring_mass`` kg at ``(RING_AT, 0)``, ``J = m·ρ²``) taken off.

    The inverse of the example's combination: the link's mass less the ring's, its first
    moment less the ring's, its inertia about its frame's origin less the ring's.
    """
    ring_at = complex(RING_AT, 0.0)
    mass = link.mass - ring_mass
    first = link.mass * complex(link.e, link.f) - ring_mass * ring_at
    about_origin = (link.inertia + link.mass * (link.e**2 + link.f**2)
                    - ring_mass * (RING_GYRATION**2 + abs(ring_at) ** 2))
    centre = first / mass
    return replace(link, mass=mass, e=centre.real, f=centre.imag,
                   inertia=about_origin - mass * abs(centre) ** 2)


def bare_robot(published: Design) -> Design:
    """The published robot without its counter rings (link 22 keeps its end effector)."""
    mech = published.mechanism
    links = {name: without_ring(mech.link(name), m) for name, m in RINGS.items()}
    return replace(published, mechanism=mech.with_links(links),
                   title="Forbal-2 without its counter rings")


def balancing(bare: Design, objective: Objective, title: str,
              links: tuple[str, ...] = tuple(RINGS)) -> Design:
    """The bare robot with the counterweights' ``[balance]`` problem, written and read back.

    Force balance imposed (for every motion: over the whole workspace); one counterweight
    (:data:`COUNTERWEIGHT`) on each of ``links`` (default links 11, 21, 22: the ringed ones).
    """
    problem = BalanceProblem(force_balance=True, objective=objective,
                             links={name: LinkFreedom(counterweight=COUNTERWEIGHT)
                                    for name in links})
    design = replace(bare, balance=problem, title=title)
    return loads_design(dumps_design(design), source=title)


def design_of(base: Design, x: np.ndarray) -> Design:
    """The design of a front's point: its design vector ``x`` on ``base``'s linkage.

    ``x`` holds per link, in the spec's order, the mass (kg), its first moments in the link's
    frame (kg·m) and its inertia about the frame's origin (kg·m²), then the counter-rotors
    (:attr:`balancer.BalanceResult.x`); none here (the problem frees none).
    """
    mech = base.mechanism
    if np.any(x[4 * len(mech.link_names):] != 0):
        raise ValueError("the design has counter-rotors, which this rebuild leaves out")
    links = {}
    for k, name in enumerate(mech.link_names):
        m, me, mf, j = x[4 * k: 4 * k + 4]
        links[name] = replace(mech.link(name), mass=float(m), e=float(me / m),
                              f=float(mf / m), inertia=float(j - (me**2 + mf**2) / m))
    return replace(base, mechanism=mech.with_links(links), balance=None)


def first_moments(design: Design) -> tuple[complex, complex]:
    """The parallelogram's first moments ``K11, K21`` (kg·m, in links 11's and 21's frames).

    Links 22 ∥ 11 and 12 ∥ 21: link 11's direction carries links 11 and 22 and link 12's mass
    at link 11's end; link 21's carries links 21 and 12 and link 22's mass at link 21's end.
    The total centre of mass is ``O + (e^{iθ11}·K11 + e^{iθ21}·K21)/M``: it stands still for
    every motion exactly when both vanish.
    """
    mech = design.mechanism

    def s(name: str) -> complex:
        link = mech.link(name)
        return link.mass * complex(link.e, link.f)

    k11 = s("link11") + s("link22") + mech.link("link12").mass * LENGTH
    k21 = s("link21") + s("link12") + mech.link("link22").mass * LENGTH
    return k11, k21


def added_bodies(bare: Design, linkage) -> dict[str, tuple[float, float]]:
    """Per ringed link, the body a design adds to the bare link: its mass (kg) and its centre's
    distance from the link's first point (m; 0 where nothing is added)."""
    out = {}
    for name in RINGS:
        before, after = bare.mechanism.link(name), linkage.link(name)
        mass = after.mass - before.mass
        first = (after.mass * complex(after.e, after.f)
                 - before.mass * complex(before.e, before.f))
        out[name] = (mass, abs(first) / mass if mass > 1e-12 else 0.0)
    return out


def rms_along(along, key: str) -> float:
    """RMS of a load over the motions, each weighted equally (the balancing's measure)."""
    return float(np.sqrt(np.mean(along.load(key) ** 2)))


def moment_about_axis(motion) -> np.ndarray:
    """The shaking moment about the motors' axis O, N·m: the package's (about the origin)
    less ``O × F`` of the shaking force."""
    r = motion.reactions
    return r.shaking_moment - (AXIS.real * r.shaking_force.imag
                               - AXIS.imag * r.shaking_force.real)


def motion_rms(along) -> dict[str, dict[str, float]]:
    """Per motion: the RMS of each of :data:`LOADS` and of the moment about O."""
    out = {}
    for motion in along.motions:
        loads = motion.loads()
        row = {key: loads[key].rms for key, _, _ in LOADS}
        row["moment_about_axis"] = float(np.sqrt(np.mean(moment_about_axis(motion) ** 2)))
        row["centre_of_mass_excursion"] = motion.centre_of_mass_excursion
        out[motion.name] = row
    return out


# -- figures -----------------------------------------------------------------------------------


def figure_diamond(analyses: dict[str, dict[str, object]]) -> Figure:
    """The loads along the diamond for the three designs, without and with gravity."""
    fig = Figure(figsize=(11, 9), layout="constrained")
    axes = fig.subplots(len(LOADS), 2, sharex=True)
    for col, (which, words) in enumerate((("inertial", "without gravity"),
                                          ("gravity", f"with gravity {GRAVITY} m/s²"))):
        for name, by in analyses.items():
            diamond = by[which].motions[0]
            r = diamond.reactions
            values = {"shaking_force": np.abs(r.shaking_force),
                      "shaking_moment": r.shaking_moment,
                      "torque_link11": r.torques[0], "torque_link21": r.torques[1]}
            for row, (key, _, _) in enumerate(LOADS):
                axes[row, col].plot(diamond.t, values[key], color=DESIGN_COLOURS[name],
                                    lw=1.8 if name == "least mass" else 1.3, label=name)
        axes[0, col].set_title(words)
        axes[-1, col].set_xlabel("time (s)")
    for row, (key, words, unit) in enumerate(LOADS):
        label = f"|{words}|" if key == "shaking_force" else words
        axes[row, 0].set_ylabel(f"{label} ({unit})")
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize="small")
    fig.suptitle("Forbal-2 along the diamond: bare, with the published rings, with the least "
                 "counterweights (moments about the origin)")
    return fig


def figure_front(front, pair, published: tuple[float, float], bare: tuple[float, float],
                 least: float) -> Figure:
    """The front of least RMS shaking moment against added mass, with the published design.

    ``pair``: the front with counterweights on links 11 and 21 only, whose certified lower
    bounds are drawn (the package makes none for ``front``'s points).
    """
    fig = Figure(figsize=(7.5, 4.8), layout="constrained")
    ax = fig.add_subplot()
    xs = [p.value for p in front.points]
    ys = [p.least for p in front.points]
    ax.plot(xs, ys, "o-", color=SERIES[0],
            label="least RMS shaking moment, every design force-balanced")
    ax.plot([p.value for p in pair.points], [p.lower_bound for p in pair.points], "_",
            color="k", ms=12, label="certified lower bound (counterweights on 11, 21 only)")
    ax.axvline(least, color=COLOURS["after"], ls=":", lw=1.2,
               label=f"least mass that balances: {least:.4f} kg")
    ax.plot(*published, "s", color=SERIES[1], ms=9,
            label=f"published rings ({published[0]:.3f} kg): not exactly balanced")
    ax.plot(*bare, "D", color=COLOURS["before"], ms=8, label="bare robot (not balanced)")
    ax.set_xlabel("mass added to the bare robot (kg)")
    ax.set_ylabel("RMS shaking moment along the motions (N·m)")
    ax.set_xlim(left=-0.05)
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", loc="upper right")
    ax.set_title("Forbal-2: what each kilogram of counterweight buys\n(diamond, circle and "
                 "figure-eight weighted equally; no gravity)", fontsize="medium")
    return fig


# -- the study ----------------------------------------------------------------------------------


def run(out_dir: Path, quick: bool = False) -> dict:
    """Run the study and write its figures and ``forbal2.md`` into ``out_dir``.

    ``quick`` traces the fronts at 4 points instead of 11 (each point is analysed along the
    motions again, which costs what the inverse kinematics of the paths costs); everything else
    is the spec's: its motions' 400 states, its workspace's grid.
    """
    start = time.perf_counter()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    published = load_design(SPEC)
    points = 4 if quick else 11
    bare = bare_robot(published)

    # 2. The least added mass that balances the bare robot for every motion.
    least_problem = balancing(bare, Objective(shaking_moment=0.0, added_mass=1.0),
                              "Forbal-2 without its rings: the least counterweights")
    (out_dir / "forbal2_least_mass.toml").write_text(dumps_design(least_problem),
                                                     encoding="utf-8")
    result = optimize(least_problem)
    least = replace(published, mechanism=result.linkage,
                    title="Forbal-2 with the least counterweights")

    # 1. The three designs along the motions, without and with gravity.
    designs = {"bare": bare, "published": published, "least mass": least}
    analyses = {name: {"inertial": analyze_motions(d),
                       "gravity": analyze_motions(d, gravity=GRAVITY)}
                for name, d in designs.items()}
    rms = {name: {which: motion_rms(a) for which, a in by.items()}
           for name, by in analyses.items()}
    reductions = {which: {motion: {key: 1 - rms["published"][which][motion][key]
                                   / rms["bare"][which][motion][key]
                                   for key in rms["bare"][which][motion]}
                          for motion in rms["bare"][which]}
                  for which in ("inertial", "gravity")}

    # The closed form of the least mass (each direction's missing first moment over the radius).
    k11, k21 = first_moments(bare)
    closed_form = (abs(k11) + abs(k21)) / COUNTERWEIGHT.radius

    # 3. The front, each point rebuilt as a linkage and analysed along the motions (a check of
    # its design vector's meaning and figures, and of its force balance over the workspace's
    # grid, by the positions rather than the conditions the optimiser imposed).
    front_problem = balancing(bare, Objective(), "Forbal-2 without its rings: the front")
    front = pareto(front_problem, against="added-mass", points=points)
    checks = []
    for point in front.points:
        along = analyze_motions(design_of(front_problem, point.x))
        checks.append({"added_mass": along.linkage.total_mass - bare.mechanism.total_mass,
                       "shaking_moment": rms_along(along, "shaking_moment"),
                       "excursion": along.workspace.centre_of_mass_excursion,
                       "residual": along.force_balance_residual,
                       "counterweights": added_bodies(bare, along.linkage)})
    # The same front with counterweights on links 11 and 21 only (the counterweight on link
    # 22, which turns with link 11, buys nothing: the two fronts agree).
    pair = pareto(balancing(bare, Objective(), "Forbal-2 without its rings: links 11, 21",
                            links=("link11", "link21")), against="added-mass", points=points)
    published_point = (published.mechanism.total_mass - bare.mechanism.total_mass,
                       rms_along(analyses["published"]["inertial"], "shaking_moment"))
    bare_point = (0.0, rms_along(analyses["bare"]["inertial"], "shaking_moment"))
    least_point = (result.added_mass, rms_along(analyses["least mass"]["inertial"],
                                                "shaking_moment"))
    on_front_at_published = float(np.interp(published_point[0], [p.value for p in front.points],
                                            [p.least for p in front.points]))

    diamond = analyses["least mass"]["inertial"].motions[0]
    figures = [
        save_png(figure_front(front, pair, published_point, bare_point, result.added_mass),
                 out_dir / "front.png"),
        save_png(figure_diamond(analyses), out_dir / "diamond.png"),
        save_png(motion_figure(diamond, motion_drawing(diamond), title=least.title),
                 out_dir / "least_mass_diamond.png"),
    ]
    workspace = {name: by["inertial"].workspace for name, by in analyses.items()}
    results = {
        "quick": quick,
        "designs": designs,
        "analyses": analyses,
        "rms": rms,
        "reductions": reductions,
        "residual": {name: by["inertial"].force_balance_residual
                     for name, by in analyses.items()},
        "workspace": workspace,
        "published_excursion": workspace["published"].centre_of_mass_excursion,
        "least_excursion": workspace["least mass"].centre_of_mass_excursion,
        "rings_mass": sum(RINGS.values()),
        "result": result,
        "least_added_mass": result.added_mass,
        "counterweights": {name: cw for name, cw in result.counterweights.items()
                           if cw.kind != "none"},
        "first_moments": (k11, k21),
        "closed_form": closed_form,
        "off_line": max(abs(bare.mechanism.link(n).f) for n in bare.mechanism.link_names),
        "front": front,
        "front_checks": checks,
        "pair_front": pair,
        "published_point": published_point,
        "bare_point": bare_point,
        "least_point": least_point,
        "front_at_published": on_front_at_published,
        "figures": figures,
    }
    results["seconds"] = time.perf_counter() - start
    write_report(out_dir / REPORT, results)
    return results


# -- the report -------------------------------------------------------------------------------


def _change(cut: float) -> str:
    """A reduction ``cut`` (1 − after/before) as the signed change, ``−65 %`` or ``+49 %``."""
    return f"{-100 * cut:+.0f} %".replace("-", "−")


def write_report(path: Path, r: dict) -> None:
    rms, red, designs = r["rms"], r["reductions"], r["designs"]
    motions = list(rms["bare"]["inertial"])
    load_rows = []
    for which in ("inertial", "gravity"):
        for motion in motions:
            for key, words, unit in (*LOADS, ("moment_about_axis", "moment about O", "N·m")):
                row = [f"{motion}, {'no gravity' if which == 'inertial' else 'gravity'}",
                       f"{words} ({unit})"]
                row += [f"{rms[name][which][motion][key]:.4g}" for name in designs]
                row.append(_change(red[which][motion][key]))
                load_rows.append(row)
    loads = markdown_table(["motion", "RMS of", "bare", "published", "least mass",
                            "rings' change"], load_rows)
    excursions = markdown_table(
        ["design", "workspace (mm)", *(f"{m} (mm)" for m in motions), "conditions' residual"],
        [[name, f"{r['workspace'][name].centre_of_mass_excursion * 1e3:.4g}",
          *(f"{rms[name]['inertial'][m]['centre_of_mass_excursion'] * 1e3:.4g}"
            for m in motions), f"{r['residual'][name]:.2g}"] for name in designs])
    cws = markdown_table(
        ["link", "mass (kg)", "e (mm)", "f (mm)", "radius (mm)", "inertia (kg·m²)"],
        [[name, f"{cw.mass:.5f}", f"{cw.e * 1e3:.2f}", f"{cw.f * 1e3:.2f}",
          f"{abs(complex(cw.e, cw.f)) * 1e3:.2f}", f"{cw.inertia:.3g}"]
         for name, cw in r["counterweights"].items()])

    def body(mass: float, radius: float) -> str:
        return f"{mass:.3f} @ {radius * 1e3:.0f}" if mass > 1e-6 else "0"

    front_points, pair_points = r["front"].points, r["pair_front"].points
    front = markdown_table(
        ["added mass (kg)", "least RMS shaking moment (N·m)", "its design analysed (N·m)",
         "centre of mass excursion (m)", *(f"{n} (kg @ mm)" for n in RINGS),
         "links 11, 21 only (N·m)", "certified lower bound (N·m)"],
        [[f"{p.value:.4f}", f"{p.least:.5f}", f"{c['shaking_moment']:.5f}",
          f"{c['excursion']:.0e}", *(body(*c["counterweights"][n]) for n in RINGS),
          f"{q.least:.5f}", f"{q.lower_bound:.5f}"]
         for p, c, q in zip(front_points, r["front_checks"], pair_points, strict=True)])

    k11, k21 = r["first_moments"]
    res = r["result"]
    radius = COUNTERWEIGHT.radius
    low, high = COUNTERWEIGHT.mass
    mass = {name: d.mechanism.total_mass for name, d in designs.items()}
    weight = {name: -GRAVITY[1] * m for name, m in mass.items()}
    pub_mass, pub_moment = r["published_point"]
    least_mass, least_moment = r["least_point"]
    end = front_points[-1]
    grav, inertial = red["gravity"], red["inertial"]
    torques = ("torque_link11", "torque_link21")

    def span(cuts: list[float]) -> str:
        return f"{min(cuts):.0%}–{max(cuts):.0%}"

    moment_cuts = span([grav[m]["shaking_moment"] for m in motions])
    axis_cuts = span([grav[m]["moment_about_axis"] for m in motions])
    torque_cuts = span([grav[m][k] for m in motions for k in torques])
    moment_rise = -min(inertial[m]["shaking_moment"] for m in motions)
    torque_rise = -min(inertial[m][k] for m in motions for k in torques)
    force_cut = min(inertial[m]["shaking_force"] for m in motions)
    static = weight["published"] * AXIS.real
    uncertified = sum(p.lower_bound <= 0 for p in front_points)
    front_gap = max(p.least - p.lower_bound for p in front_points)
    certified_text = (
        f"Every point of this front is certified (its lower bound within {front_gap:.1e} N·m "
        "of it), though the counterweights on links 11 and 22 turn together (a "
        "parallelogram): their inertias, bounded below only, enter the shaking moment only "
        "through their sum, and the certificate bounds each by the sum's bound and the "
        "other's lower bound." if not uncertified else
        f"The package makes no certified lower bound for {uncertified} of this front's "
        f"{len(front_points)} points (reported as 0): the counterweights on links 11 and 22 "
        "turn together (a parallelogram), so their inertias, bounded below only, enter the "
        "shaking moment only through their sum.")
    spread = max(abs(p.least - q.least) for p, q in zip(front_points, pair_points, strict=True))
    pair_gap = max(q.least - q.lower_bound for q in pair_points)
    on_link22 = f'{max(c["counterweights"]["link22"][0] for c in r["front_checks"]):.1g}'
    below = [p.value for p in front_points if p.least <= r["bare_point"][1]]
    crossing = f"from about {min(below):.2f} kg on" if below else "at every mass within the bounds"
    excess = r["rings_mass"] - r["least_added_mass"]
    ring_list = ", ".join(f"{m:.8g}" for m in RINGS.values())
    quick = " (quick settings: 4 points on the fronts)" if r["quick"] else ""
    ws = r["workspace"]["published"]
    text = f"""# Forbal-2: the published balance, the least mass, the front

Source: Y. Vyas, M. Bottin, *Forbal: Force Balanced 2-5 Degree of Freedom Robot Manipulator
Built from a Five Bar Linkage*, arXiv 2509.03119 (2025); data from their repository
yjvyas/forbal as `examples/forbal2.toml` holds it. Three designs: **bare** (the robot without
its counter rings: the rings of {ring_list} kg at e = {RING_AT} m, each with its own inertia
m·(r₁² + r₂²)/2, taken off links 11, 21, 22), **published** (with the rings,
{r['rings_mass']:.4f} kg) and **least mass** (the bare robot with the least counterweights that
force-balance it, section 2){quick}.

## 1. The published design and what its rings buy

RMS along each motion, without gravity (the inertial loads, which balancing changes) and with
gravity {GRAVITY} m/s² (their robot works in a vertical plane). The shaking force is the sum of
the forces on the frame (with gravity it carries the weight: {weight['bare']:.3f} N bare,
{weight['published']:.3f} N published, {weight['least mass']:.3f} N least mass); the shaking
moment is the package's, about the world origin; the moment about the motors' axis O is the
study's (the package's less O × F). "rings' change": published against bare.

{loads}

The total centre of mass's excursion (its largest distance from its mean place) over the
workspace's grid ({ws.states} of its {ws.grid} states within the joint limits) and along each
motion, and the force-balance conditions' residual (relative to their terms; 0: balanced):

{excursions}

**Against the paper.** The paper measured, on the real robot, the counter masses cutting the
average reaction moments by up to {PAPER_MOMENT_CUT:.0%} and the joint torques by up to
{PAPER_TORQUE_CUT:.0%}. The model, with gravity, cuts the RMS shaking moment about the world
origin by {moment_cuts} (about the motors' axis by {axis_cuts}) and the motors' RMS torques by
{torque_cuts}: the same sense and size, and nearly all of it is gravity's. The rings put the
total centre of mass on the motors' axis, so the motors no longer hold the arms up and the
weight's moment no longer swings with the pose. Without gravity the rings *raise* the RMS
shaking moment (by up to {moment_rise:.0%}) and the torques (by up to {torque_rise:.0%}): they add
inertia, while the shaking force falls by {force_cut:.0%} or more. Where the model and the
measurement differ they may well: the measurements include the joints' friction (which the
rings do not change, and which dilutes the measured cut of the torques) and the controller's
tracking of the motion; the paper averages its own way (here: the RMS of the ideal motion's
inverse dynamics); and a reaction moment is measured about the sensor's point, not
necessarily the origin or O. About the origin, {AXIS.real * 1e3:.2f} mm beside the motors'
axis, the published robot's whole weight has a constant moment of {static:.3f} N·m: most of its
RMS there, and why the cut about the origin is the smaller.

## 2. The least added mass that balances the bare robot

`balancer.optimize` on the bare robot with `[balance] force_balance = true` (the total centre
of mass still over the whole workspace, so for every motion) and the added mass as the only
objective; one counterweight on each of links 11, 21 and 22, of mass in [{low:g}, {high:g}] kg,
its centre within {radius} m of the link's first point (the rings' reach: O for links 11 and 21,
B for link 22), its own radius of gyration at least a ring's, {RING_GYRATION * 1e3:.2f} mm. The
spec is written out as `forbal2_least_mass.toml`. Status {res.status}, gap {res.gap:.1e}.

**Least added mass: {r['least_added_mass']:.5f} kg**, against the published rings'
{r['rings_mass']:.5f} kg ({r['least_added_mass'] / r['rings_mass']:.0%} of it):

{cws}

(e along the link from its first point, f across it.) The closed form agrees. For the bare
robot the parallelogram's first moments along link 11's direction (links 11 and 22, and link
12's mass at link 11's end) and along link 21's (links 21 and 12, and link 22's mass at link
21's end) are K11 = {k11.real:.6f} {k11.imag:+.6f}i kg·m and K21 = {k21.real:.6f}
{k21.imag:+.6f}i kg·m. A counterweight on link 11 carries K11 alone, one on link 21 K21 alone,
each at least |K|/{radius} m: (|K11| + |K21|)/{radius} = {r['closed_form']:.5f} kg. A
counterweight on link 22 carries link 11's direction just as well as one on link 11, but its
mass sits at link 21's end, which link 21's counterweight must then carry too: each of its
kilograms costs one more. That is the published design's excess: its link-22 ring
({RINGS['link22']:.4f} kg) is nearly the whole difference ({excess:.4f} kg). The least
counterweights sit off the links' lines (f above): the bare links' centres lie
up to {r['off_line'] * 1e3:.1f} mm off their lines, which rings on the lines cannot cancel. The
published design's centre of mass moves {r['published_excursion'] * 1e3:.3f} mm over the
workspace, the least-mass design's {r['least_excursion']:.1e} m.

## 3. The front: RMS shaking moment against added mass

`balancer.pareto(..., against="added-mass", points={len(front_points)})`, every design
force-balanced, the same counterweights' bounds; the moments without gravity, the three
motions weighted equally. Each point's design is rebuilt from its design vector and analysed
along the motions by `balancer.analyze_motions` (the design as a linkage, not the optimiser's
design vector through its regressors; its centre of mass over the workspace's grid by the
positions, not by the force-balance conditions the optimiser imposed):

{front}

The front starts at the least mass ({least_mass:.4f} kg, {least_moment:.5f} N·m, as the
least-mass design above analyses) and falls to {end.least:.5f} N·m at {end.value:.3f} kg, where
the counterweights' bounds ({high:g} kg each) stop it. The mass goes into the same two
counterweights, on links 11 and 21 (mass @ distance from O in the table), moved inwards: each
must carry its direction's first moment |K| = m·r, and its inertia about O, m·r² = |K|²/m,
falls as its mass grows. No point uses link 22 ({on_link22} kg there at most). At the
published rings' {pub_mass:.3f} kg the front's least moment is {r['front_at_published']:.5f} N·m
(interpolated); the published design has {pub_moment:.5f} N·m and is not on the front: it is
not exactly force-balanced (residual {r['residual']['published']:.2g}), and its link-22 ring
rides at link 21's end, which link 21's ring must balance too: mass and inertia that a heavier
ring on link 11 would have spared. The bare robot, not
balanced at all, has {r['bare_point'][1]:.5f} N·m: force balance costs shaking moment here (the
counterweights add inertia); the front is below the bare robot {crossing}.

{certified_text} With counterweights on links 11 and 21 only (the last two columns) every
point has its certified lower bound too (within {pair_gap:.1e} N·m of it), and the two fronts
agree to {spread:.1e} N·m: the counterweight on link 22 buys nothing.

Figures: `front.png` (the front, the published and bare designs), `diamond.png` (the loads
along the diamond, the three designs, without and with gravity), `least_mass_diamond.png`
(`balancer.motion_figure` of the least-mass design: its centre of mass stands still).

Study run in {r['seconds']:.1f} s.
"""
    path.write_text(text, encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    """``python studies/forbal2.py [--out DIR] [--quick]``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parent / "out" / NAME,
                        help="output folder (default studies/out/forbal2)")
    parser.add_argument("--quick", action="store_true",
                        help="4 points on the fronts instead of 11")
    args = parser.parse_args(argv)
    r = run(args.out, quick=args.quick)
    print(f"{NAME}: least added mass {r['least_added_mass']:.5f} kg (closed form "
          f"{r['closed_form']:.5f} kg; published rings {r['rings_mass']:.5f} kg); published "
          f"excursion {r['published_excursion'] * 1e3:.3f} mm over the workspace; "
          f"{r['seconds']:.1f} s; wrote {args.out / REPORT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
