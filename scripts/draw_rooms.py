"""Draw rawehelix's rooms and the imports between them, from the code itself.

    .venv/bin/python scripts/draw_rooms.py docs/architecture/rooms.png
    .venv/bin/python scripts/draw_rooms.py docs/architecture/studies_rooms.png studies

One box per room (a top-level subpackage or module), on the floor its layer of
.importlinter gives (the command line on top, the errors at the bottom); an
arrow from a room to each room it imports (but the bottom floor, which any
room may import), labelled with the number of
module-to-module imports (grimp's graph, the one lint-imports checks, imports
inside functions included).  An arrow that ran up a floor would be drawn red;
tests/test_architecture.py refuses them.

With a second argument, a container of .importlinter (``studies``), the rooms
inside it by its own layers contract: each subpackage named on a floor of its
own is a box; the modules of the first floor (the drivers and registries, which
may import each other) are one box, its top-level modules and the subpackages
named there with them.
"""

from __future__ import annotations

import collections
import configparser
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def layers(container: str | None = None) -> list[list[str]]:
    """The floors of the layers contract, top first, each a list of rooms; inside a
    container, its first floor (``a : b : ...``) is one room, ``drivers``."""
    cfg = configparser.ConfigParser()
    cfg.read(ROOT / ".importlinter")
    section = f"importlinter:contract:{container}" if container else "importlinter:contract:layers"
    lines = [line for line in cfg[section]["layers"].split("\n") if line.strip()]
    floors = [[m.strip().removeprefix("rawehelix.") for m in line.split("|")] for line in lines]
    return [["drivers"]] + floors[1:] if container else floors


def room_of(container: str | None):
    """module -> its room: the top-level subpackage, or inside ``container`` the
    subpackage on a floor of its own (None outside the container)."""
    if not container:
        return lambda m: m.split(".")[1] if m.count(".") else None
    own = {name for floor in layers(container)[1:] for name in floor}
    prefix = f"rawehelix.{container}."

    def room(m):
        if not m.startswith(prefix):
            return None
        head = m[len(prefix):].split(".")[0]
        return head if head in own else "drivers"
    return room


def room_edges(container: str | None = None) -> tuple[dict, dict]:
    """(room -> modules, (room, room) -> imports) from grimp."""
    import grimp
    graph = grimp.build_graph("rawehelix", include_external_packages=False)
    room = room_of(container)
    sizes = collections.Counter(room(m) for m in graph.modules if room(m))
    edges = collections.Counter()
    for m in graph.modules:
        for t in graph.find_modules_directly_imported_by(m):
            a, b = room(m), room(t)
            if a and b and a != b:
                edges[(a, b)] += 1
    return sizes, edges


def draw(path: Path, container: str | None = None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import FancyArrowPatch, FancyBboxPatch

    floors = layers(container)
    sizes, edges = room_edges(container)
    where, floor_of = {}, {}
    for k, floor in enumerate(floors):
        for j, name in enumerate(floor):
            where[name] = ((j + 0.5) / len(floor), 1.0 - (k + 0.5) / len(floors))
            floor_of[name] = k
    fig, ax = plt.subplots(figsize=(11, 7.5))
    w, h = 0.2, 0.055
    for name, (x, y) in where.items():
        ax.add_patch(FancyBboxPatch((x - w / 2, y - h / 2), w, h,
                                    boxstyle="round,pad=0.005", fc="#e8eef7", ec="#345"))
        label = name + ("/" if sizes[name] > 1 else ".py") if name != "drivers" else name
        ax.text(x, y + 0.008, label, ha="center",
                va="center", fontsize=10, weight="bold")
        ax.text(x, y - 0.016, f"{sizes[name]} module{'s' * (sizes[name] > 1)}", ha="center",
                va="center", fontsize=7, color="#555")
    for (a, b), n in edges.items():
        if a not in where or b not in where or (floor_of[b] == len(floors) - 1
                                                   and not container):
            continue  # the bottom floor (compat, families, errors): any room may use it
        up = floor_of[b] <= floor_of[a]
        (xa, ya), (xb, yb) = where[a], where[b]
        arrow = FancyArrowPatch((xa, ya - h / 2), (xb, yb + h / 2), arrowstyle="-|>",
                                mutation_scale=9, lw=0.4 + 0.25 * min(n, 12) ** 0.5,
                                color="red" if up else "#567", alpha=0.75,
                                connectionstyle="arc3,rad=0.08")
        ax.add_patch(arrow)
        ax.text(0.6 * xa + 0.4 * xb, 0.6 * (ya - h / 2) + 0.4 * (yb + h / 2), str(n),
                fontsize=6, color="#333", ha="center",
                bbox=dict(fc="white", ec="none", pad=0.3, alpha=0.8))
    ax.set_xlim(-0.02, 1.02)
    ax.set_ylim(0, 1)
    ax.axis("off")
    title = ("rawehelix: rooms by floor (.importlinter's layers) and the imports between "
             "them\n(number: module-to-module imports; every arrow runs down a floor; "
             "arrows into the bottom floor left out)")
    if container:
        title = (f"rawehelix/{container}/: its rooms by floor (.importlinter's {container} "
                 "contract) and the imports between them\n(drivers: its top-level modules "
                 "and the packages beside them; number: module-to-module imports)")
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    print("wrote", path)


if __name__ == "__main__":
    draw(Path(sys.argv[1] if len(sys.argv) > 1 else "docs/architecture/rooms.png"),
         sys.argv[2] if len(sys.argv) > 2 else None)
