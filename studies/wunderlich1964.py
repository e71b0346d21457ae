"""Wunderlich (1964): the path of a four-bar's total centre of mass, and when it stands still.

Source: W. Wunderlich, *Concerning the trajectory of the center of mass of the four-bar linkage
and the slider-crank mechanism*, Buletinul Institutului Politehnic din Iasi X (XIV) (1964),
285–291; Sect. 1–2, Eq. 1–10, Theorem 1 (Fig. 1) and Theorem 2 (Fig. 2).

What it reproduces:

- Theorem 1 and Fig. 1: the total centre of mass S of a four-bar moves on a curve similar to a
  coupler curve of the linkage itself, ``Z = c + γ·z`` with ``z = u1 + β·u2`` (Eq. 2, 4, 7–9),
  traced by the four-bar B0B1B2B3 with ``v_k = γ·u_k``. Wunderlich gives no dimensions for his
  Fig. 1, so the linkage is Meijaard & van der Wijk's (2020) example of Eq. 56, whose centres
  of mass lie off the link lines (complex σk, the general case). Checked numerically: the
  mass-weighted centre of mass equals the similarity transform of the coupler curve to
  rounding (~1e-16 of the link lengths), B0, B3 and β from his Eq. 8–9 written out here agree
  with :func:`balancer.massmodels.wunderlich_linkage`, and B0B1B2B3 closes.
- Theorem 2 and Fig. 2: with the centres of mass on the link lines chosen by his Eq. 10d the
  total centre of mass is a fixed point, ``m3·σ3·a`` (masses summing to one). Also checked:
  the force-balance conditions of Meijaard & van der Wijk (Eq. 57) hold, and, as Wunderlich
  remarks, the linkage is in neutral equilibrium in every position: released at rest under
  gravity, it stays at rest.
- Fig. 3 (the slider-crank, Sect. 3–4): a placeholder, :func:`slider_crank_counterpart`, to be
  filled in when the slider-crank mechanism is part of ``balancer``.

Run ``python studies/wunderlich1964.py``; it writes ``studies/out/wunderlich1964/``.
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from balancer.conditions import force_balance_error
from balancer.kinematics import position_of
from balancer.massmodels import link_centres_of_mass, total_com_direct, wunderlich_linkage
from balancer.model import FourBar, SimulationSettings
from balancer.plots import COLOURS
from balancer.simulate import simulate
from balancer.spec import load_design

NAME = "wunderlich1964"
ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "examples" / "meijaard2020.toml"
DPI = 100
#: Crank angle at which the linkages are drawn, rad.
DRAW_AT = 1.0
#: Theorem 2's free choice: the crank's centre of mass as a real fraction of the crank,
#: σ1 = −1 (a counterweight at the crank's length beyond A0).
SIGMA1 = -1.0


def save_png(fig: Figure, path: Path) -> Path:
    """Write a figure as PNG with the Agg canvas."""
    FigureCanvasAgg(fig)
    fig.savefig(path, dpi=DPI)
    return path


def markdown_table(header: list[str], rows: list[list[str]]) -> str:
    """A GitHub-flavoured markdown table (first column left-aligned, the others right)."""
    lines = ["| " + " | ".join(header) + " |",
             "|" + "|".join([":---"] + ["---:"] * (len(header) - 1)) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


# ----------------------------------------------------------------------------------------------
# Wunderlich's formulas, written out from the paper (masses normalised to sum to one,
# σk = s̄k/lk complex, u_k the link vectors, a = l4)


def wunderlich_eq7_9(linkage: FourBar) -> dict[str, complex]:
    """``α1..3`` (Eq. 7), ``B0``, ``B3`` (Eq. 8) and ``β`` (Eq. 9) from his formulas."""
    total = linkage.total_mass
    m1, m2, m3 = (link.mass / total for link in linkage.links)
    s1, s2, s3 = (link.com / length for link, length in zip(linkage.links, linkage.lengths,
                                                            strict=False))
    a = linkage.lengths[3]
    return {
        "alpha1": 1 + m1 * (s1 - 1),
        "alpha2": m2 * s2 + m3,
        "alpha3": m3 * s3,
        "B0": m3 * s3 * a,
        "B3": (1 + m1 * (s1 - 1)) * a,
        "beta": (m2 * s2 + m3 * (1 - s3)) / (m1 * s1 + m2 + m3 * (1 - s3)),
    }


def theorem2_linkage(linkage: FourBar, sigma1: float) -> FourBar:
    """The linkage with real centres of mass on the link lines chosen by Eq. 10d.

    ``σ2 = 1 + (m1/m2)·σ1`` and ``σ3 = 1 + m2/m3 + (m1/m3)·σ1``; masses and inertias kept.
    """
    (l1, l2, l3, _), (c1, c2, c3) = linkage.lengths, linkage.links
    sigma2 = 1 + c1.mass / c2.mass * sigma1
    sigma3 = 1 + c2.mass / c3.mass + c1.mass / c3.mass * sigma1
    return linkage.with_links({
        "crank": replace(c1, e=sigma1 * l1, f=0.0),
        "coupler": replace(c2, e=sigma2 * l2, f=0.0),
        "rocker": replace(c3, e=sigma3 * l3, f=0.0),
    })


# ----------------------------------------------------------------------------------------------
# Figures


def _ground(ax, points: list[complex], colour: str = "k", size: float = 11) -> None:
    ax.plot([p.real for p in points], [p.imag for p in points], "^", color=colour, ms=size,
            zorder=5)


def figure_1(linkage: FourBar, pos, one, com, w) -> Figure:
    """Fig. 1: the linkage, its coupler curve, the centre-of-mass path and B0B1B2B3."""
    fig = Figure(figsize=(8, 7), layout="constrained")
    ax = fig.add_subplot()
    z = pos.l1 + w.beta * pos.l2  # Eq. 2: the coupler curve of the point B, A1B = β·u2
    ax.plot(z.real, z.imag, color=COLOURS["before"], lw=1.4, ls="--",
            label="coupler curve of B (A1B = β·A1A2), Eq. 2")
    ax.plot(com.real, com.imag, color=COLOURS["after"], lw=2.4,
            label="path of the total centre of mass S")
    # The linkage A0A1A2A3 and its coupler point B at one position.
    a1, a2, a3 = one.A1[0], one.A2[0], one.A3
    b = a1 + w.beta * one.l2[0]
    ax.plot([0, a1.real, a2.real, a3.real], [0, a1.imag, a2.imag, a3.imag], "-o",
            color=COLOURS["A0"], lw=3, ms=6, label="four-bar A0A1A2A3")
    ax.fill([a1.real, b.real, a2.real], [a1.imag, b.imag, a2.imag], color=COLOURS["A0"],
            alpha=0.15)
    ax.plot([b.real], [b.imag], "o", color=COLOURS["before"], ms=7)
    # Link centres of mass S1, S2, S3 and S at that position.
    coms = link_centres_of_mass(linkage, one)
    ax.plot([c[0].real for c in coms], [c[0].imag for c in coms], "s", color=COLOURS["A0"],
            ms=6, label="link centres of mass S1, S2, S3")
    # The generating four-bar B0B1B2B3: v_k = γ·u_k, with S as its coupler point.
    b1, b2 = w.generating_joints(one)
    s = w.trace(one)[0]
    ax.plot([w.B0.real, b1[0].real, b2[0].real, w.B3.real],
            [w.B0.imag, b1[0].imag, b2[0].imag, w.B3.imag], "-o", color=COLOURS["A3"], lw=2,
            ms=5, label="generating four-bar B0B1B2B3 (similar, ratio |γ|)")
    ax.fill([b1[0].real, s.real, b2[0].real], [b1[0].imag, s.imag, b2[0].imag],
            color=COLOURS["A3"], alpha=0.15)
    ax.plot([s.real], [s.imag], "o", color=COLOURS["after"], ms=10, zorder=6,
            label="S, coupler point of B0B1B2B3")
    _ground(ax, [0j, a3])
    _ground(ax, [w.B0, w.B3], COLOURS["A3"], 9)
    for text, p, offset in (("A0", 0j, (-14, -14)), ("A3", a3, (6, -14)),
                            ("A1", a1, (-16, 4)), ("A2", a2, (6, 4)), ("B", b, (6, 4)),
                            ("B0", w.B0, (-16, -14)), ("B3", w.B3, (6, -14)),
                            ("B1", b1[0], (-16, 4)), ("B2", b2[0], (6, 4)), ("S", s, (8, -4))):
        ax.annotate(text, (p.real, p.imag), textcoords="offset points", xytext=offset,
                    fontsize=9)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("Wunderlich (1964), Fig. 1: the centre-of-mass path is a coupler curve similar "
                 "to the linkage's own\n(linkage: Meijaard & van der Wijk 2020, Eq. 56)",
                 fontsize=10)
    ax.grid(alpha=0.3)
    fig.legend(fontsize="small", loc="outside lower center", ncol=2)
    return fig


def figure_2(linkage: FourBar, angles: np.ndarray, fixed: complex) -> Figure:
    """Fig. 2: the linkage of Theorem 2 at several positions; S stays at m3·σ3·a."""
    fig = Figure(figsize=(8, 5.5), layout="constrained")
    ax = fig.add_subplot()
    pos = position_of(linkage, angles)
    r1, r2, r3 = link_centres_of_mass(linkage, pos)
    for path, label in ((r1, "S1"), (r2, "S2"), (r3, "S3")):
        ax.plot(path.real, path.imag, color=COLOURS["before"], lw=1, ls=":")
        k = int(np.argmax(path.imag))
        ax.annotate(f"path of {label}", (path[k].real, path[k].imag),
                    textcoords="offset points", xytext=(0, 5), fontsize=8, ha="center",
                    color="dimgray")
    a3 = pos.A3
    shown = np.linspace(0, angles.size - 1, 9)[:-1].astype(int)
    for n, k in enumerate(shown):
        a1, a2 = pos.A1[k], pos.A2[k]
        alpha = 1.0 if n == 1 else 0.25
        label = "linkage (dimmed: other positions)" if n == 1 else None
        # Links, extended to the centres of mass that lie beyond the joints.
        ax.plot([r1[k].real, a1.real], [r1[k].imag, a1.imag], color=COLOURS["A0"], lw=2.5,
                alpha=alpha, label=label)
        ax.plot([a1.real, a2.real], [a1.imag, a2.imag], color=COLOURS["A0"], lw=2.5,
                alpha=alpha)
        ax.plot([a2.real, r3[k].real], [a2.imag, r3[k].imag], color=COLOURS["A0"], lw=2.5,
                alpha=alpha)
        ax.plot([r1[k].real, r2[k].real, r3[k].real], [r1[k].imag, r2[k].imag, r3[k].imag],
                "s", color=COLOURS["A3"], ms=6 if n == 1 else 4, alpha=alpha,
                label="link centres of mass S1, S2, S3" if n == 1 else None)
    ax.plot([fixed.real], [fixed.imag], "*", color=COLOURS["after"], ms=18, zorder=6,
            label="total centre of mass S = m3·σ3·a (fixed)")
    _ground(ax, [0j, a3])
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("Wunderlich (1964), Fig. 2 / Theorem 2: centres of mass on the link lines by "
                 "Eq. 10d —\nthe total centre of mass stands still", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", loc="lower left")
    return fig


# ----------------------------------------------------------------------------------------------
# Fig. 3: the slider-crank


def slider_crank_counterpart(out_dir: Path, quick: bool = False) -> dict | None:
    """PLACEHOLDER for Wunderlich's Fig. 3: the slider-crank counterpart (Sect. 3–4).

    To be filled in once the slider-crank mechanism is part of ``balancer``. It should show
    Theorem 3 — the total centre of mass of a slider-crank traces a connecting-rod curve similar
    to one of the mechanism itself, ``Z = α0 + α1·(u1 + β·u2)`` (Eq. 13, 16), generated by the
    slider-crank B0B1B2B2' with ``B0 = m3·s3`` (Eq. 17), ``v_k = α1·u_k`` (Eq. 18) and
    ``β = α2/α1`` (Eq. 19) — checked to rounding as for the four-bar, and the stationary centre
    of mass of Eq. 20a–b (at B0). Return its key numbers as a dict and write its figure(s) into
    ``out_dir``; ``None`` means "not yet", and the report says so.
    """
    return None


# ----------------------------------------------------------------------------------------------


def run(out_dir: Path, quick: bool = False) -> dict:
    """Run the study and write its figures and ``report.md`` into ``out_dir``.

    ``quick`` samples fewer crank angles and simulates the neutral equilibrium for less time.
    """
    start = time.perf_counter()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    linkage = load_design(SPEC).mechanism.without_loads()
    angles = np.linspace(0.0, 2 * np.pi, 181 if quick else 1441)
    scale = max(linkage.lengths)

    # Theorem 1.
    pos = position_of(linkage, angles)
    com = total_com_direct(linkage, pos)
    w = wunderlich_linkage(linkage)
    z = pos.l1 + w.beta * pos.l2
    similarity = float(np.max(np.abs(com - (w.B0 + w.gamma * z))) / scale)
    paper = wunderlich_eq7_9(linkage)
    formula = max(abs(paper["B0"] - w.B0), abs(paper["B3"] - w.B3)) / scale
    formula = max(formula, abs(paper["beta"] - w.beta))
    b1, b2 = w.generating_joints(pos)
    closure = float(np.max(np.abs(b2 + w.gamma * pos.l3 - w.B3)) / scale)

    # Theorem 2.
    still = theorem2_linkage(linkage, SIGMA1)
    mt = still.total_mass
    sigma3 = still.rocker.e / still.lengths[2]
    fixed = still.rocker.mass / mt * sigma3 * still.lengths[3]  # m3·σ3·a, masses summing to 1
    still_com = total_com_direct(still, position_of(still, angles))
    stationary = float(np.max(np.abs(still_com - fixed)) / scale)
    rest = simulate(still, SimulationSettings(duration=0.5 if quick else 2.0, theta1=DRAW_AT,
                                              omega1=0.0, gravity=(0.0, -9.81)),
                    method="opened-loop", rtol=1e-11, atol=1e-13, outputs=51)
    neutral = float(np.max(np.abs(rest.omega)))

    figures = [
        save_png(figure_1(linkage, pos, position_of(linkage, DRAW_AT), com, w),
                 out_dir / "fig1_com_path.png"),
        save_png(figure_2(still, angles, fixed), out_dir / "fig2_stationary.png"),
    ]
    slider = slider_crank_counterpart(out_dir, quick)
    results = {
        "similarity": similarity,
        "formula": float(formula),
        "closure": closure,
        "gamma": w.gamma,
        "beta": w.beta,
        "B0": w.B0,
        "B3": w.B3,
        "stationary": stationary,
        "stationary_point": fixed,
        "stationary_force_balance": force_balance_error(still),
        "is_stationary": wunderlich_linkage(still).is_stationary,
        "neutral_equilibrium": neutral,
        "slider_crank": slider,
        "figures": figures,
    }
    results["seconds"] = time.perf_counter() - start
    write_report(out_dir / "report.md", linkage, still, paper, angles.size, results)
    return results


def _c(x: complex, digits: int = 6) -> str:
    return f"{x.real:.{digits}g} {'+' if x.imag >= 0 else '−'} {abs(x.imag):.{digits}g}i"


def write_report(path: Path, linkage, still, paper, samples, results) -> None:
    w = results
    table1 = markdown_table(
        ["quantity", "Wunderlich's formula (Eq. 7–9)", "balancer.massmodels"],
        [["B0 = m3·σ3·a (m)", _c(paper["B0"]), _c(w["B0"])],
         ["B3 = [1 + m1(σ1 − 1)]·a (m)", _c(paper["B3"]), _c(w["B3"])],
         ["γ = α1 − α3", _c(paper["alpha1"] - paper["alpha3"]), _c(w["gamma"])],
         ["β = (α2 − α3)/(α1 − α3)", _c(paper["beta"]), _c(w["beta"])]],
    )
    checks = markdown_table(
        ["check", "value"],
        [["max abs(S − (B0 + γ·z)) / l_max over the revolution", f"{w['similarity']:.1e}"],
         ["Eq. 8–9 against the library (largest difference)", f"{w['formula']:.1e}"],
         ["closure of B0B1B2B3: max abs(B2 + γ·u3 − B3) / l_max", f"{w['closure']:.1e}"],
         ["Theorem 2: max abs(S − m3·σ3·a) / l_max", f"{w['stationary']:.1e}"],
         ["Theorem 2: Eq. 57 residual (Meijaard & van der Wijk)",
          f"{w['stationary_force_balance']:.1e}"],
         ["Theorem 2: largest link rate after release at rest under gravity (rad/s)",
          f"{w['neutral_equilibrium']:.1e}"]],
    )
    sig = [link.e / length for link, length in zip(still.links, still.lengths, strict=False)]
    slider = ("Not yet: `slider_crank_counterpart()` is a placeholder until the slider-crank "
              "mechanism is part of `balancer`." if w["slider_crank"] is None
              else str(w["slider_crank"]))
    text = f"""# Wunderlich (1964): the trajectory of the total centre of mass

Source: W. Wunderlich, *Concerning the trajectory of the center of mass of the four-bar linkage
and the slider-crank mechanism*, Bul. Inst. Politehnic Iasi X (XIV) (1964), 285–291.

## Theorem 1, Fig. 1: a coupler curve similar to the linkage's own

Wunderlich's Fig. 1 has no dimensions in the text; the linkage here is Meijaard & van der
Wijk's example (2020, Eq. 56), whose centres of mass are off the link lines (complex σk).
The total centre of mass S, computed as the mass-weighted mean of the links' centres of mass at
{samples} crank angles, equals the similarity transform `B0 + γ·z` of the coupler curve
`z = u1 + β·u2` (Eq. 2, 4): the point B with A1B = β·A1A2 on the linkage's own coupler.
The generating four-bar B0B1B2B3 has links `v_k = γ·u_k`: similar to A0A1A2A3 at every
instant, in the ratio |γ| = {abs(w['gamma']):.6g}, turned by arg γ = {np.angle(w['gamma']):.6g}
rad.

{table1}

## Theorem 2, Fig. 2: a stationary centre of mass

Same lengths and masses, centres of mass on the link lines chosen by Eq. 10d with
σ1 = {sig[0]:.6g} (a counterweight beyond A0): σ2 = 1 + (m1/m2)·σ1 = {sig[1]:.6g},
σ3 = 1 + m2/m3 + (m1/m3)·σ1 = {sig[2]:.6g}. The total centre of mass stays at
m3·σ3·a = {w['stationary_point'].real:.6g} m on the frame line (masses normalised to sum to
one, as in the paper). Wunderlich's conditions are Meijaard & van der Wijk's force-balance
conditions (Eq. 57) in other words, and the linkage is in neutral equilibrium under gravity.

## Checks

{checks}

## Fig. 3: the slider-crank (Sect. 3–4, Theorem 3)

{slider}

## Figures

- `fig1_com_path.png`: the linkage, the coupler curve of B, the path of S and the generating
  four-bar B0B1B2B3 (his Fig. 1).
- `fig2_stationary.png`: the linkage of Theorem 2 in eight positions with its centres of mass;
  S does not move (his Fig. 2).

Generated by `python studies/{NAME}.py` in {w['seconds']:.1f} s.
"""
    path.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    res = run(Path(__file__).parent / "out" / NAME)
    print(f"{NAME}: similarity {res['similarity']:.1e}, stationary {res['stationary']:.1e}, "
          f"neutral equilibrium {res['neutral_equilibrium']:.1e} rad/s; {res['seconds']:.1f} s")
