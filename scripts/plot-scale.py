#!/usr/bin/env python3
"""The scale ladder's plot: scripts/bench-scale.sh's table to a PNG.

    python3 scripts/plot-scale.py build/bench/scale/scale.tsv build/bench/scale/scale.png [TITLE]

Two log-log panels against the input's triangles: Mtri/s (input triangles over wall
seconds, file to file) and peak anonymous memory in MiB, one line per method and
shape (colour: method; solid sphere, dotted parts, other shapes their own styles),
with a dashed line for each --mem over the rungs that ran at it. Rows without figures
(skipped, refused) are left out. Needs matplotlib (Debian's python3-matplotlib).
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = {
    "uniform": "tab:blue",
    "floating": "tab:green",
    "target": "tab:purple",
    "sloppy": "tab:orange",
    "simplify": "tab:red",
}
LABELS = {
    "uniform": "oocsimp uniform",
    "floating": "oocsimp floating",
    "target": "oocsimp to a target (qem)",
    "sloppy": "meshopt_simplifySloppy",
    "simplify": "meshopt_simplify",
}
STYLES = [("-", "o"), (":", "s"), ("-.", "^"), ((0, (1, 3)), "D")]


def mem_mib(text):
    """--mem's text (256M, 1G, 512K, bytes) in MiB, as oocsimp reads it."""
    units = {"K": 1 / 1024, "M": 1, "G": 1024, "T": 1024 * 1024}
    text = text.strip().upper().rstrip("B").rstrip("I")
    if text and text[-1] in units:
        return float(text[:-1]) * units[text[-1]]
    return float(text) / 1048576


def rung_tris(rung):
    """A rung's name (1M, 4M, 1B) to its nominal triangles, or None."""
    mult = {"K": 1e3, "M": 1e6, "B": 1e9, "G": 1e9}
    try:
        if rung[-1:].upper() in mult:
            return float(rung[:-1]) * mult[rung[-1].upper()]
        return float(rung)
    except ValueError:
        return None


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit("usage: plot-scale.py SCALE.tsv OUT.png [TITLE]")
    with open(sys.argv[1], newline="") as f:
        rows = [r for r in csv.DictReader(f, delimiter="\t") if r["Mtri_s"] not in ("", "-")]
    if not rows:
        sys.exit("plot-scale.py: no measured rows in " + sys.argv[1])

    shapes = sorted({r["shape"] for r in rows}, key=lambda s: (s != "sphere", s != "parts", s))
    style = {s: STYLES[i % len(STYLES)] for i, s in enumerate(shapes)}
    methods = [m for m in COLOURS if any(r["method"] == m for r in rows)]
    methods += sorted({r["method"] for r in rows} - set(methods))

    ticks = {}
    for r in rows:
        t = rung_tris(r["rung"])
        ticks[t if t else int(r["input_tris"])] = r["rung"]
    ticks = sorted(ticks.items())

    fig, (speed, memory) = plt.subplots(1, 2, figsize=(13, 6.5))
    for method in methods:
        for shape in shapes:
            pts = sorted(
                (int(r["input_tris"]), float(r["Mtri_s"]), float(r["peak_anon_MiB"]))
                for r in rows
                if r["method"] == method and r["shape"] == shape
            )
            if not pts:
                continue
            x = [p[0] for p in pts]
            line, marker = style[shape]
            kw = dict(color=COLOURS.get(method), linestyle=line, marker=marker, markersize=5,
                      label=f"{LABELS.get(method, method)}, {shape}")
            speed.plot(x, [p[1] for p in pts], **kw)
            memory.plot(x, [p[2] for p in pts], **kw)

    # A dashed line for each --mem, over the rungs that ran at it.
    budgets = {}
    for r in rows:
        if r["mem"] not in ("", "-"):
            budgets.setdefault(r["mem"], []).append(int(r["input_tris"]))
    for i, (mem, xs) in enumerate(sorted(budgets.items(), key=lambda kv: mem_mib(kv[0]))):
        lo, hi = min(xs), max(xs)
        memory.plot([lo / 1.3, hi * 1.3], [mem_mib(mem)] * 2, color="black", linestyle="--",
                    linewidth=1, alpha=0.8 - 0.25 * (i % 2))
        memory.annotate(f"--mem {mem}", (lo / 1.3, mem_mib(mem)), textcoords="offset points",
                        xytext=(2, 4), fontsize=8)

    for ax, title, ylabel in (
        (speed, "Speed, file to file", "input Mtri/s (input triangles / wall seconds)"),
        (memory, "Peak anonymous memory", "peak anonymous MiB"),
    ):
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("input triangles")
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.set_xticks([t for t, _ in ticks], [name for _, name in ticks])  # the rungs, by name
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.yaxis.set_major_locator(matplotlib.ticker.LogLocator(subs=(1, 2, 5)))
        ax.yaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda y, _pos: f"{y:g}"))
        ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = speed.get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(len(methods), 5), fontsize=8, frameon=False)
    fig.suptitle(sys.argv[3] if len(sys.argv) > 3 else "oocsimp scale ladder")
    rows_of_legend = -(-len(labels) // min(len(methods), 5))
    fig.tight_layout(rect=(0, 0.035 * rows_of_legend + 0.02, 1, 1))
    fig.savefig(sys.argv[2], dpi=120)


if __name__ == "__main__":
    main()
