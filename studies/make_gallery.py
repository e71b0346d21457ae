"""Regenerate ``docs/gallery/``: the studies' figures, report pictures, an animation.

Runs every study (``studies/*.py`` with a ``run``) in full mode into ``studies/out/<name>/``,
copies the figures listed in :data:`CHOSEN` into ``docs/gallery/`` under stable names, runs the
``balancer`` commands of :data:`COMMANDS` (docs/gallery.md's, word for word: the report pictures
of ``plot --cycle``, ``plot --orders`` and ``verify --plot``, from designs balanced by
``optimize`` into ``studies/out/gallery/``, and of ``plot --motion``), and writes animations
(:data:`ANIMATIONS`) of the example of Meijaard & van der Wijk (2020), Eq. 56
(``examples/meijaard2020.toml``) and of the single-cylinder engine
(``examples/single_cylinder.toml``: its piston and counterweights) with
:func:`balancer.plots.animate`. The gallery is committed, so each file must stay small
(:data:`MAX_BYTES`); the script says which one does not and exits with status 1.

Run ``python studies/make_gallery.py`` from anywhere; ``docs/gallery.md`` shows the figures with
the commands and studies that make them.
"""

from __future__ import annotations

import importlib.util
import shlex
import shutil
import sys
import time
from pathlib import Path
from types import ModuleType

from balancer.cli import main as balancer
from balancer.plots import animate
from balancer.spec import load_design

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
GALLERY = ROOT / "docs" / "gallery"
STUDIES = ("meijaard2020_example", "meijaard2020_balanced", "wunderlich1964",
           "bai2024_lie_group", "benchmarks_pb", "linkages", "atlas_and_fronts", "forbal2")
#: (study, figure it writes, name in the gallery).
CHOSEN = (
    ("meijaard2020_balanced", "comparison.png", "balancing_four_designs.png"),
    ("wunderlich1964", "fig1_com_path.png", "wunderlich_com_path.png"),
    ("bai2024_lie_group", "fig7_parallelogram.png", "bai_parallelogram.png"),
    ("linkages", "jansen_s_leg.png", "jansen_leg_balanced.png"),
    ("linkages", "stephenson_six_bar.png", "stephenson_balanced.png"),
    ("atlas_and_fronts", "atlas.png", "pb1_atlas.png"),
    ("atlas_and_fronts", "front_torque.png", "pb1_front_torque.png"),
    ("atlas_and_fronts", "front_mass.png", "pb1_front_mass.png"),
)
#: Report pictures by the command line, as docs/gallery.md shows them: (gallery name, commands run
#: from the repository's root; ``OUT`` is ``studies/out/gallery``). Each command overwrites.
COMMANDS = (
    ("pb1_cycle.png", (
        "balancer optimize examples/pb1.toml --out OUT/pb1_balanced.toml",
        "balancer plot OUT/pb1_balanced.toml --cycle docs/gallery/pb1_cycle.png")),
    ("pb1_verify.png", (
        "balancer verify OUT/pb1_balanced.toml --duration 2 --plot docs/gallery/pb1_verify.png",
    )),
    ("engine_cycle.png", (
        "balancer optimize examples/engine.toml --out OUT/engine_balanced.toml",
        "balancer plot OUT/engine_balanced.toml --cycle docs/gallery/engine_cycle.png")),
    ("two_plane_cycle.png", (
        "balancer optimize examples/two_plane_drive.toml --out OUT/two_plane_balanced.toml",
        "balancer plot OUT/two_plane_balanced.toml --cycle docs/gallery/two_plane_cycle.png")),
    ("two_plane_orders.png", (
        "balancer plot OUT/two_plane_balanced.toml --orders docs/gallery/two_plane_orders.png",
    )),
    ("inline_four_cycle.png", (
        "balancer plot examples/inline_four.toml --cycle docs/gallery/inline_four_cycle.png",
    )),
    ("inline_four_orders.png", (
        "balancer plot examples/inline_four.toml --orders docs/gallery/inline_four_orders.png",
    )),
    ("inline_three_phasors.png", (
        "balancer plot examples/inline_three_to_balance.toml --phasors "
        "docs/gallery/inline_three_phasors.png",
    )),
    ("single_cylinder_orders.png", (
        "balancer plot examples/single_cylinder.toml --orders "
        "docs/gallery/single_cylinder_orders.png --log",
    )),
    ("forbal2_diamond.png", (
        "balancer plot examples/forbal2.toml --motion diamond --cycle "
        "docs/gallery/forbal2_diamond.png",
    )),
    ("fivebar_5r_verify.png", (
        "balancer optimize examples/fivebar_5r.toml --no-verify --out "
        "OUT/fivebar_5r_balanced.toml",
        "balancer verify OUT/fivebar_5r_balanced.toml --plot docs/gallery/fivebar_5r_verify.png",
    )),
    ("forbal2_plan.png", (
        "balancer plan examples/forbal2.toml --plot docs/gallery/forbal2_plan.png",
    )),
    ("servo_press_plan.png", (
        "balancer plan examples/servo_press.toml --plot docs/gallery/servo_press_plan.png",
    )),
)
#: Animations: (gallery name, example spec, frames per revolution).
ANIMATIONS = (("meijaard2020.gif", "meijaard2020", 48),
              ("single_cylinder.gif", "single_cylinder", 36),
              ("square_four.gif", "square_four", 36),
              ("opposed_piston.gif", "opposed_piston", 36))
#: Size budget per gallery file, bytes.
MAX_BYTES = {".png": 250_000, ".gif": 600_000}


def load_study(name: str) -> ModuleType:
    """Import ``studies/<name>.py`` from its file."""
    spec = importlib.util.spec_from_file_location(f"study_{name}", HERE / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def command_argv(command: str) -> list[str]:
    """The arguments of a :data:`COMMANDS` line, paths from the repository's root."""
    words = shlex.split(command.replace("OUT/", "studies/out/gallery/"))
    assert words[0] == "balancer"
    return [str(ROOT / w) if "/" in w else w for w in words[1:]]


def run_commands() -> list[Path]:
    """Run :data:`COMMANDS` (overwriting their outputs); the gallery files they wrote."""
    (HERE / "out" / "gallery").mkdir(parents=True, exist_ok=True)
    for _, commands in COMMANDS:
        for command in commands:
            start = time.perf_counter()
            status = balancer([*command_argv(command), "--force"])
            if status != 0:
                raise SystemExit(f"{command}: exit {status}")
            print(f"{command:<88} {time.perf_counter() - start:6.1f} s")
    return [palette_png(GALLERY / target) for target, _ in COMMANDS]


def write_animations() -> list[Path]:
    """Write :data:`ANIMATIONS` (the gallery files)."""
    return [animate(load_design(ROOT / "examples" / f"{spec}.toml"), GALLERY / name,
                    frames=frames) for name, spec, frames in ANIMATIONS]


def palette_png(path: Path) -> Path:
    """Rewrite a PNG with a palette of 256 colours (a plot has few): a third of the bytes."""
    from PIL import Image

    with Image.open(path) as image:
        small = image.convert("RGB").quantize(colors=256, method=Image.Quantize.MEDIANCUT)
    small.save(path, format="PNG", optimize=True)
    return path


def main() -> int:
    """Run the studies, fill the gallery, report sizes; 0 if every file is within budget."""
    GALLERY.mkdir(parents=True, exist_ok=True)
    written = []
    for name in STUDIES:
        start = time.perf_counter()
        load_study(name).run(HERE / "out" / name)
        print(f"{name:<24} {time.perf_counter() - start:6.1f} s")
    for study, figure, target in CHOSEN:
        written.append(Path(shutil.copyfile(HERE / "out" / study / figure, GALLERY / target)))
    written.extend(run_commands())
    written.extend(write_animations())
    status = 0
    for path in written:
        size = path.stat().st_size
        budget = MAX_BYTES[path.suffix]
        note = "" if size <= budget else f"  OVER the budget of {budget // 1000} kB"
        status = status or int(size > budget)
        print(f"{path.relative_to(ROOT)}  {size / 1000:.0f} kB{note}")
    return status


if __name__ == "__main__":
    sys.exit(main())
