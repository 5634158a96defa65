"""The body graph of a mechanism file, for ``cpm-nlp describe FILE --plot FIGURE``: bodies as
nodes (the base at the bottom, the platform at the top, each leg's links in a column between),
joints as edges labelled with their type, actuated joints drawn thick and red with their
actuator's name.  Matplotlib only (no pyplot: no global figure state)."""

from __future__ import annotations

from typing import Any

#: colours of the drawing: actuated joints, passive joints, bodies
ACTUATED, PASSIVE, BODY = "#c0392b", "#555555", "#d6eaf8"


def _graph_layout(nodes: list[str], edges: list[tuple[str, str, str, bool]]) -> dict[str, tuple[float, float]]:
    """A body graph of any topology: the ground (the first node) at the bottom, each body one row
    above the nearest body it is joined to (breadth first), the bodies of a row side by side in
    the order of the file."""
    pairs = [(u, v) for a, b, _label, _act in edges for u, v in ((a, b), (b, a))]
    depth = {nodes[0]: 0}
    frontier = [nodes[0]]
    while frontier:
        nxt = [v for u, v in pairs if u in frontier and v not in depth]
        for v in nxt:
            depth.setdefault(v, depth[next(u for u, w in pairs if w == v and u in frontier)] + 1)
        frontier = list(dict.fromkeys(nxt))
    for body in nodes:
        depth.setdefault(body, max(depth.values()) + 1)
    rows: dict[int, list[str]] = {}
    for body in nodes:
        rows.setdefault(depth[body], []).append(body)
    pos: dict[str, tuple[float, float]] = {}
    for level in sorted(rows):
        row = rows[level]
        if level:  # fewer crossings: each body under the mean of its neighbours in the row below (stable)
            below = {b: pos[b][0] for b in pos if depth[b] == level - 1}

            def mean(body: str, below: dict = below) -> float:
                xs = [below[v] for u, v in pairs if u == body and v in below]
                return sum(xs) / len(xs) if xs else 0.0

            row = sorted(row, key=mean)
        for k, body in enumerate(row):
            pos[body] = ((k - (len(row) - 1) / 2) * 1.8, float(level))
    return pos


def _layout(nodes: list[str], edges: list[tuple[str, str, str, bool]]) -> dict[str, tuple[float, float]]:
    """Base at (0, 0), platform at (0, top); a leg's links in its own column, evenly up."""
    if nodes and nodes[0] != "base":  # a bodies-and-joints file: any topology
        return _graph_layout(nodes, edges)
    chains: list[list[str]] = []
    for a, b, _label, _act in edges:
        if a == "base":
            chains.append([])
        if b not in ("base", "platform") and chains and b not in chains[-1]:
            chains[-1].append(b)
    depth = max((len(c) for c in chains), default=0)
    top = float(depth + 1)
    pos = {"base": (0.0, 0.0), "platform": (0.0, top)}
    n = max(len(chains), 1)
    for k, chain in enumerate(chains):
        x = (k - (n - 1) / 2) * 1.6
        for h, body in enumerate(chain):
            pos.setdefault(body, (x, top * (h + 1) / (len(chain) + 1)))
    for k, body in enumerate(b for b in nodes if b not in pos):  # bodies no edge reaches
        pos[body] = (1.6 * (k + 1), top / 2)
    return pos


def graph_figure(title: str, nodes: list[str], edges: list[tuple[str, str, str, bool]], note: str = "") -> Any:
    """A Matplotlib figure of the body graph."""
    from matplotlib.figure import Figure

    pos = _layout(nodes, edges)
    width = max(6.0, 1.6 * max(1, sum(1 for a, *_ in edges if a == "base")) + 2)
    fig = Figure(figsize=(width, 5.5))
    ax = fig.add_subplot()
    for k, (a, b, label, actuated) in enumerate(edges):
        (x0, y0), (x1, y1) = pos[a], pos[b]
        colour = ACTUATED if actuated else PASSIVE
        ax.plot([x0, x1], [y0, y1], color=colour, lw=3.0 if actuated else 1.4, zorder=1)
        f = 0.5 if abs(y1 - y0) < 1e-9 else (0.38, 0.62)[k % 2]  # crossing links: labels apart
        ax.text(
            x0 + f * (x1 - x0),
            y0 + f * (y1 - y0),
            label,
            fontsize=8,
            color=colour,
            ha="center",
            va="center",
            bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": colour, "lw": 0.6},
            zorder=3,
        )
    for body, (x, y) in pos.items():
        wide = body in ("base", "platform", "ground")
        ax.text(
            x,
            y,
            body,
            fontsize=9 if wide else 7,
            ha="center",
            va="center",
            zorder=4,
            bbox={"boxstyle": "square,pad=0.4" if wide else "round,pad=0.3", "fc": BODY, "ec": "#1f4e79"},
        )
    xs = [x for x, _ in pos.values()]
    ax.set_xlim(min(xs) - 1.2, max(xs) + 1.2)
    ax.set_ylim(-0.6, max(y for _, y in pos.values()) + 0.6)
    ax.set_axis_off()
    ax.set_title(title, fontsize=10)
    legend = "thick red: actuated joint (its actuator); grey: passive joint"
    fig.text(0.5, 0.02, legend + (f"\n{note}" if note else ""), ha="center", fontsize=8)
    return fig


__all__ = ["graph_figure"]
